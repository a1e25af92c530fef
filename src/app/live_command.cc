// softsight live: the overlay window on a camera or a video, with mouse recalibration, live
// HSV picking, recording and the strip chart.
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "app/capture_options.h"
#include "app/commands.h"
#include "app/publish_options.h"
#include "app/python_hook.h"
#include "app/shared_flags.h"
#include "softsight/core/error.h"
#include "gui/live_window.h"
#include "softsight/config/config.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/output_guard.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/track/tracker.h"

namespace softsight {
namespace {

struct LiveArgs {
  std::optional<CameraId> camera;
  std::string input;
  std::string config;
  std::optional<std::string> method;
  std::string save_config;
  std::string record_prefix = "live";
  double window_s = 10.0;
  std::optional<double> scale_distance_mm;
  bool no_pace = false;
  bool no_trackbars = false;
  std::string csv;  // Every frame the window tracks, as the stream has them.
  CaptureArgs capture;
  PublishArgs publish;
  HookArgs hook;
};

// markers.yaml -> markers.live.yaml beside it: saving never overwrites the hand-written config.
std::string DefaultSavePath(const std::string& config) {
  std::filesystem::path path(config);
  return (path.parent_path() / (path.stem().string() + ".live.yaml")).string();
}

int RunLive(const LiveArgs& args) {
  if (args.camera.has_value() && !args.input.empty()) {
    throw InputError("give exactly one of --camera N or --input VIDEO");
  }
  std::string why;
  if (!HaveDisplay(&why)) {
    throw InputError(why +
                     ": the live window needs a display; to measure without one run "
                     "`softsight track --config " +
                     args.config + " --input VIDEO --csv out.csv`");
  }
  TrackingConfig config = LoadTrackingConfig(args.config, args.method);
  FrameSourceSpec spec;
  std::unique_ptr<FrameSource> source =
      OpenLiveSource(args.camera, args.input, args.capture, args.config, config, &spec);
  LiveOptions options;
  options.save_config_path =
      args.save_config.empty() ? DefaultSavePath(args.config) : args.save_config;
  options.record_prefix = args.record_prefix;
  options.chart.window_s = args.window_s;
  options.scale_distance_mm = args.scale_distance_mm;
  if (std::string problem; !options.Check(&problem)) throw InputError("live options: " + problem);
  // The stream sees every frame the window tracks (stepped and sought ones too, by their own
  // frame numbers); its columns are those of the config as the window opens.
  const std::unique_ptr<PublishSink> publish = OpenPublishSink(args.publish.resolved(), args.config);
  // The hook first among the sinks: the CSV, the stream and the recordings write its columns.
  // From a camera it runs beside the window's loop; a file waits for it on every frame.
  const std::unique_ptr<CommandHook> hook =
      CommandHook::Open(args.hook, source->is_live(), TrackingColumns(config), std::cerr);
  if (hook) {
    options.sinks.push_back(&hook->sink());
    options.extra_columns = hook->columns();
  }
  std::optional<CsvSink> csv;
  if (!args.csv.empty()) {
    std::vector<PathRole> inputs = ConfigInputs(config);
    for (const std::string& file : source->files()) inputs.push_back({"--input", file});
    CheckOutputsAreNotInputs({{"--csv", args.csv}}, inputs);
    csv.emplace(args.csv, TrackingColumns(config, options.extra_columns));
    options.sinks.push_back(&*csv);
  }
  if (publish) {
    publish->set_columns(TrackingColumns(config, options.extra_columns));
    options.sinks.push_back(publish.get());
  }
  std::cerr << "softsight live: " << source->description() << ", " << config.markers.size()
            << " markers; press h in the window for help\n";
  LiveWindowOptions window;
  window.trackbars = !args.no_trackbars;
  window.pace_files = !args.no_pace;
  FrameSourceOpener reopen;
  if (!source->is_live()) reopen = [spec] { return OpenFrameSource(spec); };
  LiveRunResult run = RunLiveWindow(config, std::move(source), options, window, reopen);
  // The window's run does not end the program's sinks: they end here, with its summary.
  for (FrameSink* sink : options.sinks) sink->end(run.summary.run);
  for (FrameSink* sink : options.sinks) sink->report(run.summary.run);
  std::cerr << run.summary.Report();
  if (!run.last_recording.empty()) {
    std::cerr << "softsight live: last recording " << run.last_recording << ".*\n";
  }
  return run.exit_code;
}


const FlagTable<LiveArgs>& LiveFlags() {
  using A = LiveArgs;
  static const FlagTable<LiveArgs> table = {
      CameraFlag<A>("--camera", &A::camera, "The camera"),
      ValueFlag<A>(kInputFlag, &A::input)
          .Help("Video file or image sequence instead of a camera (played at its frame rate)")
          .Excludes("--camera"),
      ValueFlag<A>(kConfigFlag, &A::config)
          .Help("Marker configuration (YAML, see examples/)")
          .Required(),
      MethodFlag<A>(&A::method),
      ValueFlag<A>("--save-config", &A::save_config)
          .Help("Where `s` saves the config (default: <config>.live.yaml beside it)"),
      RecordPrefixFlag<A>(&A::record_prefix, ""),
      ChartSecondsFlag<A>(&A::window_s, "Time span of the strip chart, seconds"),
      ValueFlag<A>("--scale-distance-mm", &A::scale_distance_mm)
          .Help("Known distance between the two points clicked after `c` (mm), e.g. 50 for two "
                "ruler marks 50 mm apart; sets the mm scale live")
          .Check(CLI::PositiveNumber),
      NoPaceFlag<A>([](A& a) { a.no_pace = true; }),
      SwitchFlag<A>("--no-trackbars", &A::no_trackbars).Help("Hide the HSV trackbars"),
  };
  return table;
}

// After the camera's settings in --help, as before.
const FlagTable<LiveArgs>& LiveOutputFlags() {
  using A = LiveArgs;
  static const FlagTable<LiveArgs> table = {
      ValueFlag<A>("--csv", &A::csv)
          .Help("Also write a CSV row for every frame the window tracks (stepped and sought "
                "ones too, by their own frame numbers), as `track --csv` does"),
  };
  return table;
}

}  // namespace

CommandRunner SetupLiveCommand(CLI::App& sub) {
  auto args = std::make_shared<LiveArgs>();
  sub.footer(
      "The window shows each marker, the base-middle-tip triangle, the fitted arc, the\n"
      "measurements (mm when the config has a scale), fps, processing time and capture-to-result\n"
      "latency, and a strip chart of the last seconds under the image.\n"
      "Mouse: drag a box over a marker to reselect it (template / search region); click a marker\n"
      "to pick its HSV ranges from the pixels around the click (keys 1..9 choose which marker).\n"
      "Trackbars adjust the active marker's ranges. Keys: h help, space pause, r record, s save\n"
      "config, b reset the bending-distance reference, m switch method, c mm scale, q quit.\n"
      "Playback of a file or image sequence: . / , one frame forward / back, ] / [ (Right / Left)\n"
      "+-1 s, < / > (Home / End) first / last frame, l loop, 0 restart; at the end the last frame\n"
      "stays and every key works. Rows keep the source's frame numbers after a seek.\n"
      "The timeline under the image shows where the frame is, where edits and recordings were\n"
      "made and where a marker was not found; click or drag on it to seek. { / } play slower /\n"
      "faster (0.1x..4x); + / - zoom at the pointer, right-drag pans, z shows the\n"
      "whole image (clicks and boxes work zoomed); u undoes the last reselection or range change.\n"
      "v: mask view of the active marker (member pixels, candidate blobs with their verdicts,\n"
      "the searched region); there a click adds the clicked colours to the ranges, shift-click\n"
      "removes them; while paused every range change re-tracks the frame on screen.\n"
      "Scale: with --scale-distance-mm D, press c and click two points D mm apart (e.g. the ends\n"
      "of a ruler in the actuator's plane); the mm values appear at once and `s` saves the points\n"
      "as scale_from_points, so `softsight track` with the saved config gives the same mm.\n"
      "A recording writes <prefix>-NNN.csv, .avi (annotated), .raw.avi (lossless) and .yaml;\n"
      "`softsight track --config <prefix>-NNN.yaml --input <prefix>-NNN.raw.avi` reproduces it.\n"
      "Camera settings (capture: in the config, or the --camera-* options below) are applied\n"
      "when the camera opens, read back and printed; `softsight cameras` lists the modes.\n"
      "Needs a display; without one use `softsight track`.\n"
      "Example: softsight live --camera 0 --config markers.yaml");
  AddFlags(sub, LiveFlags(), args.get());
  AddFlags(sub, CaptureFlags(), &args->capture);
  AddFlags(sub, LiveOutputFlags(), args.get());
  AddFlags(sub, PublishFlags(), &args->publish);
  AddFlags(sub, HookFlags(), &args->hook);
  return [args] { return RunLive(*args); };
}

}  // namespace softsight
