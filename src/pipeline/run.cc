#include "softsight/pipeline/run.h"

#include <algorithm>
#include <chrono>
#include <deque>
#include <string>
#include <type_traits>

#include <opencv2/core.hpp>

#include "pipeline/key_frame_groups.h"
#include "softsight/core/error.h"
#include "softsight/pipeline/stereo_session.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {
bool NeedsColour(const TrackingConfig& config) {
  for (const MarkerSpec& spec : config.markers) {
    if (spec.params.kind().needs_colour(spec.params)) return true;
  }
  return false;
}

std::string GrayFrameProblem() {
  return "colour tracking needs colour (use --method zncc, which matches in gray, or a "
         "gray-level range `gray: [lo, hi]` for white or black markers)";
}

std::string NoFramesProblem(const std::string& source) {
  return source + ": no frames to read (an empty video or folder, a start past its end, or frames "
                  "that cannot be decoded)";
}

RunInfo DescribeMarkers(const TrackingConfig& config) {
  RunInfo info;
  for (const MarkerSpec& spec : config.markers) info.marker_names.push_back(spec.name);
  const MetricModel& metric = config.measure.metric;
  info.metric = metric.scale_mm_per_px.has_value() || metric.plane_mm_from_image.has_value();
  return info;
}

RunInfo DescribeRun(const FrameSource& source, const TrackingSession& session,
                    const RunOptions& options) {
  RunInfo info = DescribeMarkers(session.config());
  info.source = source.description();
  info.fps = source.fps();
  info.live = source.is_live();
  info.frame_count = source.frame_count();
  if (options.max_frames && (!info.frame_count || *options.max_frames < *info.frame_count)) {
    info.frame_count = options.max_frames;
  }
  return info;
}

RunInfo DescribeRun(const StereoInput& input, const StereoSession& session,
                    const RunOptions& options) {
  RunInfo info;
  info.marker_names = session.marker_names();
  info.source = input.description();
  info.fps = input.fps();
  info.live = input.is_live();
  info.frame_count = options.max_frames;
  return info;
}

namespace {

// What differs between one view's step and a pair's, for the one run below: the frame whose
// index, capture time and size stand for the input (a pair's left one), whether the session
// refuses gray frames, and what a result counts in the summary.
Frame& FirstView(Frame& frame) { return frame; }
Frame& FirstView(FramePair& pair) { return pair.left; }
const Frame& FirstView(const Frame& frame) { return frame; }
const Frame& FirstView(const FramePair& pair) { return pair.left; }

bool IsGrayInput(const Frame& frame) { return IsGrayscale(frame.image); }
bool IsGrayInput(const FramePair& pair) {
  return IsGrayscale(pair.left.image) || IsGrayscale(pair.right.image);
}

bool SessionNeedsColour(const TrackingSession& session) { return NeedsColour(session.config()); }
bool SessionNeedsColour(const StereoSession& session) {
  return NeedsColour(session.left_config()) || NeedsColour(session.right_config());
}

// A marker counts as found where its tracker found it; a frame as measured where it has an
// angle; why markers were not found is summarised per marker.
void CountResult(const FrameResult& result, RunSummary& summary) {
  for (size_t i = 0; i < result.markers.size(); ++i) {
    summary.markers[i].found += result.markers[i].observation.found() ? 1 : 0;
  }
  summary.statuses.add(result);
  summary.measured += result.measurement.angle_deg ? 1 : 0;
}
// A pair: found in 3D (both views and the checks), measured where the 3D angle is.
void CountResult(const StereoFrameResult& result, RunSummary& summary) {
  for (size_t i = 0; i < result.markers.size() && i < summary.markers.size(); ++i) {
    summary.markers[i].found += result.markers[i].point.found() ? 1 : 0;
  }
  summary.measured += result.shape.angle_deg ? 1 : 0;
}

}  // namespace

