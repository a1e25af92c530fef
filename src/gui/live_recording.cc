#include "gui/live_recording.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "softsight/core/error.h"
#include "softsight/io/csv_columns.h"
#include "softsight/track/tracker_kind.h"

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
                             const RunInfo& info, const RecordingOrigin& origin, FrameDrawer draw,
                             std::function<void(int64_t index)> before_encode,
                             const std::vector<CsvColumn>& extra_columns)
    : prefix_(FreePrefix(base)), info_(info) {
  auto csv = std::make_unique<CsvSink>(prefix_ + ".csv", TrackingColumns(config, extra_columns));
  auto raw = std::make_unique<VideoSink>(prefix_ + ".raw.avi", "", info.fps, FrameDrawer{},
                                         before_encode);
  auto annotated = std::make_unique<VideoSink>(prefix_ + ".avi", "mjpg", info.fps, std::move(draw),
                                               before_encode);
  csv_ = csv.get();
  raw_ = raw.get();
  annotated_ = annotated.get();
  sinks_.push_back(std::move(csv));
  sinks_.push_back(std::move(raw));
  sinks_.push_back(std::move(annotated));
  saved_ = config;
  saved_.recording = origin;
  saved_.changes.clear();
  SaveTrackingConfig(saved_, prefix_ + ".yaml");
}

LiveRecording::~LiveRecording() {
  if (begun_ && !ended_) {
    RunSummary summary;
    summary.frames = frames_;
    end(summary);
  }
}

void LiveRecording::begin(const RunInfo& /*info*/) {
  for (auto& sink : sinks_) sink->begin(info_);
  begun_ = true;
}

void LiveRecording::end(const RunSummary& summary) {
  if (!begun_ || ended_) return;
  ended_ = true;
  RunSummary own = summary;
  own.frames = frames_;
  for (auto& sink : sinks_) sink->end(own);
}

void LiveRecording::consume(const Frame& frame, const FrameResult& result) {
  for (auto& sink : sinks_) sink->consume(frame, result);
  ++frames_;
}

void LiveRecording::log(ConfigChange change) {
  // The raw video's index of the frame on screen: the recording holds consecutive frames from
  // its first (a camera's dropped frames are not in it, so the source's numbers would not do).
  change.after_frame = std::max<int64_t>(0, frames_ - 1);
  // A start frame the window set (a reselection's, in the source's numbers) is already behind:
  // the new tracker starts on the next frame, live and in `track` alike.
  if (change.kind == ConfigChange::Kind::kRespec) {
    MarkerParams& params = change.spec.params;
    params.kind().start_by(params, change.after_frame);
    // Pixels the parameters hold (a template cut live) go to an image file beside the config.
    if (const cv::Mat* image = params.kind().image(params)) {
      const std::filesystem::path yaml(prefix_ + ".yaml");
      const std::string name = yaml.stem().string() + "." +
                               std::to_string(saved_.changes.size() + 1) + "." +
                               change.spec.name + ".png";
      const std::string path = (yaml.parent_path() / name).string();
      if (!cv::imwrite(path, *image)) {
        throw InputError(path + ": cannot write the template image");
      }
      change.template_file = name;  // Relative to the config, as the reader resolves it.
    }
  }
  saved_.changes.push_back(std::move(change));
  SaveTrackingConfig(saved_, prefix_ + ".yaml");
}

TrackingConfig RecordingStartConfig(const TrackingConfig& config,
                                    const std::vector<std::optional<cv::Rect>>& boxes) {
  TrackingConfig start = config;
  start.recording.reset();
  start.changes.clear();
  for (size_t i = 0; i < start.markers.size() && i < boxes.size(); ++i) {
    if (!boxes[i]) continue;
    // The recording's frame 0 is the frame on screen: the marker starts there, in its box (a
    // template is cut from that frame, so no image file holds it).
    MarkerSpec& spec = start.markers[i];
    spec.params.kind().start_in(spec.params, *boxes[i]);
    start.template_files.erase(spec.name);
  }
  return start;
}

namespace {

// A template held as pixels (cut live, or read from a file) is written as an image beside the
// config, `<config without extension>.<marker>.png`, and the config names it (`template: {file:
// ...}`): a rectangle on frame 0 would cut the wrong pixels (the marker has moved since). Writes
// the images and returns the config to save.
TrackingConfig WithTemplateImages(const TrackingConfig& config, const std::string& path) {
  TrackingConfig saved = config;
  const std::filesystem::path file(path);
  for (const MarkerSpec& spec : saved.markers) {
    const cv::Mat* image = spec.params.kind().image(spec.params);
    if (image == nullptr) continue;
    const std::string name = file.stem().string() + "." + spec.name + ".png";
    const std::string image_path = (file.parent_path() / name).string();
    if (!cv::imwrite(image_path, *image)) {
      throw InputError(image_path + ": cannot write the template image");
    }
    // Relative to the config, as the reader resolves it. A template selected live keeps its rect
    // and frame: `track` starts it there and then, as the selection did.
    saved.template_files[spec.name] = name;
  }
  return saved;
}

}  // namespace

void SaveLiveConfig(const TrackingConfig& config, const std::string& path) {
  SaveTrackingConfig(WithTemplateImages(config, path), path);
}

}  // namespace softsight
