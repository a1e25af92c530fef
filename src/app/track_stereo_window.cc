// `softsight track-stereo --window`, in the live plugin (the GUI's libraries load with it
// only): the command as the commands plugin runs it, with the stereo window as a sink of the
// run (gui/stereo_window.h).
#include <memory>
#include <string>

#include "app/commands.h"
#include "app/track_stereo_command.h"
#include "gui/live_window.h"  // HaveDisplay
#include "gui/stereo_window.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

StereoWindowRun OpenStereoWindow(const TrackStereoOptions& options, const TrackingConfig& left,
                                 const TrackingConfig& right) {
  std::string why;
  if (!HaveDisplay(&why)) {
    throw InputError(why + ": --window needs a display; without it, drop --window (the CSV is "
                           "the same)");
  }
  StereoWindowOptions window;
  window.chart.window_s = options.chart_seconds;
  // Cameras' pairs come at their own rate; recorded inputs play at theirs unless --no-pace.
  window.pace = options.pace && !options.left_camera && !options.right_camera;
  if (std::string problem; !window.chart.Check(&problem)) {
    throw InputError("--chart-seconds: " + problem);
  }
  auto sink = std::make_unique<StereoWindow>(window, left, right);
  const StereoWindow* shown = sink.get();
  return {std::move(sink), [shown] { return shown->quit_requested(); }};
}

}  // namespace

CommandRunner SetupTrackStereoWindowCommand(CLI::App& sub) {
  return SetupTrackStereoCommand(sub, OpenStereoWindow);
}

}  // namespace softsight