template <typename Session>
BasicPipelineRun<Session>::BasicPipelineRun(Session& session, RunInfo info,
                                            std::vector<Sink*> sinks)
    : session_(session),
      info_(std::move(info)),
      sinks_(std::move(sinks)),
      needs_colour_(SessionNeedsColour(session)),
      start_(std::chrono::steady_clock::now()),
      deliver_([this](const Input& input, const Result& result) { deliver(input, result); }) {
  summary_.source = info_.source;
  for (const std::string& name : info_.marker_names) summary_.markers.push_back({name, 0});
  if (info_.frame_count) {
    // Reserved once: the loop does not reallocate for files (cameras grow it geometrically).
    const auto frames = static_cast<size_t>(std::min<int64_t>(*info_.frame_count, int64_t{1} << 22));
    for (std::vector<double>* times : {&proc_ms_, &latency_result_ms_, &latency_done_ms_}) {
      times->reserve(frames);
    }
  }
}

template <typename Session>
void BasicPipelineRun<Session>::describe(const RunInfo& described) {
  CV_Assert(summary_.frames == 0);
  info_.source = described.source;
  info_.fps = described.fps;
  info_.live = described.live;
  info_.frame_count = described.frame_count;
  summary_.source = info_.source;
}

template <typename Session>
void BasicPipelineRun<Session>::begin_sinks() {
  for (; begun_ < sinks_.size(); ++begun_) sinks_[begun_]->begin(info_);
}

template <typename Session>
void BasicPipelineRun<Session>::join(Sink& sink) {
  // Frames held back before it joined have no image when no sink read them: it gets the frames
  // from the next one on.
  if (key_frame_groups_ && sink.uses_image()) key_frame_groups_->hold_images();
  joined_.push_back(&sink);
}

template <typename Session>
void BasicPipelineRun<Session>::leave(Sink& sink) {
  joined_.erase(std::remove(joined_.begin(), joined_.end(), &sink), joined_.end());
}

template <typename Session>
BasicPipelineRun<Session>::~BasicPipelineRun() = default;

template <typename Session>
auto BasicPipelineRun<Session>::process(Input& input) -> const Result& {
  Frame& first = FirstView(input);
  if (first.captured == std::chrono::steady_clock::time_point{}) {
    first.captured = std::chrono::steady_clock::now();
  }
  if (processed_ == 0) {
    if (needs_colour_ && IsGrayInput(input)) {
      throw InputError(summary_.source + ": the video is grayscale, but " + GrayFrameProblem());
    }
    info_.frame_size = first.image.size();
    begin_sinks();
    summary_.first_index = first.index;
  }
  const Result& result = session_.process(input);
  ++processed_;
  if (key_frame_groups_) {
    key_frame_groups_->add(input, result, deliver_);
    return result;
  }
  deliver(input, result);
  return result;
}

template <typename Session>
void BasicPipelineRun<Session>::deliver(const Input& input, const Result& result) {
  CountResult(result, summary_);
  proc_ms_.push_back(result.proc_ms);
  latency_result_ms_.push_back(result.latency_result_ms);
  for (Sink* sink : sinks_) sink->consume(input, result);
  const Frame& first = FirstView(input);
  for (Sink* sink : joined_) {
    if (first.image.empty() && sink->uses_image()) continue;  // Held before it joined (join()).
    sink->consume(input, result);
  }
  latency_done_ms_.push_back(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - first.captured)
          .count());
  ++summary_.frames;
  summary_.last_index = first.index;
}

template <typename Session>
void BasicPipelineRun<Session>::check_key_frame_groups() {
  if (!key_frame_groups_) {
    // Their images only when a sink reads them (Sink::uses_image).
    const auto reads = [](const Sink* sink) { return sink->uses_image(); };
    const bool images = std::any_of(sinks_.begin(), sinks_.end(), reads) ||
                        std::any_of(joined_.begin(), joined_.end(), reads);
    key_frame_groups_ = std::make_unique<KeyFrameCheck>(size_t{512} << 20, images);
  }
}

template <typename Session>
RunSummary BasicPipelineRun<Session>::summary() const {
  RunSummary summary = summary_;
  std::vector<double> proc = proc_ms_, result = latency_result_ms_, done = latency_done_ms_;
  SummariseTimes(proc, &summary.proc_ms_median, &summary.proc_ms_p99);
  SummariseTimes(result, &summary.latency_result_ms_median, &summary.latency_result_ms_p99);
  SummariseTimes(done, &summary.latency_done_ms_median, &summary.latency_done_ms_p99);
  summary.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  return summary;
}

