// The flags several commands take, each declared here once (name, check, default shown) and
// added by every command that takes it as one row of its table (app/flag_table.h). A row's help
// is the command's when the flag means something of the command's own ("Markers and `control:`
// section" for control's --config); the name, the check and what the flag is stay these.
// Groups of flags with a struct of their own (--publish*, --hook*, --camera-*, the stereo pair)
// have a table of their own: publish_options.h, python_hook.h, capture_options.h, below.
#pragma once

#include <functional>
#include <string>
#include <utility>

#include "app/capture_options.h"
#include "app/cli_checks.h"
#include "app/flag_table.h"

namespace softsight {

// Flags several commands take whose help, check and default are each command's own (what the
// config holds, whether it is required): their names, declared once.
inline constexpr const char* kConfigFlag = "-c,--config";  // The YAML the command reads.
inline constexpr const char* kInputFlag = "-i,--input";    // Frames (or views) from files.
inline constexpr const char* kQuietFlag = "-q,--quiet";    // Less on stderr.
// A printed chessboard: calibrate's, and track-stereo's --bench-board.
inline constexpr const char* kChessboardFlag = "--chessboard";
inline constexpr const char* kSquareMmFlag = "--square-mm";
// The two cameras: their recordings (track-stereo's videos, calibrate's views) and the pair's
// calibration (track-stereo, control and identify --stereo).
inline constexpr const char* kLeftFlag = "--left";
inline constexpr const char* kRightFlag = "--right";
inline constexpr const char* kStereoFlag = "--stereo";

// -o is --output, the command's main output, everywhere; `old_name` ("csv", "out", "out-dir";
// "" for none) is the long name it had before and keeps.
template <typename Args, typename Access>
FlagBuilder<Args> OutputFlag(Access access, const std::string& old_name, std::string help) {
  const std::string names = old_name.empty() ? "-o,--output" : "-o,--output,--" + old_name;
  return ValueFlag<Args>(names, access).Help(std::move(help));
}

// --fps: an image sequence's frame rate, for its timestamps (a video has its own).
template <typename Args, typename Access>
FlagBuilder<Args> SequenceFpsFlag(Access access, std::string help) {
  return ValueFlag<Args>("--fps", access)
      .Help(std::move(help))
      .ShowDefault()
      .Check(NumberIn(1e-3, 1e6));
}

// --max-frames: stop after this many frames (or pairs).
template <typename Args, typename Access>
FlagBuilder<Args> MaxFramesFlag(Access access, std::string help) {
  return ValueFlag<Args>("--max-frames", access).Help(std::move(help)).Check(NumberIn(0, 1e15));
}

// -m,--method: one tracking method for every marker, whatever the config says.
std::string MethodHelp();  // Names the methods of the tracker registry.
template <typename Args, typename Access>
FlagBuilder<Args> MethodFlag(Access access) {
  return ValueFlag<Args>("-m,--method", access).Help(MethodHelp());
}

// --no-pace: recorded frames read as fast as they are tracked instead of at their frame rate;
// `action` says so in the command's args.
template <typename Args>
FlagBuilder<Args> NoPaceFlag(std::function<void(Args&)> action,
                             std::string help =
                                 "Read a video file as fast as it decodes instead "
                                 "of at its frame rate") {
  return ActionFlag<Args>("--no-pace", std::move(action)).Help(std::move(help));
}

// --chart-seconds: the time span of a window's strip chart.
template <typename Args, typename Access>
FlagBuilder<Args> ChartSecondsFlag(Access access, std::string help) {
  return ValueFlag<Args>("--chart-seconds", access).Help(std::move(help)).ShowDefault();
}

// The two cameras of track-stereo and control/identify --stereo: the right view's own config
// and how far from its epipolar line a pair is still believed.
template <typename Args, typename Access>
FlagBuilder<Args> RightConfigFlag(Access access, std::string help) {
  return ValueFlag<Args>("--right-config", access).Help(std::move(help)).Check(CLI::ExistingFile);
}
template <typename Args, typename Access>
FlagBuilder<Args> MaxEpipolarFlag(Access access, std::string help) {
  return ValueFlag<Args>("--max-epipolar-px", access)
      .Help(std::move(help))
      .ShowDefault()
      .Check(NumberIn(1e-3, 1e3));
}

// --record-prefix: where a live front end's recordings go; `where` says relative to what.
template <typename Args, typename Access>
FlagBuilder<Args> RecordPrefixFlag(Access access, const std::string& where) {
  return ValueFlag<Args>("--record-prefix", access)
      .Help("Recordings go to " + where + "<prefix>-NNN.csv/.avi/.raw.avi/.yaml")
      .ShowDefault();
}

// Where control and identify get their board and frames: -p,--port, --simulate, --camera,
// --rig-frames and the --fps of the simulated frames. `Args` has fields port, simulate, camera,
// rig_frames and fps.
template <typename Args>
FlagTable<Args> RigSourceFlags(std::string port_help, std::string simulate_help,
                               std::string rig_frames_help) {
  return {
      ValueFlag<Args>("-p,--port", &Args::port).Help(std::move(port_help)),
      SwitchFlag<Args>("--simulate", &Args::simulate).Help(std::move(simulate_help)),
      CameraFlag<Args>("--camera", &Args::camera, "The camera for the frames (live)"),
      ValueFlag<Args>("--rig-frames", &Args::rig_frames).Help(std::move(rig_frames_help)),
      ValueFlag<Args>("--fps", &Args::fps)
          .Help("Frame rate of --simulate and --rig-frames")
          .ShowDefault(),
  };
}

// The rendered scene of synth, evaluate and demo: which scene, how many frames, its noise, blur
// and seed (same seed, same frames in each of them).
template <typename Args, typename Access>
FlagBuilder<Args> SceneFlag(Access access, std::string help) {
  return ValueFlag<Args>("--scene", access).Help(std::move(help)).ShowDefault();
}
template <typename Args, typename Access>
FlagBuilder<Args> FramesFlag(Access access, std::string help) {
  return ValueFlag<Args>("-n,--frames", access).Help(std::move(help)).ShowDefault();
}
template <typename Args, typename Access>
FlagBuilder<Args> NoiseFlag(Access access) {
  return ValueFlag<Args>("--noise", access)
      .Help("Gaussian sensor noise sigma, grey levels")
      .ShowDefault();
}
template <typename Args, typename Access>
FlagBuilder<Args> BlurFlag(Access access) {
  return ValueFlag<Args>("--blur", access)
      .Help("Optical blur (Gaussian sigma), pixels")
      .ShowDefault();
}
template <typename Args, typename Access>
FlagBuilder<Args> SeedFlag(Access access, std::string help) {
  return ValueFlag<Args>("--seed", access).Help(std::move(help)).ShowDefault();
}

}  // namespace softsight
