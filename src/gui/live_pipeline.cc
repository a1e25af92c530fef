#include "gui/live_pipeline.h"

#include "gui/live_recording.h"
#include "softsight/core/error.h"

namespace softsight {

LivePipeline::LivePipeline(const TrackingConfig& config, LiveRecordingSettings settings)
    : settings_(std::move(settings)), session_(std::make_unique<TrackingSession>(config)) {
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
  // The listener points here; the session goes first, so nothing calls it after this.
  session_->set_edit_listener({});
}

const FrameResult& LivePipeline::process(const Frame& frame) {
  const FrameResult& result = session_->process(frame);
  stats_.add_result(result);
  if (recording_) {
    try {
      recording_->consume(frame, result);
    } catch (const InputError& e) {
      fail(e.what());  // A full disk: the window keeps running.
    }
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
  RunInfo info;
  info.frame_size = frame.image.size();
  info.fps = fps;
  info.live = settings_.live_source;
  for (const MarkerSpec& spec : snapshot.markers) info.marker_names.push_back(spec.name);
  const MetricModel& metric = snapshot.measure.metric;
  info.metric = metric.scale_mm_per_px || metric.plane_mm_from_image;
  // The raw video's frame 0 is this source frame: its config says so (`recording:`), so that
  // `track` on it numbers and times the rows as the source did, like the live CSV. Opening the
  // files first: when that fails, the session is as it was.
  auto recording = std::make_unique<LiveRecording>(
      settings_.prefix, snapshot, info, RecordingOrigin{frame.index, frame.time_s},
      std::move(draw), settings_.before_encode);
  // Rebuilt before the recording listens: these are its start, not edits made during it.
  for (const MarkerSpec& spec : snapshot.markers) session_->respec(spec);
  session_->reset_tip_reference();
  recording_ = std::move(recording);
  const FrameResult& result = session_->process(frame);
  try {
    recording_->consume(frame, result);
  } catch (const InputError& e) {
    fail(e.what());
  }
  return result;
}

int64_t LivePipeline::stop_recording() {
  if (!recording_) return 0;
  const int64_t frames = recording_->frames();
  last_recording_ = recording_->prefix();
  stats_.add_recording(*recording_);
  recording_.reset();  // Closes the CSV and both videos.
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

LiveRunSummary LivePipeline::summary(int64_t dropped_by_source) const {
  return stats_.summary(dropped_by_source, recording_.get());
}

}  // namespace softsight
