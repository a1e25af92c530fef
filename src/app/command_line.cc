#include "app/command_line.h"

#include <csignal>
#include <exception>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include "app/cli_checks.h"
#include "app/command_table.h"
#include "app/help_format.h"
#include "app/unknown_word.h"
#include "softsight/core/error.h"
#include "softsight/version.h"

namespace softsight {

int RunCommandLine(int argc, char** argv, const std::vector<CommandSetup>& commands) {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_WARNING);
  // A file-size limit (ulimit -f) must surface as a failed write() with EFBIG, which the CSV
  // writer reports after cutting the file back to its last complete row, not kill the process.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{kProgramDescription};
  app.name("softsight");  // Not argv[0], the path it was started by: "Usage: softsight track".
  app.formatter(TerminalHelpFormatter());  // Before the commands: they take the app's.
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("softsight ") + kVersion);
  std::map<const CLI::App*, CommandRunner> runners;
  for (const CommandSetup& entry : commands) {
    const CommandInfo* info = FindCommand(entry.name);
    CLI::App* sub = app.add_subcommand(entry.name, info != nullptr ? info->summary : "");
    runners[sub] = entry.setup(*sub);
    // control and rig check every number in their own options' Check(), with their messages.
    const std::string name = entry.name;
    if (name != "control" && name != "rig") RequireFiniteNumbers(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (const std::optional<int> answered = AnswerHelpOrUnknownWord(app, e, std::cerr)) {
      return *answered;
    }
    // One line like every other error, naming the command it was for.
    const std::vector<CLI::App*> parsed = app.get_subcommands();
    const std::string command =
        parsed.empty() ? "softsight" : "softsight " + parsed.front()->get_name();
    std::cerr << command << ": error: " << EscapeForMessage(e.what()) << " (see " << command
              << " --help)\n";
    return kInputErrorExitCode;
  }
  const CLI::App* chosen = app.get_subcommands().front();
  // Messages may quote the user's bytes (a config's text, a file name): one escaped line each.
  try {
    return runners.at(chosen)();
  } catch (const InputError& e) {
    std::cerr << "softsight " << chosen->get_name() << ": error: " << EscapeForMessage(e.what())
              << "\n";
    return kInputErrorExitCode;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the user gave that the file system cannot resolve (a loop of symbolic links, a
    // name too long, a folder without permission): the user's input, said as such.
    std::cerr << "softsight " << chosen->get_name() << ": error: "
              << EscapeForMessage(e.path1().string()) << ": " << EscapeForMessage(e.code().message())
              << "\n";
    return kInputErrorExitCode;
  } catch (const cv::Exception& e) {
    std::cerr << "softsight " << chosen->get_name()
              << ": OpenCV error: " << EscapeForMessage(e.what()) << "\n";
    return 1;
  } catch (const std::exception& e) {
    // A bug, not the user's fault, but still one line and an exit code rather than an abort.
    std::cerr << "softsight " << chosen->get_name()
              << ": internal error: " << EscapeForMessage(e.what()) << "\n";
    return 1;
  }
}

}  // namespace softsight
