#include "softsight/pipeline/sinks.h"

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "softsight/core/error.h"

namespace softsight {
namespace {

// Frames a recording queues for its encoder (AsyncFrameWriter's buffers: 7 MB at VGA).
constexpr size_t kQueuedFrames = 8;

}  // namespace

CsvColumnTable TrackingColumns(const TrackingConfig& config, const std::vector<CsvColumn>& extra) {
  std::vector<std::string> names;
  for (const MarkerSpec& spec : config.markers) names.push_back(spec.name);
  const MetricModel& metric = config.measure.metric;
  return TrackingColumns(names, metric.scale_mm_per_px || metric.plane_mm_from_image, extra,
                         config.measure.inner_markers());
}

CsvSink::CsvSink(const std::string& path, CsvColumnTable columns)
    : writer_(path, std::move(columns)) {}

void CsvSink::begin(const RunInfo& info) {
  // Reserved once: no reallocation per row for a file (a camera's run grows it geometrically).
  if (info.frame_count) {
    row_latency_ms_.reserve(static_cast<size_t>(std::clamp<int64_t>(*info.frame_count, 0, int64_t{1} << 22)));
  }
}

void CsvSink::consume(const Frame& frame, const FrameResult& result) {
  (void)frame;
  writer_.write(result);
  if (result.captured != std::chrono::steady_clock::time_point{}) {
    row_latency_ms_.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - result.captured)
            .count());
  }
}


VideoSink::VideoSink(std::string path, std::string codec, std::optional<double> fps,
                     FrameDrawer draw, std::function<void(int64_t index)> before_encode)
    : fps_(fps), draw_(std::move(draw)), before_encode_(std::move(before_encode)) {
  options_.path = std::move(path);
  options_.codec = std::move(codec);
  options_.fps = fps.value_or(30.0);
  // Checks path and codec now.
  writer_ = std::make_unique<AsyncFrameWriter>(options_, policy_, kQueuedFrames, before_encode_);
}

void VideoSink::begin(const RunInfo& info) {
  // A camera cannot wait for the encoder; a file can, and its recording keeps every frame.
  const WhenEncoderBehind policy = info.live ? WhenEncoderBehind::kDrop : WhenEncoderBehind::kWait;
  if ((!fps_ && info.fps && *info.fps > 0.0) || policy != policy_) {
    if (!fps_ && info.fps && *info.fps > 0.0) options_.fps = *info.fps;
    policy_ = policy;
    writer_.reset();  // Nothing written yet: the file is made again with the right rate.
    writer_ = std::make_unique<AsyncFrameWriter>(options_, policy_, kQueuedFrames, before_encode_);
  }
  if (!info.frame_size.empty()) writer_->open(info.frame_size);
}

void VideoSink::consume(const Frame& frame, const FrameResult& result) {
  cv::Mat* slot = writer_->acquire();
  if (slot == nullptr) return;  // The encoder is behind a camera: dropped, and counted.
  frame.image.copyTo(*slot);    // Into the queue's own buffer: no allocation once it has one.
  if (draw_) draw_(*slot, result);
  writer_->commit(frame.index);
}

void VideoSink::end(const RunSummary& summary) {
  (void)summary;
  try {
    writer_->close();
  } catch (const InputError& e) {
    error_ = e.what();
  }
}

}  // namespace softsight
