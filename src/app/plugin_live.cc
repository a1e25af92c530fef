// softsight_live.so: the `live` command and `track-stereo --window`, the only ones that need the
// GUI's libraries (highgui, its toolkit, X11); they load with this plugin only.
#include "app/command_line.h"
#include "app/command_table.h"

extern "C" __attribute__((visibility("default"))) int softsight_run_command(int argc, char** argv) {
  using namespace softsight;
  static const std::vector<CommandSetup> kCommands = {
      {"live", SetupLiveCommand},
      {"serve", SetupServeCommand},
      {"track-stereo", SetupTrackStereoWindowCommand}};
  return RunCommandLine(argc, argv, kCommands);
}
