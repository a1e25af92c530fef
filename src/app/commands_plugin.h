// The commands softsight_commands.so holds: every one but those of softsight_live.so
// (plugin_live.cc). Here, not in plugin_commands.cc, so that the tests run the plugin's own
// table (command_line_test.cc: each is in kCommandTable, answers --help, ...).
#pragma once

#include <vector>

#include "app/command_line.h"

namespace softsight {

inline const std::vector<CommandSetup>& CommandsPluginCommands() {
  static const std::vector<CommandSetup> commands = {
      {"demo", SetupDemoCommand},           {"track", SetupTrackCommand},
      {"init", SetupInitCommand},           {"pick", SetupPickCommand},
      {"synth", SetupSynthCommand},         {"evaluate", SetupEvaluateCommand},
      {"calibrate", SetupCalibrateCommand}, {"control", SetupControlCommand},
      {"identify", SetupIdentifyCommand},   {"rig", SetupRigCommand},
      {"plot", SetupPlotCommand},           {"config", SetupConfigCommand},
      {"cameras", SetupCamerasCommand},     {"listen", SetupListenCommand},
      {"track-stereo", SetupTrackStereoCommand},
  };
  return commands;
}

}  // namespace softsight
