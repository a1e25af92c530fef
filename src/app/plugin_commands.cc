// softsight_commands.so: every command but `live` (app/command_table.h). Linked with --as-needed,
// so none of the GUI's libraries are loaded with it.
#include "app/command_line.h"
#include "app/command_table.h"

extern "C" __attribute__((visibility("default"))) int softsight_run_command(int argc, char** argv) {
  using namespace softsight;
  static const std::vector<CommandSetup> kCommands = {
      {"demo", SetupDemoCommand},         {"track", SetupTrackCommand},
      {"init", SetupInitCommand},         {"pick", SetupPickCommand},
      {"synth", SetupSynthCommand},       {"evaluate", SetupEvaluateCommand},
      {"calibrate", SetupCalibrateCommand}, {"control", SetupControlCommand},
      {"identify", SetupIdentifyCommand}, {"rig", SetupRigCommand},
      {"plot", SetupPlotCommand},         {"config", SetupConfigCommand},
      {"cameras", SetupCamerasCommand},   {"listen", SetupListenCommand},
      {"track-stereo", SetupTrackStereoCommand},
  };
  return RunCommandLine(argc, argv, kCommands);
}
