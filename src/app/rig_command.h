// `softsight rig --pty`: the simulated board + pneumatic actuator on a pseudo-terminal, in real
// time, for driving by hand (a terminal program) or by `softsight control --port /dev/pts/N`.
#pragma once

#include <optional>
#include <string>

namespace softsight {

struct RigCommandOptions {
  bool pty = false;                          // Serve on a new pseudo-terminal (the only transport).
  std::optional<std::string> config_file;    // Its `control: rig:` section; defaults without.
  std::optional<std::string> frames_file;    // Render the actuator here at `fps` (atomic rewrite).
  double fps = 30.0;
  int supersample = 2;
  std::optional<double> duration_s;          // Default: until Ctrl-C / SIGTERM.
  // Close the port this long after the host's first command (a pulled cable), keep running.
  std::optional<double> disconnect_after_s;
  // Or once this many answer lines have been sent (reproducible whatever the machine's load).
  std::optional<int64_t> disconnect_after_replies;
  bool quiet = false;                        // No state-change lines on stderr.
};

struct RigCommandSummary {
  double time_s = 0.0;
  double peak_pressure_kpa = 0.0;
  uint32_t board_rejected = 0;
  std::string final_mode;
};

// Prints "rig: serving on /dev/pts/N" on stdout (flushed), then runs. Throws InputError.
RigCommandSummary RunRig(const RigCommandOptions& options);

}  // namespace softsight
