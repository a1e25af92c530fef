#include "app/track_command.h"

#include <filesystem>
#include <iostream>
#include <thread>
#include <memory>
#include <optional>
#include <vector>

#include "app/capture_options.h"
#include "app/cli_checks.h"
#include "app/commands.h"
#include "app/progress.h"
#include "app/publish_options.h"
#include "app/shared_flags.h"
#include "app/stop_request.h"
#include "app/track_many.h"
#include "gui/overlay.h"
#include "softsight/core/error.h"
#include "softsight/io/run_source.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/track/template_tracker.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {
namespace {

void CheckRunnable(const TrackingConfig& config, const TrackOptions& options) {
  for (const MarkerSpec& spec : config.markers) {
    if (const auto missing = spec.params.kind().missing_for_batch(spec.params)) {
      throw InputError(options.config_file + ": marker '" + spec.name + "' " + *missing);
    }
  }
}

// Before any output is opened: none of them may be a file this run reads, nor another output.
void CheckOutputs(const TrackOptions& options, const TrackingConfig& config,
                  const FrameSource& source) {
  std::vector<PathRole> outputs{{"--csv", options.csv_file}};
  if (options.annotated_file) outputs.push_back({"--annotated", *options.annotated_file});
  if (options.record_file) outputs.push_back({"--record", *options.record_file});
  if (const std::optional<PathRole> socket = PublishOutput(options.publish)) outputs.push_back(*socket);
  std::vector<PathRole> inputs = ConfigInputs(config);
  for (const std::string& file : source.files()) inputs.push_back({"--input", file});
  CheckOutputsAreNotInputs(outputs, inputs);
}

// `-o` names a folder: an existing one, or a path ending in '/'.
bool IsOutputFolder(const std::string& path) {
  return !path.empty() && (path.back() == '/' || std::filesystem::is_directory(path));
}

int DefaultJobs() {
  const unsigned cores = std::thread::hardware_concurrency();
  return cores == 0 ? 1 : static_cast<int>(cores);
}

}  // namespace

TrackingConfig LoadTrackConfig(const TrackOptions& options) {
  TrackingConfig config = LoadTrackingConfig(options.config_file, options.method);
  if (options.template_colour) {
    for (MarkerSpec& spec : config.markers) {
      if (auto* templ = spec.params.get_if<TemplateParams>()) templ->colour = *options.template_colour;
    }
  }
  CheckRunnable(config, options);
  if (options.max_frames && *options.max_frames < 0) {
    throw InputError("--max-frames " + std::to_string(*options.max_frames) + ": must be 0 or more");
  }
  return config;
}

RunSummary RunTrack(const TrackOptions& options, RunSummary* summary_out,
                    const std::vector<FrameSink*>& more_sinks, const TrackSeams& seams) {
  RunSummary local;
  RunSummary& summary = summary_out != nullptr ? *summary_out : local;
  summary = RunSummary{};

  // Ctrl-C ends a camera run (or a long file) with its summary. Caught from before anything is
  // written: a signal after the CSV's header and before the first frame ends the run through its
  // own path too (it was the default action, death, in that gap).
  const StopRequest stop;
  const TrackingConfig config = LoadTrackConfig(options);
  std::unique_ptr<FrameSource> source =
      seams.open_source ? seams.open_source() : OpenFrameSource(options.source);
  CheckOutputs(options, config, *source);
  // A test's stand-in is read as it is; a file is decoded ahead (io/run_source.h).
  if (!seams.open_source) source = SourceForRun(std::move(source), FilePacing::kReadAhead);
  TrackingSession session(config);

  // Sinks in the order they see each frame; every output is opened (and checked) before the run,
  // the stream's endpoint first: a bad one is refused before the CSV is made.
  const std::unique_ptr<PublishSink> publish = OpenPublishSink(options.publish, options.config_file);
  // The hook before the CSV: a bad hook file is refused before the CSV is made. A file's run
  // waits for the hook on every frame (every row has its values); a camera's does not.
  const std::unique_ptr<CommandHook> hook =
      CommandHook::Open(options.hook, source->is_live(), TrackingColumns(config), std::cerr);
  const std::vector<CsvColumn> hook_columns = hook ? hook->columns() : std::vector<CsvColumn>{};
  CsvSink csv(options.csv_file, TrackingColumns(config, hook_columns));
  std::vector<FrameSink*> sinks;
  if (hook) sinks.push_back(&hook->sink());  // Before every sink that writes its columns.
  sinks.push_back(&csv);
  if (publish) {
    // Right after the CSV: each frame's record leaves as its row is written.
    publish->set_columns(TrackingColumns(config, hook_columns));
    sinks.push_back(publish.get());
  }
  std::optional<VideoSink> annotated;
  if (options.annotated_file) {
    // MJPG keeps the file small: the annotated video is for people, not for measurement.
    annotated.emplace(*options.annotated_file, "mjpg", std::nullopt,
                      [overlay = OverlayOptionsFor(config.measure)](
                          cv::Mat& canvas, const FrameResult& result) {
                        DrawOverlay(canvas, result, overlay);
                      },
                      seams.before_encode);
    sinks.push_back(&*annotated);
  }
  std::optional<VideoSink> recording;
  if (options.record_file) {
    recording.emplace(*options.record_file, "", std::nullopt, FrameDrawer{}, seams.before_encode);
    sinks.push_back(&*recording);
  }
  sinks.insert(sinks.end(), more_sinks.begin(), more_sinks.end());
  ProgressSink progress("track", !options.quiet && !options.brief);
  sinks.push_back(&progress);

  RunOptions run;
  run.max_frames = options.max_frames;
  run.stop_requested = [&stop] { return stop.requested(); };
  run.describe_stop = [&stop](StopReason reason) {
    return reason == StopReason::kStopRequested && stop.signal() != 0 ? StopSignalReason(stop.signal())
                                                                      : std::string();
  };
  // The sinks add their own figures (CSV row latency, encoder errors and waits): FrameSink::report.
  summary = RunPipeline(*source, session, sinks, run);
  if (!summary.ok()) throw InputError(summary.error);
  return summary;
}

