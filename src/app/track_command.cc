#include "app/track_command.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "app/commands.h"
#include "app/progress.h"
#include "app/stop_request.h"
#include "softsight/core/error.h"
#include <opencv2/videoio.hpp>

#include "softsight/gui/overlay.h"
#include "softsight/io/csv_writer.h"
#include "softsight/pipeline/tracking_session.h"

namespace softsight {
namespace {

void CheckRunnable(const TrackingConfig& config, const TrackOptions& options) {
  for (const MarkerSpec& spec : config.markers) {
    if (IsTemplateMethod(spec.method) && spec.templ.image.empty() && !spec.templ.rect) {
      throw InputError(options.config_file + ": marker '" + spec.name + "' uses template matching (" +
                       spec.method +
                       ") but has no template: give `template: {frame: 0, rect: [x, y, w, h]}` "
                       "or `template: {file: marker.png}`");
    }
  }
}

// The annotated video: every frame with the overlay drawn on it. Opened on the first frame,
// when the size is known; MJPG keeps files small (the overlay is for people, not measurement).
class AnnotatedVideo {
 public:
  AnnotatedVideo(std::string path, double fps, OverlayOptions overlay)
      : path_(std::move(path)), fps_(fps), overlay_(std::move(overlay)) {}

  void write(const Frame& frame, const FrameResult& result) {
    if (!writer_.isOpened()) {
      if (!writer_.open(path_, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps_,
                        frame.image.size())) {
        throw InputError(path_ + ": cannot write the annotated video (use a .avi name in a "
                         "writable folder)");
      }
    }
    frame.image.copyTo(canvas_);
    DrawOverlay(canvas_, result, overlay_);
    writer_.write(canvas_);
  }

 private:
  std::string path_;
  double fps_;
  OverlayOptions overlay_;
  cv::VideoWriter writer_;
  cv::Mat canvas_;
};

bool NeedsColour(const TrackingConfig& config) {
  for (const MarkerSpec& spec : config.markers) {
    if (!IsTemplateMethod(spec.method) || spec.templ.colour) return true;
  }
  return false;
}

}  // namespace

void SummariseTimes(std::vector<double> proc_ms, TrackSummary* summary) {
  if (proc_ms.empty()) return;
  std::sort(proc_ms.begin(), proc_ms.end());
  summary->proc_ms_median = proc_ms[proc_ms.size() / 2];
  const size_t p99 = std::min(proc_ms.size() - 1,
                              static_cast<size_t>(0.99 * static_cast<double>(proc_ms.size())));
  summary->proc_ms_p99 = proc_ms[p99];
}

TrackSummary RunTrack(const TrackOptions& options, TrackSummary* summary_out) {
  TrackSummary local;
  TrackSummary& summary = summary_out != nullptr ? *summary_out : local;
  summary = TrackSummary{};

  TrackingConfig config = LoadTrackingConfig(options.config_file, options.method);
  if (options.template_colour) {
    for (MarkerSpec& spec : config.markers) spec.templ.colour = *options.template_colour;
  }
  CheckRunnable(config, options);
  std::unique_ptr<FrameSource> source = OpenFrameSource(options.source);
  TrackingSession session(config);
  std::vector<std::string> names;
  for (const MarkerSpec& spec : config.markers) names.push_back(spec.name);
  const MetricModel& metric = config.measure.metric;
  CsvWriter csv(options.csv_file, names, metric.scale_mm_per_px || metric.plane_mm_from_image);

  std::optional<AnnotatedVideo> annotated;
  if (options.annotated_file) {
    annotated.emplace(*options.annotated_file, source->fps().value_or(30.0),
                      OverlayOptionsFor(config.measure));
  }
  summary.marker_names = names;
  summary.found.assign(names.size(), 0);
  std::optional<int64_t> total = source->frame_count();
  if (options.max_frames && (!total || *options.max_frames < *total)) total = options.max_frames;
  ProgressBar progress("track", total, !options.quiet);
  std::vector<double> proc_ms;
  if (total) proc_ms.reserve(static_cast<size_t>(*total));
  const auto start = std::chrono::steady_clock::now();
  auto finish = [&](const std::string& reason) {
    progress.finish();
    summary.stop_reason = reason;
    summary.wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    SummariseTimes(proc_ms, &summary);
  };

  Frame frame;
  const StopRequest stop;  // Ctrl-C ends a camera run (or a long file) with its summary.
  bool interrupted = false;
  try {
    while (!options.max_frames || summary.frames < *options.max_frames) {
      if (stop.requested()) {
        interrupted = true;
        break;
      }
      if (!source->read(frame)) break;
      if (summary.frames == 0 && NeedsColour(config) && IsGrayscale(frame.image)) {
        throw InputError(source->description() +
                         ": the video is grayscale, but colour tracking needs colour (use "
                         "--method zncc, which matches in gray)");
      }
      const FrameResult& result = session.process(frame);
      csv.write(result);
      if (annotated) annotated->write(frame, result);
      for (size_t i = 0; i < result.markers.size(); ++i) {
        summary.found[i] += result.markers[i].observation.found() ? 1 : 0;
      }
      summary.measured += result.measurement.angle_deg ? 1 : 0;
      proc_ms.push_back(result.proc_ms);
      ++summary.frames;
      progress.update(summary.frames);
    }
  } catch (const InputError&) {
    finish("stopped by an error at frame " + std::to_string(summary.frames));
    throw;
  }
  finish(interrupted ? "stopped by Ctrl-C"
         : options.max_frames && summary.frames >= *options.max_frames ? "--max-frames reached"
                                                                       : "end of input");
  return summary;
}

std::string FormatSummary(const TrackSummary& summary) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof(line), "frames: %lld in %.2f s (%s)\n",
                static_cast<long long>(summary.frames), summary.wall_s,
                summary.stop_reason.c_str());
  out << line;
  for (size_t i = 0; i < summary.marker_names.size(); ++i) {
    const double rate = summary.frames > 0 ? 100.0 * summary.found[i] / summary.frames : 0.0;
    std::snprintf(line, sizeof(line), "  %-12s found in %lld frames (%.1f %%)\n",
                  summary.marker_names[i].c_str(), static_cast<long long>(summary.found[i]), rate);
    out << line;
  }
  std::snprintf(line, sizeof(line), "angle measured in %lld frames\n",
                static_cast<long long>(summary.measured));
  out << line;
  std::snprintf(line, sizeof(line), "processing per frame: median %.3f ms, p99 %.3f ms\n",
                summary.proc_ms_median, summary.proc_ms_p99);
  out << line;
  return out.str();
}

