#include "gui/live_recording.h"

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "softsight/core/error.h"
#include "softsight/io/csv_columns.h"

namespace softsight {
namespace {

constexpr int kMaxRecordings = 999;

std::string FreePrefix(const std::string& base) {
  for (int n = 1; n <= kMaxRecordings; ++n) {
    char number[16];
    std::snprintf(number, sizeof(number), "-%03d", n);
    const std::string prefix = base + number;
    if (!std::filesystem::exists(prefix + ".csv")) return prefix;
  }
  throw InputError(base + "-*.csv: all " + std::to_string(kMaxRecordings) +
                   " recording numbers are taken; choose another --record-prefix");
}

}  // namespace

LiveRecording::LiveRecording(const std::string& base, const TrackingConfig& config,
                             const RunInfo& info, const RecordingOrigin& origin, FrameDrawer draw)
    : prefix_(FreePrefix(base)) {
  sinks_.push_back(
      std::make_unique<CsvSink>(prefix_ + ".csv", TrackingColumns(config)));
  sinks_.push_back(std::make_unique<VideoSink>(prefix_ + ".raw.avi", "", info.fps));
  sinks_.push_back(std::make_unique<VideoSink>(prefix_ + ".avi", "mjpg", info.fps, std::move(draw)));
  for (auto& sink : sinks_) sink->begin(info);
  TrackingConfig saved = config;
  saved.recording = origin;
  SaveTrackingConfig(saved, prefix_ + ".yaml");
}

LiveRecording::~LiveRecording() {
  RunSummary summary;
  summary.frames = frames_;
  for (auto& sink : sinks_) sink->end(summary);
}

void LiveRecording::consume(const Frame& frame, const FrameResult& result) {
  for (auto& sink : sinks_) sink->consume(frame, result);
  ++frames_;
}

namespace {

// A template held as pixels (cut live, or read from a file) is written as an image beside the
// config, `<config without extension>.<marker>.png`, and the config names it (`template: {file:
// ...}`): a rectangle on frame 0 would cut the wrong pixels (the marker has moved since). Writes
// the images and returns the config to save.
TrackingConfig WithTemplateImages(const TrackingConfig& config, const std::string& path) {
  TrackingConfig saved = config;
  const std::filesystem::path file(path);
  for (MarkerSpec& spec : saved.markers) {
    if (!IsTemplateMethod(spec.method) || spec.templ.image.empty()) continue;
    const std::string name = file.stem().string() + "." + spec.name + ".png";
    const std::string image_path = (file.parent_path() / name).string();
    if (!cv::imwrite(image_path, spec.templ.image)) {
      throw InputError(image_path + ": cannot write the template image");
    }
    // Relative to the config, as the reader resolves it. A template selected live keeps its rect
    // and frame: `track` starts it there and then, as the selection did.
    spec.templ.image_file = name;
  }
  return saved;
}

}  // namespace

void SaveLiveConfig(const TrackingConfig& config, const std::string& path) {
  SaveTrackingConfig(WithTemplateImages(config, path), path);
}

}  // namespace softsight