template <typename Session>
RunSummary BasicPipelineRun<Session>::finish(StopReason reason, int64_t dropped,
                                             std::vector<std::string> notes, std::string error) {
  CV_Assert(!finished_);
  finished_ = true;
  if (key_frame_groups_) {
    // The last group has no key frame after it: it goes on unchecked.
    try {
      key_frame_groups_->flush(deliver_, reason == StopReason::kError);
    } catch (const InputError& e) {
      if (error.empty()) error = e.what();
      reason = StopReason::kError;
    }
    if (key_frame_groups_->demoted() > 0) {
      // A pair's: the pairs' markers no longer found in 3D.
      notes.push_back(std::to_string(key_frame_groups_->demoted()) +
                      " marker-frames not believed: moved by damage the decoder did not report, "
                      "undone at the next key frame");
    }
  }
  // An empty source, or a stop before the first frame: the sinks still see begin() and end().
  if (processed_ == 0 && reason != StopReason::kError) begin_sinks();
  RunSummary summary = this->summary();
  summary.stop_reason = reason;
  summary.dropped = dropped;
  summary.notes = std::move(notes);
  summary.error = std::move(error);
  if (describe_stop_) summary.stop_detail = describe_stop_(reason);
  for (size_t i = 0; i < begun_; ++i) sinks_[i]->end(summary);
  for (size_t i = 0; i < begun_; ++i) sinks_[i]->report(summary);
  return summary;
}

template class BasicPipelineRun<TrackingSession>;
template class BasicPipelineRun<StereoSession>;

namespace {

// What a source says beyond its frames: the frames it dropped (a camera's newest-frame reader),
// and its note (gaps in an image sequence). A pair input drops none and says how it ended in
// its own words (StereoInput::ended_first, for the command's report).
int64_t DroppedFrames(const FrameSource& source) { return source.dropped_frames(); }
int64_t DroppedFrames(const StereoInput&) { return 0; }
std::vector<std::string> SourceNotes(const FrameSource& source) {
  std::vector<std::string> notes;
  if (const std::optional<std::string> note = source.note()) notes.push_back(*note);
  return notes;
}
std::vector<std::string> SourceNotes(const StereoInput&) { return {}; }

// The one loop: read, process, hand on, until the input ends, max_frames are done, a stop is
// asked for or an InputError ends it.
template <typename Source, typename Session>
RunSummary RunLoop(Source& source, Session& session,
                   const std::vector<BasicFrameSink<typename Session::Input,
                                                    typename Session::Result>*>& sinks,
                   const RunOptions& options) {
  BasicPipelineRun<Session> run(session, DescribeRun(source, session, options), sinks);
  if (options.check_key_frame_groups) run.check_key_frame_groups();
  run.describe_stop_with(options.describe_stop);
  StopReason reason = StopReason::kEndOfInput;
  std::string error;
  typename Session::Input input;
  try {
    for (;;) {
      if (options.max_frames && run.frames() >= *options.max_frames) {
        reason = StopReason::kMaxFrames;
        break;
      }
      if (options.stop_requested && options.stop_requested()) {
        reason = StopReason::kStopRequested;
        break;
      }
      FirstView(input).captured = {};
      if (!source.read(input)) {
        reason = StopReason::kEndOfInput;
        if (run.frames() == 0) {
          // A file that ends before its first frame is a wrong input, not a run.
          reason = StopReason::kError;
          error = NoFramesProblem(run.summary().source);
        }
        break;
      }
      run.process(input);
    }
  } catch (const InputError& e) {
    reason = StopReason::kError;
    error = e.what();
  } catch (const std::exception& e) {
    // Not a user error (a bug, or a caller's own exception such as a stop raised mid-wait):
    // the sinks still close their files, then it goes on to the caller.
    run.finish(StopReason::kError, DroppedFrames(source), SourceNotes(source), e.what());
    throw;
  }
  return run.finish(reason, DroppedFrames(source), SourceNotes(source), std::move(error));
}

}  // namespace

