#include "app/rig_command.h"

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "app/commands.h"
#include "app/shared_flags.h"
#include "app/stop_request.h"
#include "softsight/io/output_guard.h"
#include "softsight/control/rig.h"
#include "softsight/core/error.h"
#include "softsight/config/control_config.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

// Grey levels, 1 sigma: a good webcam in lab light.
constexpr double kRigCameraNoise = 1.0;

const char* ModeName(BoardMode mode) {
  switch (mode) {
    case BoardMode::kIdle: return "idle (vented)";
    case BoardMode::kPressure: return "pressure";
    case BoardMode::kDuty: return "duty";
    case BoardMode::kStopped: return "stopped (vented)";
    case BoardMode::kWatchdog: return "watchdog (vented)";
  }
  return "?";
}

// Writes the frame so that a reader never sees half a file: a temporary, then rename().
void WriteAtomically(const std::string& file, const cv::Mat& image) {
  const std::string tmp = file + ".tmp.png";
  if (!cv::imwrite(tmp, image) || std::rename(tmp.c_str(), file.c_str()) != 0) {
    throw InputError(file + ": cannot write the rig's frame");
  }
}

// The options' numbers in their ranges; the picture written must not replace the config.
void CheckRigOptions(const RigCommandOptions& options) {
  if (!options.pty) throw InputError("rig: give --pty (the rig serves on a pseudo-terminal)");
  // Tests for the good range: every comparison with NaN is false.
  if (!(options.fps > 0.0 && options.fps <= 240.0)) {
    throw InputError("--fps " + std::to_string(options.fps) + ": must be in (0, 240]");
  }
  if (options.duration_s && !(*options.duration_s > 0.0 && *options.duration_s <= 1e6)) {
    throw InputError("--duration-s " + std::to_string(*options.duration_s) +
                     ": must be a number in (0, 1e6]");
  }
  if (options.disconnect_after_s &&
      !(*options.disconnect_after_s >= 0.0 && *options.disconnect_after_s <= 1e6)) {
    throw InputError("--disconnect-after-s " + std::to_string(*options.disconnect_after_s) +
                     ": must be a number in [0, 1e6]");
  }
  if (options.disconnect_after_replies && *options.disconnect_after_replies < 1) {
    throw InputError("--disconnect-after-replies " +
                     std::to_string(*options.disconnect_after_replies) + ": must be at least 1");
  }
  // The picture written must not replace the config it was started with.
  if (options.frames_file) {
    CheckOutputsAreNotInputs({{"--frames", *options.frames_file}},
                             {{"--config", options.config_file.value_or("")}});
  }
}

// --frames: the rig's camera, a rendered scene, and its first frame written before anyone
// connects.
std::unique_ptr<SyntheticScene> OpenRigCamera(const RigCommandOptions& options,
                                              const SimulatedRig& rig, cv::Mat& image) {
  SceneOptions scene_options;
  scene_options.fps = options.fps;
  RenderOptions render;
  render.supersample = options.supersample;
  // A camera's sensor noise: every frame is a new picture, as from a real camera, so a reader
  // can tell a frame the rig wrote from the last one read again (control: a stalled relay).
  NoiseOptions noise;
  noise.sigma = kRigCameraNoise;
  auto scene = std::make_unique<SyntheticScene>(scene_options, noise, render);
  const RigSnapshot s = rig.snapshot();
  scene->render_at_bend(s.bend_deg, s.time_s, 0, image);
  WriteAtomically(*options.frames_file, image);  // A first frame before anyone connects.
  return scene;
}

// --disconnect-after-s, --disconnect-after-replies: the port closes once either is due.
void PullCableWhenDue(const RigCommandOptions& options, const RigSnapshot& s, RigServer& server,
                      std::optional<std::chrono::steady_clock::time_point>& first_contact) {
  // The cable is pulled that long after the host's first command, however late it started.
  if (!first_contact && server.contacted()) first_contact = std::chrono::steady_clock::now();
  const bool pull_by_time =
      options.disconnect_after_s && first_contact &&
      std::chrono::steady_clock::now() - *first_contact >=
          std::chrono::duration<double>(*options.disconnect_after_s);
  const bool pull_by_count =
      options.disconnect_after_replies && server.past_reply_limit();
  if (server.connected() && (pull_by_time || pull_by_count)) {
    server.disconnect();
    if (!options.quiet) {
      std::fprintf(stderr, "rig: t=%.3f s: port closed (cable pulled), rig keeps running\n",
                   s.time_s);
    }
  }
}

}  // namespace