CommandRunner SetupTrackCommand(CLI::App& sub) {
  auto options = std::make_shared<TrackOptions>();
  sub.description(
      "Track the markers of a config in a video (or image sequence) and write one CSV row per\n"
      "frame: every marker's centroid, the bending angle, chord, sagitta, radius of curvature,\n"
      "arc length and bending distance (in mm too when the config gives a scale).\n"
      "Examples:\n"
      "  softsight track --config examples/markers.yaml --input run.avi --csv run.csv\n"
      "  softsight track --config markers.yaml --camera 0 --csv bench.csv   (Ctrl-C stops)");
  sub.add_option("-c,--config", options->config_file, "Marker config (YAML), see examples/")
      ->required()
      ->check(CLI::ExistingFile);
  CLI::Option* input = sub.add_option("-i,--input", options->source.input,
                 "Video file, folder of images, printf pattern such as frames/%04d.png, or a "
                 "built-in scene: synth:bending, synth:wedge1, synth:wedge4")
      ;
  sub.add_option("--camera", options->source.camera,
                 "Camera index (V4L2) instead of --input: tracks until Ctrl-C or --max-frames")
      ->excludes(input);
  sub.add_option("-o,--csv", options->csv_file, "Where to write the per-frame CSV")->required();
  sub.add_option("-m,--method", options->method,
                 "Use this method for every marker: colour, sad, ssd or zncc");
  CLI::Option* gray = sub.add_flag_function(
      "--gray", [options](int64_t) { options->template_colour = false; },
      "Template matching on gray frames (the default unless the config says colour)");
  sub.add_flag_function(
         "--colour", [options](int64_t) { options->template_colour = true; },
         "Template matching on BGR frames: 3x the work, tells same-shape markers of different "
         "colours apart")
      ->excludes(gray);
  sub.add_option("--annotated", options->annotated_file,
                 "Also write a video with the overlay drawn on each frame (.avi)");
  sub.add_option("--fps", options->source.sequence_fps,
                 "Frame rate of an image sequence, for its timestamps")
      ->capture_default_str();
  sub.add_option("--max-frames", options->max_frames, "Stop after this many frames");
  sub.add_flag("-q,--quiet", options->quiet, "No progress bar and no summary");
  return [options] {
    TrackSummary summary;
    try {
      RunTrack(*options, &summary);
    } catch (const InputError&) {
      if (!options->quiet && summary.frames > 0) std::cerr << FormatSummary(summary);
      throw;
    }
    if (!options->quiet) {
      std::cerr << FormatSummary(summary) << "CSV: " << options->csv_file << "\n";
    }
    return 0;
  };
}

}  // namespace softsight
