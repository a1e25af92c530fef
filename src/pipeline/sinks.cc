#include "softsight/pipeline/sinks.h"

#include <string>
#include <utility>
#include <vector>

namespace softsight {

CsvColumnTable TrackingColumns(const TrackingConfig& config, const std::vector<CsvColumn>& extra) {
  std::vector<std::string> names;
  for (const MarkerSpec& spec : config.markers) names.push_back(spec.name);
  const MetricModel& metric = config.measure.metric;
  return TrackingColumns(names, metric.scale_mm_per_px || metric.plane_mm_from_image, extra,
                         config.measure.inner_markers());
}

CsvSink::CsvSink(const std::string& path, CsvColumnTable columns)
    : writer_(path, std::move(columns)) {}

void CsvSink::consume(const Frame& frame, const FrameResult& result) {
  (void)frame;
  writer_.write(result);
}

VideoSink::VideoSink(std::string path, std::string codec, std::optional<double> fps,
                     FrameDrawer draw)
    : fps_(fps), draw_(std::move(draw)) {
  options_.path = std::move(path);
  options_.codec = std::move(codec);
  options_.fps = fps.value_or(30.0);
  writer_ = std::make_unique<FrameWriter>(options_);  // Checks path and codec now.
}

void VideoSink::begin(const RunInfo& info) {
  if (!fps_ && info.fps && *info.fps > 0.0) {
    options_.fps = *info.fps;
    writer_ = std::make_unique<FrameWriter>(options_);
  }
  if (!info.frame_size.empty()) writer_->open(info.frame_size);
}

void VideoSink::consume(const Frame& frame, const FrameResult& result) {
  if (!draw_) {
    writer_->write(frame.image, frame.index);
    return;
  }
  frame.image.copyTo(canvas_);
  draw_(canvas_, result);
  writer_->write(canvas_, frame.index);
}

void VideoSink::end(const RunSummary& summary) {
  (void)summary;
  writer_->close();
}

}  // namespace softsight