RigCommandSummary RunRig(const RigCommandOptions& options) {
  CheckRigOptions(options);
  const ControlConfig config =
      options.config_file ? LoadControlConfig(*options.config_file) : ControlConfig{};
  SimulatedRig rig(config.rig);
  RigServer server(rig, /*realtime=*/true);
  cv::Mat image;
  const std::unique_ptr<SyntheticScene> scene =
      options.frames_file ? OpenRigCamera(options, rig, image) : nullptr;
  if (options.disconnect_after_replies) {
    server.set_reply_limit(static_cast<uint64_t>(*options.disconnect_after_replies));
  }
  std::printf("rig: serving on %s\n", server.port().c_str());
  std::fflush(stdout);

  const StopRequest stop;
  const auto start = std::chrono::steady_clock::now();
  auto next_frame = start;
  const auto frame_period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / options.fps));
  BoardMode last_mode = BoardMode::kIdle;
  bool last_limit = false;
  int frame_index = 1;
  RigCommandSummary summary;
  std::optional<std::chrono::steady_clock::time_point> first_contact;
  {
    while (!stop.requested()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      const double wall_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const RigSnapshot s = rig.snapshot();
      const bool limit = s.limit();
      if (!options.quiet && (s.mode != last_mode || limit != last_limit)) {
        std::fprintf(stderr, "rig: t=%.3f s: board %s%s, pressure %.2f kPa, angle %.1f deg\n",
                     s.time_s, ModeName(s.mode), limit ? ", limit guard venting" : "",
                     s.pressure_kpa, s.angle_deg);
      }
      last_mode = s.mode;
      last_limit = limit;
      PullCableWhenDue(options, s, server, first_contact);
      if (scene && std::chrono::steady_clock::now() >= next_frame) {
        next_frame += frame_period;
        scene->render_at_bend(s.bend_deg, s.time_s, frame_index++, image);
        WriteAtomically(*options.frames_file, image);
      }
      if (options.duration_s && wall_s >= *options.duration_s) break;
    }
  }
  const RigSnapshot s = rig.snapshot();
  summary.time_s = s.time_s;
  summary.peak_pressure_kpa = s.peak_pressure_kpa;
  summary.board_rejected = s.board_rejected;
  summary.final_mode = ModeName(s.mode);
  if (!options.quiet) {
    const std::string why =
        stop.requested() ? StopSignalReason(stop.signal()) : "stopped (--duration-s)";
    std::fprintf(stderr,
                 "rig: %s after %.2f s; board %s, pressure %.2f kPa (peak %.2f), %u lines "
                 "rejected\n",
                 why.c_str(), s.time_s, summary.final_mode.c_str(), s.pressure_kpa,
                 s.peak_pressure_kpa, s.board_rejected);
  }
  return summary;
}

namespace {

const FlagTable<RigCommandOptions>& RigFlags() {
  using A = RigCommandOptions;
  static const FlagTable<RigCommandOptions> table = {
      SwitchFlag<A>("--pty", &A::pty)
          .Help("Serve on a new pseudo-terminal and print its path")
          .Required(),
      ValueFlag<A>(kConfigFlag, &A::config_file)
          .Help("Config whose `control: rig:` section sets the board and plant (defaults "
                "without)")
          .Check(CLI::ExistingFile),
      ValueFlag<A>("--frames", &A::frames_file)
          .Help("Render the actuator to this image file at --fps (rewritten atomically), for "
                "`softsight control --rig-frames`"),
      ValueFlag<A>("--fps", &A::fps).Help("Frame rate of --frames").ShowDefault(),
      ValueFlag<A>("--duration-s", &A::duration_s).Help("Stop after this many seconds"),
      ValueFlag<A>("--disconnect-after-s", &A::disconnect_after_s)
          .Help("Close the port this many seconds after the host's first command (a pulled "
                "cable) and keep running, to watch the watchdog vent"),
      ValueFlag<A>("--disconnect-after-replies", &A::disconnect_after_replies)
          .Help("Answer this many lines, close the port when the host asks again (it has read "
                "them all), and keep running (the same pulled cable, at a point that does not "
                "depend on timing)"),
      SwitchFlag<A>(kQuietFlag, &A::quiet).Help("No state-change lines on stderr"),
  };
  return table;
}

}  // namespace

CommandRunner SetupRigCommand(CLI::App& sub) {
  auto o = std::make_shared<RigCommandOptions>();
  sub.description(
      "A simulated rig for trying the control loop without hardware: the board's own firmware\n"
      "logic (protocol, inner pressure loop, pressure limit, watchdog) driving a simulated\n"
      "pneumatic actuator (pump, valves, chamber; bending with lag and hysteresis), in real time\n"
      "on a pseudo-terminal. It prints the device path; drive it with\n"
      "  softsight control --config examples/rig.yaml --port /dev/pts/N --rig-frames rig.png "
      "--target-deg 120 --csv run.csv\n"
      "or type commands by hand (docs/protocol.md). Stops on Ctrl-C.");
  AddFlags(sub, RigFlags(), o.get());
  return [o] {
    RunRig(*o);
    return ExitCodeAfterStop(0);  // 130 / 143 when Ctrl-C / SIGTERM ended it.
  };
}

}  // namespace softsight
