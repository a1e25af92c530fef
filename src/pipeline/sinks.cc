#include "softsight/pipeline/sinks.h"

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "softsight/core/error.h"
#include "softsight/io/output_guard.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/stereo_session.h"

namespace softsight {
namespace {

// Frames a recording queues for its encoder (AsyncFrameWriter's buffers: 7 MB at VGA).
constexpr size_t kQueuedFrames = 8;
// A camera's recording queues about two seconds of frames, at most this many bytes.
constexpr double kCameraQueueBytes = 256.0 * 1024 * 1024;

size_t CameraQueueFrames(cv::Size frame_size, double fps) {
  // Buffers are allocated only as the queue fills, so the depth costs memory only while the
  // encoder is behind.
  const double frame_bytes = 3.0 * std::max(1, frame_size.area());
  const double two_seconds = 2.0 * (fps > 0.0 ? fps : 30.0);
  const double by_memory = kCameraQueueBytes / frame_bytes;
  return static_cast<size_t>(std::clamp(std::min(two_seconds, by_memory),
                                        static_cast<double>(kQueuedFrames), 240.0));
}

}  // namespace

CsvColumnTable TrackingColumns(const TrackingConfig& config, const std::vector<CsvColumn>& extra) {
  const RunInfo markers = DescribeMarkers(config);
  return TrackingColumns(markers.marker_names, markers.metric, extra,
                         config.measure.inner_markers());
}

template <typename Input, typename Row>
BasicCsvSink<Input, Row>::BasicCsvSink(const std::string& path, BasicCsvColumnTable<Row> columns)
    : writer_(path, std::move(columns)) {}

template <typename Input, typename Row>
void BasicCsvSink<Input, Row>::begin(const RunInfo& info) {
  // Reserved once: no reallocation per row for a file (a camera's run grows it geometrically).
  if (info.frame_count) {
    row_latency_ms_.reserve(static_cast<size_t>(std::clamp<int64_t>(*info.frame_count, 0, int64_t{1} << 22)));
  }
}

template <typename Input, typename Row>
void BasicCsvSink<Input, Row>::report(RunSummary& summary) const {
  if (row_latency_ms_.empty()) return;
  std::vector<double> sorted = row_latency_ms_;  // SummariseTimes sorts; once per run.
  double median = 0.0, p99 = 0.0;
  SummariseTimes(sorted, &median, &p99);
  summary.latency_row_ms_median = median;
  summary.latency_row_ms_p99 = p99;
}

template <typename Input, typename Row>
void BasicCsvSink<Input, Row>::consume(const Input& input, const Row& row) {
  (void)input;
  writer_.write(row);
  if (row.captured != std::chrono::steady_clock::time_point{}) {
    row_latency_ms_.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - row.captured)
            .count());
  }
}

template class BasicCsvSink<Frame, FrameResult>;
template class BasicCsvSink<FramePair, StereoFrameResult>;

VideoSink::VideoSink(std::string path, std::string codec, std::optional<double> fps,
                     FrameDrawer draw, std::function<void(int64_t index)> before_encode)
    : fps_(fps), draw_(std::move(draw)), before_encode_(std::move(before_encode)) {
  options_.path = std::move(path);
  options_.codec = std::move(codec);
  options_.fps = fps.value_or(30.0);
  // Checks path and codec now, and locks the video (FrameWriter): a second run writing it is
  // refused here.
  capacity_ = kQueuedFrames;
  writer_ = std::make_unique<AsyncFrameWriter>(options_, capacity_, before_encode_);
}

VideoSink::~VideoSink() = default;

void VideoSink::begin(const RunInfo& info) {
  live_ = info.live;
  // Every frame is kept (the recording and the CSV hold the same frames). A camera gets a deeper
  // queue: its frames keep coming while the encoder has a hiccup.
  const size_t capacity =
      info.live ? CameraQueueFrames(info.frame_size, info.fps.value_or(options_.fps)) : kQueuedFrames;
  if ((!fps_ && info.fps && *info.fps > 0.0) || capacity != capacity_) {
    if (!fps_ && info.fps && *info.fps > 0.0) options_.fps = *info.fps;
    capacity_ = capacity;
    writer_.reset();  // Nothing written yet: the file is made again with the right rate.
    writer_ = std::make_unique<AsyncFrameWriter>(options_, capacity_, before_encode_);
  }
  if (!info.frame_size.empty()) writer_->open(info.frame_size);
}

void VideoSink::consume(const Frame& frame, const FrameResult& result) {
  cv::Mat* slot = writer_->acquire();  // Waits while the queue is full (counted).
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

void VideoSink::report(RunSummary& summary) const {
  if (error_ && summary.ok()) {
    summary.stop_reason = StopReason::kError;
    summary.error = *error_;
  }
  // A recording keeps every frame of the CSV. Never silent: an encoder that fell a whole queue
  // behind held up the run (a camera's frames skipped meanwhile are the source's drops, counted
  // in the summary). A camera's run says so also when it did not.
  const int64_t waited = waited_frames();
  if (waited > 0 || live_) {
    summary.notes.push_back(path() + ": all " + std::to_string(summary.frames) + " frames recorded" +
                            (waited > 0 ? "; the encoder fell behind and held up the run at " +
                                              std::to_string(waited) + " of them"
                                        : " (the encoder kept up)"));
  }
}

}  // namespace softsight
