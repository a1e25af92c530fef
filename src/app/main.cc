// softsight: measure soft robots with a camera. See README.md.
#include <csignal>
#include <exception>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include "app/cli_checks.h"
#include "app/commands.h"
#include "softsight/core/error.h"
#include "softsight/version.h"

namespace softsight {
namespace {

struct CommandEntry {
  const char* name;
  const char* summary;
  CommandRunner (*setup)(CLI::App& sub);
};

// The subcommands, in the order --help lists them.
const CommandEntry kCommands[] = {
    {"demo", "Render the built-in demo scene, track it and write a CSV (start here)",
     SetupDemoCommand},
    {"track", "Track markers in a video or image sequence and write per-frame measurements",
     SetupTrackCommand},
    {"init", "Find the markers in a frame by themselves and write a config (no GUI)",
     SetupInitCommand},
    {"pick", "Write a config with the colours at given pixels, as clicks in `live` give them",
     SetupPickCommand},
    {"synth", "Render a synthetic actuator video with exact ground truth", SetupSynthCommand},
    {"evaluate", "Compare the tracking methods' accuracy and speed on a rendered scene",
     SetupEvaluateCommand},
    {"calibrate", "Calibrate the camera from chessboard views, or the plane's mm per pixel",
     SetupCalibrateCommand},
    {"live", "Live window on a camera or video: overlay, mouse recalibration, recording",
     SetupLiveCommand},
    {"control", "Close the loop: bend the actuator to a target angle over the serial link",
     SetupControlCommand},
    {"identify", "Identify the actuator (steps, PRBS) and write a config with gains from the model",
     SetupIdentifyCommand},
    {"rig", "Simulated pressure-control board + actuator on a pseudo-terminal (no hardware)",
     SetupRigCommand},
    {"plot", "Draw angle, bending distance and arc length against time from a CSV (PNG or SVG)",
     SetupPlotCommand},
    {"config", "Print every config key with its default and range (--doc), or check a config",
     SetupConfigCommand},
};

int Main(int argc, char** argv) {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_WARNING);
  // A file-size limit (ulimit -f) must surface as a failed write() with EFBIG, which the CSV
  // writer reports after cutting the file back to its last complete row, not kill the process.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{
      "softsight measures soft robots with a camera: it finds coloured markers on an actuator,\n"
      "computes its bending angle, radius of curvature, arc length and bending distance, and can\n"
      "close the control loop over a serial link. Run `softsight <command> --help` for details."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("softsight ") + kVersion);
  std::map<const CLI::App*, CommandRunner> runners;
  for (const CommandEntry& entry : kCommands) {
    CLI::App* sub = app.add_subcommand(entry.name, entry.summary);
    runners[sub] = entry.setup(*sub);
    // control and rig check every number in their own options' Check(), with their messages.
    const std::string name = entry.name;
    if (name != "control" && name != "rig") RequireFiniteNumbers(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version.
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

}  // namespace
}  // namespace softsight

int main(int argc, char** argv) { return softsight::Main(argc, argv); }
