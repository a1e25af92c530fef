// softsight_commands.so: every command but `live` (app/command_table.h). Linked with --as-needed,
// so none of the GUI's libraries are loaded with it.
#include "app/command_line.h"
#include "app/command_table.h"
#include "app/commands_plugin.h"

extern "C" __attribute__((visibility("default"))) int softsight_run_command(int argc, char** argv) {
  using namespace softsight;
  return RunCommandLine(argc, argv, CommandsPluginCommands());
}
