#include "softsight/pipeline/run.h"

#include <algorithm>
#include <chrono>
#include <string>

#include "softsight/core/error.h"

namespace softsight {
namespace {

// A marker whose colour range accepts gray pixels (a gray-level range, white or black dots) is
// tracked on gray video as well; only the others make a gray video an error.
bool NeedsColour(const TrackingConfig& config) {
  for (const MarkerSpec& spec : config.markers) {
    const auto* templ = std::get_if<TemplateParams>(&spec.params);
    if (templ ? templ->colour : std::get<ColourParams>(spec.params).NeedsColour()) return true;
  }
  return false;
}

}  // namespace

RunInfo DescribeRun(const FrameSource& source, const TrackingSession& session,
                    const RunOptions& options) {
  RunInfo info;
  info.source = source.description();
  info.fps = source.fps();
  info.live = source.is_live();
  info.frame_count = source.frame_count();
  if (options.max_frames && (!info.frame_count || *options.max_frames < *info.frame_count)) {
    info.frame_count = options.max_frames;
  }
  const TrackingConfig& config = session.config();
  for (const MarkerSpec& spec : config.markers) info.marker_names.push_back(spec.name);
  const MetricModel& metric = config.measure.metric;
  info.metric = metric.scale_mm_per_px.has_value() || metric.plane_mm_from_image.has_value();
  return info;
}

RunSummary RunPipeline(FrameSource& source, TrackingSession& session,
                       const std::vector<FrameSink*>& sinks, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const TrackingConfig& config = session.config();
  RunSummary summary;
  summary.source = source.description();
  RunInfo info = DescribeRun(source, session, options);
  for (const std::string& name : info.marker_names) summary.markers.push_back({name, 0});

  std::vector<double> proc_ms, latency_result_ms, latency_done_ms;
  if (info.frame_count) {
    // Reserved once: the loop does not reallocate for files (cameras grow it geometrically).
    const auto frames = static_cast<size_t>(std::min<int64_t>(*info.frame_count, int64_t{1} << 22));
    for (std::vector<double>* times : {&proc_ms, &latency_result_ms, &latency_done_ms}) {
      times->reserve(frames);
    }
  }
  size_t begun = 0;  // Sinks whose begin() has run: exactly these get end().
  const auto begin_sinks = [&] {
    for (; begun < sinks.size(); ++begun) sinks[begun]->begin(info);
  };
  const bool needs_colour = NeedsColour(config);

  const auto finish = [&] {
    summary.dropped = source.dropped_frames();
    if (const std::optional<std::string> note = source.note()) summary.notes.push_back(*note);
    SummariseTimes(proc_ms, &summary.proc_ms_median, &summary.proc_ms_p99);
    SummariseTimes(latency_result_ms, &summary.latency_result_ms_median,
                   &summary.latency_result_ms_p99);
    SummariseTimes(latency_done_ms, &summary.latency_done_ms_median, &summary.latency_done_ms_p99);
    summary.wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (size_t i = 0; i < begun; ++i) sinks[i]->end(summary);
  };

  Frame frame;
  try {
    for (;;) {
      if (options.max_frames && summary.frames >= *options.max_frames) {
        summary.stop_reason = StopReason::kMaxFrames;
        break;
      }
      if (options.stop_requested && options.stop_requested()) {
        summary.stop_reason = StopReason::kStopRequested;
        break;
      }
      frame.captured = {};
      if (!source.read(frame)) {
        summary.stop_reason = StopReason::kEndOfInput;
        break;
      }
      if (frame.captured == std::chrono::steady_clock::time_point{}) {
        frame.captured = std::chrono::steady_clock::now();
      }
      if (summary.frames == 0) {
        if (needs_colour && IsGrayscale(frame.image)) {
          throw InputError(summary.source +
                           ": the video is grayscale, but colour tracking needs colour (use "
                           "--method zncc, which matches in gray, or a gray-level range "
                           "`gray: [lo, hi]` for white or black markers)");
        }
        info.frame_size = frame.image.size();
        begin_sinks();
        summary.first_index = frame.index;
      }
      const FrameResult& result = session.process(frame);
      for (size_t i = 0; i < result.markers.size(); ++i) {
        summary.markers[i].found += result.markers[i].observation.found() ? 1 : 0;
      }
      summary.statuses.add(result);
      summary.measured += result.measurement.angle_deg ? 1 : 0;
      proc_ms.push_back(result.proc_ms);
      latency_result_ms.push_back(result.latency_result_ms);
      for (FrameSink* sink : sinks) sink->consume(frame, result);
      latency_done_ms.push_back(std::chrono::duration<double, std::milli>(
                                    std::chrono::steady_clock::now() - frame.captured)
                                    .count());
      ++summary.frames;
      summary.last_index = frame.index;
    }
    if (begun == 0) begin_sinks();  // An empty source: sinks still see begin() and end().
  } catch (const InputError& error) {
    summary.stop_reason = StopReason::kError;
    summary.error = error.what();
  } catch (const std::exception& error) {
    // Not a user error (a bug, or a caller's own exception such as a stop raised mid-wait):
    // the sinks still close their files, then it goes on to the caller.
    summary.stop_reason = StopReason::kError;
    summary.error = error.what();
    finish();
    throw;
  }
  finish();
  return summary;
}

}  // namespace softsight
