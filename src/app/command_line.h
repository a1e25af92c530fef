// What a plugin does with its command line: the subcommands it holds (app/command_table.h names
// them and gives their summaries), parsed with CLI11, run, and every error reported in one line.
#pragma once

#include <vector>

#include "app/commands.h"

namespace softsight {

struct CommandSetup {
  const char* name;  // As in kCommandTable.
  CommandRunner (*setup)(CLI::App& sub);
};

// Parses `argv` (as main() got it: argv[0] the program, then the command) against `commands`
// and runs the chosen one. Returns the exit code: the command's, 2 for a usage error or an
// InputError (its message printed once, as one escaped line), 1 for anything else.
int RunCommandLine(int argc, char** argv, const std::vector<CommandSetup>& commands);

}  // namespace softsight
