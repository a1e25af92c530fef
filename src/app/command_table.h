// The subcommands of `softsight`, as --help lists them, and the plugin each one lives in.
//
// The program itself (main.cc) is a small launcher that links no OpenCV: `softsight --version`
// and `softsight --help` answer from this table alone, in a few milliseconds. A command is run
// by the plugin beside the program that holds it (loaded with dlopen): softsight_commands.so
// for every command but `live`, softsight_live.so for `live` (and `track-stereo --window`), the
// only ones that need the GUI's libraries (highgui and its Qt/GTK and X11), which therefore load
// only for them.
#pragma once

#include <cstring>

namespace softsight {

struct CommandInfo {
  const char* name;
  const char* summary;
  const char* plugin;  // softsight_<plugin>.so.
};

// One paragraph: --help wraps it to the terminal (app/help_format.h).
inline constexpr char kProgramDescription[] =
    "softsight measures soft robots with a camera: it finds coloured markers on an actuator, "
    "computes its bending angle, radius of curvature, arc length and bending distance, and can "
    "close the control loop over a serial link. Run `softsight <command> --help` for details; "
    "-o (--output) is every command's main output file.";

// In the order --help lists them.
inline constexpr CommandInfo kCommandTable[] = {
    {"demo", "Render the built-in demo scene, track it and write a CSV (start here)", "commands"},
    {"track", "Track markers in a video or image sequence and write per-frame measurements",
     "commands"},
    {"track-stereo",
     "Track markers in two cameras' videos and write 3D positions and angles (--window: watch)",
     "commands"},
    {"init", "Find the markers in a frame by themselves and write a config (no GUI)", "commands"},
    {"pick", "Write a config with the colours at given pixels, as clicks in `live` give them",
     "commands"},
    {"synth", "Render a synthetic actuator video with exact ground truth", "commands"},
    {"evaluate", "Compare the tracking methods' accuracy and speed on a rendered scene",
     "commands"},
    {"calibrate", "Calibrate a camera or two (stereo) from chessboard views, or the plane's scale",
     "commands"},
    {"live", "Live window on a camera or video: overlay, mouse recalibration, recording", "live"},
    {"serve", "The live bench as a web page: watch, tune, play back and record from a browser",
     "live"},
    {"cameras", "List the V4L2 cameras (pixel formats, sizes, frame rates) and GenICam ones",
     "commands"},
    {"control", "Close the loop: bend the actuator to a target angle over the serial link",
     "commands"},
    {"identify", "Identify the actuator (steps, PRBS) and write a config with gains from the model",
     "commands"},
    {"rig", "Simulated pressure-control board + actuator on a pseudo-terminal (no hardware)",
     "commands"},
    {"listen", "Receive the results a run publishes (--publish): print them or write a CSV",
     "commands"},
    {"plot", "Draw angle, bending distance and arc length against time from a CSV (PNG or SVG)",
     "commands"},
    {"config", "Print every config key with its default and range (--doc), or check a config",
     "commands"},
};

// A command that runs in another plugin when given a flag: `track-stereo --window` opens the
// stereo window, so it runs in the live plugin, which holds a `track-stereo` of its own (the
// same options and run, with the window).
struct PluginByFlag {
  const char* command;
  const char* flag;
  const char* plugin;
};
inline constexpr PluginByFlag kPluginsByFlag[] = {{"track-stereo", "--window", "live"}};

// The plugin that runs `command` with these arguments (argv as main() got it).
inline const char* PluginFor(const CommandInfo& command, int argc, char** argv) {
  for (const PluginByFlag& by_flag : kPluginsByFlag) {
    if (std::strcmp(by_flag.command, command.name) != 0) continue;
    const size_t length = std::strlen(by_flag.flag);
    for (int i = 1; i < argc; ++i) {
      if (std::strcmp(argv[i], "--") == 0) break;
      if (std::strncmp(argv[i], by_flag.flag, length) == 0 &&
          (argv[i][length] == '\0' || argv[i][length] == '=')) {
        return by_flag.plugin;
      }
    }
  }
  return command.plugin;
}

inline const CommandInfo* FindCommand(const char* name) {
  for (const CommandInfo& command : kCommandTable) {
    if (std::strcmp(command.name, name) == 0) return &command;
  }
  return nullptr;
}

// What a plugin exports: runs `softsight <command> ...` (argv as main() got it) and returns the
// exit code.
inline constexpr char kPluginEntry[] = "softsight_run_command";
using PluginEntry = int (*)(int argc, char** argv);

}  // namespace softsight