namespace {

// What track's flags set until it runs. Several inputs (or an output folder) run as a batch:
// one CSV per input (track_many.h).
struct TrackArgs {
  TrackOptions options;
  std::vector<std::string> inputs;
  int jobs = DefaultJobs();
  CaptureArgs capture;
  PublishArgs publish;
};

const FlagTable<TrackArgs>& TrackFlags() {
  using A = TrackArgs;
  static const FlagTable<TrackArgs> table = {
      ValueFlag<A>(kConfigFlag, [](A& a) -> auto& { return a.options.config_file; })
          .Help("Marker config (YAML), see examples/")
          .Required()
          .Check(CLI::ExistingFile),
      ValueFlag<A>(kInputFlag, &A::inputs)
          .Help("Video file, folder of images, printf pattern such as frames/%04d.png, or a "
                "built-in scene: synth:bending, synth:wedge1, synth:wedge4, synth:bench, "
                "synth:plate. Repeat it for several inputs (with -o FOLDER/)"),
      CameraFlag<A>("--camera", [](A& a) -> auto& { return a.options.source.camera; },
                    "The camera instead of --input: tracks until Ctrl-C or --max-frames")
          .Excludes("--input"),
      OutputFlag<A>([](A& a) -> auto& { return a.options.csv_file; }, "csv",
                    "Where to write the per-frame CSV; a folder (an existing one, or a path "
                    "ending in /) gets one CSV per input, named after it (run.avi -> "
                    "FOLDER/run.csv)")
          .Required(),
      ValueFlag<A>("-j,--jobs", &A::jobs)
          .Help("With several inputs: how many are tracked at the same time (default: the "
                "number of cores)")
          .Check(CLI::Range(1, 1024)),
      MethodFlag<A>([](A& a) -> auto& { return a.options.method; }),
      ActionFlag<A>("--gray", [](A& a) { a.options.template_colour = false; })
          .Help("Template matching on gray frames (the default unless the config says colour)"),
      ActionFlag<A>("--colour", [](A& a) { a.options.template_colour = true; })
          .Help("Template matching on BGR frames: 3x the work, tells same-shape markers of "
                "different colours apart")
          .Excludes("--gray"),
      ValueFlag<A>("--annotated", [](A& a) -> auto& { return a.options.annotated_file; })
          .Help("Also write a video with the overlay drawn on each frame (.avi)"),
      ValueFlag<A>("--record", [](A& a) -> auto& { return a.options.record_file; })
          .Help("Also write every processed frame as read (.avi/.mkv: lossless HuffYUV, or "
                "frames/%04d.png), e.g. to track a camera run again later"),
      SequenceFpsFlag<A>([](A& a) -> auto& { return a.options.source.sequence_fps; },
                         "Frame rate of an image sequence, for its timestamps"),
      MaxFramesFlag<A>([](A& a) -> auto& { return a.options.max_frames; },
                       "Stop after this many frames"),
      SwitchFlag<A>(kQuietFlag, [](A& a) -> auto& { return a.options.quiet; })
          .Help("No progress bar and no summary"),
      SwitchFlag<A>("--brief", [](A& a) -> auto& { return a.options.brief; })
          .Help("No progress bar; a one-line summary at the end"),
  };
  return table;
}

}  // namespace

