#include "gui/live_pipeline.h"

#include "gui/live_recording.h"
#include "softsight/core/error.h"

namespace softsight {

LivePipeline::LivePipeline(const TrackingConfig& config, LiveRecordingSettings settings,
                           std::vector<FrameSink*> sinks)
    : settings_(std::move(settings)), session_(std::make_unique<TrackingSession>(config)) {
  RunInfo info = DescribeMarkers(config);
  info.source = "live";
  run_ = std::make_unique<PipelineRun>(*session_, std::move(info), std::move(sinks));
  in_run_ = std::make_unique<RecordingInRun>(*this);
  session_->set_edit_listener([this](const ConfigChange& change) {
    if (!recording_) return;
    try {
      recording_->log(change);
    } catch (const InputError& e) {
      // The recording could not keep the edit, so it no longer reproduces the window.
      fail(e.what());
    }
  });
}

LivePipeline::~LivePipeline() {
  stop_recording();
  session_->set_edit_listener({});
}

void LivePipeline::describe_source(const FrameSource& source) { run_->describe_source(source); }

// The recording in the run: a frame it cannot take (a full disk) is kept as the reason to stop
// it once the run has handed the frame to every sink (not while it does).
class LivePipeline::RecordingInRun : public FrameSink {
 public:
  explicit RecordingInRun(LivePipeline& owner) : owner_(owner) {}
  void begin(const RunInfo&) override {}  // The pipeline begins and ends the recording.
  void consume(const Frame& frame, const FrameResult& result) override {
    if (!owner_.recording_ || owner_.frame_failure_) return;
    try {
      owner_.recording_->consume(frame, result);
    } catch (const InputError& e) {
      owner_.frame_failure_ = e.what();
    }
  }
  void end(const RunSummary&) override {}

 private:
  LivePipeline& owner_;
};

const FrameResult& LivePipeline::process(const Frame& frame) {
  Frame stamped = frame;  // A shallow copy: the run stamps an unset capture time.
  const FrameResult& result = run_->process(stamped);
  if (frame_failure_) {
    const std::string why = *frame_failure_;
    frame_failure_.reset();
    fail(why);  // The window keeps running.
  }
  return result;
}

const FrameResult& LivePipeline::measure_again(const Frame& frame) {
  return session_->process(frame);
}

const FrameResult& LivePipeline::start_recording(
    const Frame& frame, const std::vector<std::optional<cv::Rect>>& boxes, double fps,
    FrameDrawer draw) {
  if (recording_) stop_recording();
  const TrackingConfig snapshot = RecordingStartConfig(config(), boxes);
  RunInfo info = DescribeMarkers(snapshot);
  info.source = run_->info().source;
  info.frame_size = frame.image.size();
  info.fps = fps;
  // A camera's videos get a deeper queue (VideoSink), so a hiccup of the encoder does not hold
  // up the window; they still keep every frame.
  info.live = run_->info().live;
  // The raw video's frame 0 is this source frame: its config says so (`recording:`), so that
  // `track` on it numbers and times the rows as the source did, like the live CSV. Opening the
  // files first: when that fails, the session is as it was.
  auto recording = std::make_unique<LiveRecording>(
      settings_.prefix, snapshot, info, RecordingOrigin{frame.index, frame.time_s},
      std::move(draw), settings_.before_encode, settings_.extra_columns);
  recording->begin(info);
  // Built afresh from the recording's config before the recording listens (these are its start,
  // not edits made during it): `track` on the recording starts from that config alone, without
  // what this session learned before (the body's arrangement, the markers' motion).
  session_->restart(snapshot);
  recording_ = std::move(recording);
  // The frame on screen again, as the recording's first row (the run counted it already).
  const FrameResult& result = session_->process(frame);
  try {
    recording_->consume(frame, result);
    run_->join(*in_run_);
  } catch (const InputError& e) {
    fail(e.what());
  }
  return result;
}

int64_t LivePipeline::stop_recording() {
  if (!recording_) return 0;
  run_->leave(*in_run_);
  recording_->end(run_->summary());  // Closes the CSV and both videos.
  const int64_t frames = recording_->frames();
  last_recording_ = recording_->prefix();
  count_recording(*recording_, &row_ms_, &notes_, &recorded_, &encoder_waits_);
  recording_.reset();
  return frames;
}

std::string LivePipeline::recording_prefix() const {
  return recording_ ? recording_->prefix() : std::string();
}

void LivePipeline::fail(const std::string& why) {
  const int64_t frames = stop_recording();
  failure_ = "recorded " + std::to_string(frames) + " frames to " + last_recording_ + ".*; " + why;
}

std::optional<std::string> LivePipeline::take_recording_failure() {
  std::optional<std::string> failure;
  failure.swap(failure_);
  return failure;
}

void LivePipeline::count_recording(const LiveRecording& recording, std::vector<double>* row_ms,
                                   std::vector<std::string>* notes, int64_t* recorded,
                                   int64_t* waits) const {
  const std::vector<double>& rows = recording.row_latencies_ms();
  row_ms->insert(row_ms->end(), rows.begin(), rows.end());
  *recorded += recording.frames();
  *waits += recording.encoder_waits();
  std::string note = recording.prefix() + ".*: recorded " + std::to_string(recording.frames()) +
                     " frames, each in the CSV and both videos";
  note += recording.encoder_waits() == 0
              ? " (the encoders kept up)"
              : "; the encoders fell behind and held up the window " +
                    std::to_string(recording.encoder_waits()) + " times";
  notes->push_back(std::move(note));
}

LiveRunSummary LivePipeline::summary(int64_t dropped_by_source) const {
  LiveRunSummary out;
  out.run = run_->summary();
  out.run.dropped = dropped_by_source;
  out.run.stop_reason = StopReason::kStopRequested;
  out.run.stop_detail = "the window was closed";
  std::vector<double> row_ms = row_ms_;
  out.run.notes = notes_;
  out.recorded_frames = recorded_;
  out.encoder_waits = encoder_waits_;
  if (recording_) {  // Still open: counted as the window closes it.
    count_recording(*recording_, &row_ms, &out.run.notes, &out.recorded_frames,
                    &out.encoder_waits);
  }
  if (!row_ms.empty()) {
    double median = 0.0, p99 = 0.0;
    SummariseTimes(row_ms, &median, &p99);
    out.run.latency_row_ms_median = median;
    out.run.latency_row_ms_p99 = p99;
  }
  if (out.recorded_frames == 0) out.run.notes.push_back("nothing recorded");
  return out;
}

}  // namespace softsight