RunSummary RunPipeline(FrameSource& source, TrackingSession& session,
                       const std::vector<FrameSink*>& sinks, const RunOptions& options) {
  return RunLoop(source, session, sinks, options);
}

RunSummary RunPipeline(StereoInput& input, StereoSession& session,
                       const std::vector<PairSink*>& sinks, const RunOptions& options) {
  return RunLoop(input, session, sinks, options);
}

// Collects the results the run delivers (after their key-frame group was checked) for next().
template <typename Source, typename Session>
class BasicRunStream<Source, Session>::Queue : public BasicFrameSink<Input, Result> {
 public:
  void consume(const Input& input, const Result& result) override {
    (void)input;
    results.push_back(result);
    ForgetViews(results.back());
  }
  std::deque<Result> results;

 private:
  // A pair's views are the session's (or the held group's) until the next pair: a result kept
  // for later does not point at them.
  static void ForgetViews(FrameResult&) {}
  static void ForgetViews(StereoFrameResult& result) {
    result.left_view = nullptr;
    result.right_view = nullptr;
  }
};

template <typename Source, typename Session>
BasicRunStream<Source, Session>::BasicRunStream(Source& source, Session& session,
                                                const RunOptions& options)
    : source_(source), options_(options), queue_(std::make_unique<Queue>()) {
  run_ = std::make_unique<BasicPipelineRun<Session>>(
      session, DescribeRun(source, session, options),
      std::vector<BasicFrameSink<Input, Result>*>{queue_.get()});
  if (options.check_key_frame_groups) run_->check_key_frame_groups();
  summary_ = run_->summary();
}

template <typename Source, typename Session>
BasicRunStream<Source, Session>::~BasicRunStream() = default;

template <typename Source, typename Session>
const RunInfo& BasicRunStream<Source, Session>::info() const {
  return run_->info();
}

// GCC 12 at -O2 takes the disengaged std::optional<cv::Vec3d> in a moved StereoFrameResult
// (Shape3d::plane_normal) for uninitialised data: a false alarm, silenced here only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
template <typename Source, typename Session>
auto BasicRunStream<Source, Session>::next() -> std::optional<Result> {
  if (queue_->results.empty() && !ended_) fill();
  if (!queue_->results.empty()) {
    std::optional<Result> result(std::in_place, std::move(queue_->results.front()));
    queue_->results.pop_front();
    ++returned_;
    return result;
  }
  // Every result is out: now the error that ended the run, once.
  if (!summary_.error.empty()) {
    std::string error;
    std::swap(error, summary_.error);
    throw InputError(error);
  }
  return std::nullopt;
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

template <typename Source, typename Session>
void BasicRunStream<Source, Session>::fill() {
  try {
    while (queue_->results.empty()) {
      if (options_.max_frames && run_->frames() >= *options_.max_frames) {
        return end(StopReason::kMaxFrames, {});
      }
      if (options_.stop_requested && options_.stop_requested()) {
        return end(StopReason::kStopRequested, {});
      }
      FirstView(input_).captured = {};
      if (!source_.read(input_)) {
        // A file that ends before its first frame is a wrong input, not a run.
        if (run_->frames() == 0) return end(StopReason::kError, NoFramesProblem(summary_.source));
        return end(StopReason::kEndOfInput, {});
      }
      run_->process(input_);
    }
  } catch (const InputError& e) {
    end(StopReason::kError, e.what());
  } catch (const std::exception& e) {
    end(StopReason::kError, e.what());
    summary_.error.clear();
    throw;
  }
}

template <typename Source, typename Session>
void BasicRunStream<Source, Session>::end(StopReason reason, std::string error) {
  ended_ = true;
  // Hands on the held group (unchecked: no key frame follows it) before the error is thrown.
  summary_ = run_->finish(reason, DroppedFrames(source_), SourceNotes(source_), std::move(error));
}

template class BasicRunStream<FrameSource, TrackingSession>;
template class BasicRunStream<StereoInput, StereoSession>;

}  // namespace softsight