CommandRunner SetupTrackCommand(CLI::App& sub) {
  auto args = std::make_shared<TrackArgs>();
  sub.description(
      "Track the markers of a config in a video (or image sequence) and write one CSV row per\n"
      "frame: every marker's centroid, the bending angle, chord, sagitta, radius of curvature,\n"
      "arc length and bending distance (in mm too when the config gives a scale).\n"
      "Examples:\n"
      "  softsight track --config examples/markers.yaml --input run.avi --csv run.csv\n"
      "  softsight track --config markers.yaml --camera 0 --csv bench.csv   (Ctrl-C stops)\n"
      "  softsight track -c markers.yaml -i a.avi -i b.avi -i c.avi -o results/ --jobs 2\n"
      "  softsight track -c markers.yaml --camera 0 --csv run.csv --publish tcp://*:5556\n"
      "      (and in another terminal: softsight listen tcp://localhost:5556)");
  AddFlags(sub, CaptureFlags(), &args->capture);
  AddFlags(sub, TrackFlags(), args.get());
  AddFlags(sub, PublishFlags(), &args->publish);
  AddFlags(sub, HookFlags(), &args->options.hook);
  // The run's parts, each keeping `args` alive.
  const std::shared_ptr<TrackOptions> options(args, &args->options);
  const std::shared_ptr<std::vector<std::string>> inputs(args, &args->inputs);
  const std::shared_ptr<int> jobs(args, &args->jobs);
  const std::shared_ptr<CaptureArgs> capture(args, &args->capture);
  const std::shared_ptr<PublishArgs> publish(args, &args->publish);
  return [options, inputs, jobs, capture, publish] {
    options->publish = publish->resolved();
    const bool from_files = !inputs->empty() || !options->source.input.empty();
    if (!options->source.camera && from_files) {  // Neither: the missing input is said below.
      const std::string source = inputs->size() == 1   ? "the file " + inputs->front()
                                 : inputs->empty()      ? "the file " + options->source.input
                                                        : "files";
      RefuseCaptureWithoutCamera(*capture, LoadTrackingConfig(options->config_file).capture,
                                 options->config_file, source, std::cerr);
    }
    const bool to_folder = IsOutputFolder(options->csv_file);
    if (inputs->size() > 1 || to_folder) {
      if (!to_folder) {
        throw InputError("-o " + options->csv_file + ": with several inputs, give an output "
                         "folder (one CSV per input), e.g. -o results/");
      }
      TrackManyOptions many;
      many.common = *options;
      many.inputs = *inputs;
      many.out_dir = options->csv_file;
      many.jobs = *jobs;
      return RunTrackMany(many, std::cerr);
    }
    if (!inputs->empty()) options->source.input = inputs->front();
    if (options->source.camera) {
      // The camera's settings: the config's `capture:` section, the --camera-* options on top
      // (what it accepted is in the summary's note).
      options->source.capture = MergeCaptureOptions(
          *capture, LoadTrackingConfig(options->config_file).capture.value_or(CameraSettings{}));
    }
    RunSummary summary;
    try {
      RunTrack(*options, &summary);
    } catch (const InputError&) {
      // The error itself is reported once, by main().
      if (options->brief && summary.frames > 0) std::cerr << summary.BriefReport() << "\n";
      if (!options->quiet && !options->brief && summary.frames > 0) {
        std::cerr << summary.FullReport();
      }
      throw;
    }
    if (options->brief) {
      std::cerr << summary.BriefReport() << "\n";
    } else if (!options->quiet) {
      std::cerr << summary.FullReport() << "CSV: " << options->csv_file << "\n";
    }
    // A run a signal stopped has printed its summary; its exit code says it was interrupted.
    return ExitCodeAfterStop(0);
  };
}

}  // namespace softsight
