#include "softsight/io/frame_source.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <variant>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "softsight/core/error.h"
#include "softsight/sim/builtin_scenes.h"

namespace softsight {
namespace fs = std::filesystem;
namespace {

// Decoders hand back gray or BGRA for some files; everything downstream expects 8-bit BGR.
void ToBgr(const cv::Mat& decoded, cv::Mat& bgr) {
  if (decoded.type() == CV_8UC3) {
    if (decoded.data != bgr.data) decoded.copyTo(bgr);
  } else if (decoded.type() == CV_8UC1) {
    cv::cvtColor(decoded, bgr, cv::COLOR_GRAY2BGR);
  } else if (decoded.type() == CV_8UC4) {
    cv::cvtColor(decoded, bgr, cv::COLOR_BGRA2BGR);
  } else {
    cv::Mat eight_bit;
    decoded.convertTo(eight_bit, CV_8U, decoded.depth() == CV_16U ? 1.0 / 256.0 : 1.0);
    ToBgr(eight_bit, bgr);
  }
}

class VideoFileSource : public FrameSource {
 public:
  explicit VideoFileSource(const std::string& path) : path_(path) {
    if (!fs::exists(path)) throw InputError(path + ": no such video file");
    if (!capture_.open(path, cv::CAP_FFMPEG) || !capture_.isOpened()) {
      throw InputError(path + ": cannot open as a video (unsupported, truncated or corrupt file)");
    }
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    if (count > 0) frame_count_ = static_cast<int64_t>(count);
    const double fps = capture_.get(cv::CAP_PROP_FPS);
    if (fps > 0 && fps < 100000) fps_ = fps;
  }

  bool read(Frame& frame) override {
    if (!capture_.read(decoded_) || decoded_.empty()) {
      // Tell "the stream ended" from "a frame failed to decode": a decoder that can still grab a
      // later frame skipped a broken one, and a header promising more frames means truncation.
      bool later_frame_decodes = false;
      for (int attempt = 0; attempt < 3 && !later_frame_decodes; ++attempt) {
        later_frame_decodes = capture_.grab();
      }
      if (later_frame_decodes) {
        throw InputError(path_ + ": frame " + std::to_string(next_index_) +
                         " failed to decode (corrupt video)");
      }
      // FFmpeg skips a frame it cannot decode without saying so; the header's frame count is the
      // only witness, so a shortfall is reported (at the end: the rows before stay valid).
      if (frame_count_ && next_index_ < *frame_count_) {
        throw InputError(path_ + ": only " + std::to_string(next_index_) + " of the " +
                         std::to_string(*frame_count_) +
                         " frames its header lists could be decoded (truncated or corrupt file; "
                         "rows after the damage may be misnumbered)");
      }
      return false;
    }
    ToBgr(decoded_, frame.image);
    frame.index = next_index_++;
    const double pos_ms = capture_.get(cv::CAP_PROP_POS_MSEC);
    // Container timestamps when the demuxer has them; the nominal rate otherwise.
    frame.time_s = (pos_ms > 0 || frame.index == 0) ? pos_ms / 1000.0
                                                    : frame.index / fps_.value_or(30.0);
    if (frame.index > 0 && frame.time_s <= last_time_s_) {
      frame.time_s = frame.index / fps_.value_or(30.0);
    }
    last_time_s_ = frame.time_s;
    return true;
  }

  std::string description() const override { return "video " + path_; }
  std::optional<int64_t> frame_count() const override { return frame_count_; }
  std::optional<double> fps() const override { return fps_; }

 private:
  std::string path_;
  cv::VideoCapture capture_;
  cv::Mat decoded_;
  int64_t next_index_ = 0;
  double last_time_s_ = -1.0;
  std::optional<int64_t> frame_count_;
  std::optional<double> fps_;
};

bool IsImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  static const char* kExtensions[] = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm",
                                      ".pgm", ".webp"};
  return std::any_of(std::begin(kExtensions), std::end(kExtensions),
                     [&](const char* e) { return ext == e; });
}

class ImageSequenceSource : public FrameSource {
 public:
  ImageSequenceSource(std::vector<std::string> files, std::string description, double fps)
      : files_(std::move(files)), description_(std::move(description)), fps_(fps) {}

  bool read(Frame& frame) override {
    if (next_index_ >= static_cast<int64_t>(files_.size())) return false;
    const std::string& file = files_[next_index_];
    decoded_ = cv::imread(file, cv::IMREAD_UNCHANGED);
    if (decoded_.empty()) {
      throw InputError(file + ": frame " + std::to_string(next_index_) +
                       " cannot be read as an image (corrupt or not an image)");
    }
    ToBgr(decoded_, frame.image);
    frame.index = next_index_++;
    frame.time_s = frame.index / fps_;
    return true;
  }

  std::string description() const override { return description_; }
  std::optional<int64_t> frame_count() const override {
    return static_cast<int64_t>(files_.size());
  }
  std::optional<double> fps() const override { return fps_; }

 private:
  std::vector<std::string> files_;
  std::string description_;
  double fps_;
  cv::Mat decoded_;
  int64_t next_index_ = 0;
};

std::unique_ptr<FrameSource> OpenFolder(const std::string& folder, double fps) {
  std::vector<std::string> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && IsImageFile(entry.path())) files.push_back(entry.path().string());
  }
  if (files.empty()) throw InputError(folder + ": folder holds no image files");
  std::sort(files.begin(), files.end());
  return std::make_unique<ImageSequenceSource>(std::move(files), "images " + folder, fps);
}

std::string FormatIndex(const std::string& pattern, int index) {
  std::vector<char> name(pattern.size() + 32);
  std::snprintf(name.data(), name.size(), pattern.c_str(), index);
  return name.data();
}

std::unique_ptr<FrameSource> OpenPattern(const std::string& pattern, double fps) {
  // Sequences start at 0 or 1 and end at the first missing index.
  int start = 0;
  if (!fs::exists(FormatIndex(pattern, start))) start = 1;
  std::vector<std::string> files;
  for (int index = start; fs::exists(FormatIndex(pattern, index)); ++index) {
    files.push_back(FormatIndex(pattern, index));
  }
  if (files.empty()) {
    throw InputError(pattern + ": no image matches this pattern (tried indices 0 and 1)");
  }
  return std::make_unique<ImageSequenceSource>(std::move(files), "images " + pattern, fps);
}

class CameraSource : public FrameSource {
 public:
  explicit CameraSource(int index) : index_(index) {
    if (!capture_.open(index, cv::CAP_V4L2) || !capture_.isOpened()) {
      throw InputError("camera " + std::to_string(index) +
                       ": cannot open (is it plugged in? try `ls /dev/video*`)");
    }
    start_ = std::chrono::steady_clock::now();
  }

  bool read(Frame& frame) override {
    if (!capture_.read(decoded_) || decoded_.empty()) {
      throw InputError("camera " + std::to_string(index_) + ": frame " +
                       std::to_string(next_index_) + " could not be captured (unplugged?)");
    }
    ToBgr(decoded_, frame.image);
    frame.index = next_index_++;
    frame.time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    return true;
  }

  std::string description() const override { return "camera " + std::to_string(index_); }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override {
    const double fps = capture_.get(cv::CAP_PROP_FPS);
    return fps > 0 ? std::optional<double>(fps) : std::nullopt;
  }
  bool is_live() const override { return true; }

 private:
  int index_;
  cv::VideoCapture capture_;
  cv::Mat decoded_;
  int64_t next_index_ = 0;
  std::chrono::steady_clock::time_point start_;
};

// Any rendered scene (SyntheticScene, PlateScene) as a source.
template <class Scene>
class SyntheticSource : public FrameSource {
 public:
  template <class Options>
  SyntheticSource(const Options& scene, const NoiseOptions& noise, std::string description)
      : scene_(scene, noise), description_(std::move(description)) {}

  bool read(Frame& frame) override {
    if (next_index_ >= scene_.frame_count()) return false;
    const SceneTruth truth = scene_.render(next_index_, frame.image);
    frame.index = next_index_++;
    frame.time_s = truth.time_s;
    return true;
  }
  std::string description() const override { return description_; }
  std::optional<int64_t> frame_count() const override { return scene_.frame_count(); }
  std::optional<double> fps() const override { return scene_.options().fps; }

 private:
  Scene scene_;
  std::string description_;
  int next_index_ = 0;
};

}  // namespace

bool IsGrayscale(const cv::Mat& frame_bgr) {
  CV_Assert(frame_bgr.type() == CV_8UC3);
  for (int y = 0; y < frame_bgr.rows; ++y) {
    const cv::Vec3b* row = frame_bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < frame_bgr.cols; ++x) {
      // Compression may leave the chroma a level or two off pure gray.
      if (std::abs(row[x][0] - row[x][1]) > 2 || std::abs(row[x][1] - row[x][2]) > 2) return false;
    }
  }
  return true;
}

std::unique_ptr<FrameSource> OpenFrameSource(const FrameSourceSpec& spec) {
  if (spec.camera) return std::make_unique<CameraSource>(*spec.camera);
  const std::string& input = spec.input;
  if (input.empty()) {
    throw InputError("no input given (use --input VIDEO|FOLDER|PATTERN or --camera N)");
  }
  if (!(spec.sequence_fps > 0)) throw InputError("--fps must be positive");
  if (input.rfind(kSyntheticPrefix, 0) == 0) {
    const BuiltinSceneOptions scene =
        ParseBuiltinScene(input.substr(std::string(kSyntheticPrefix).size()));
    return std::visit([](const auto& o) { return OpenSyntheticSource(o, NoiseOptions{}); }, scene);
  }
  if (input.find('%') != std::string::npos) return OpenPattern(input, spec.sequence_fps);
  if (fs::is_directory(input)) return OpenFolder(input, spec.sequence_fps);
  if (!fs::exists(input)) throw InputError(input + ": no such file or folder");
  if (IsImageFile(input)) {
    return std::make_unique<ImageSequenceSource>(std::vector<std::string>{input}, "image " + input,
                                                 spec.sequence_fps);
  }
  return std::make_unique<VideoFileSource>(input);
}

std::unique_ptr<FrameSource> OpenSyntheticSource(const SceneOptions& scene,
                                                 const NoiseOptions& noise) {
  std::string description = std::string("synthetic scene ") + SceneKindName(scene.kind);
  if (scene.background == BackgroundKind::kBench) description += " on the textured bench";
  return std::make_unique<SyntheticSource<SyntheticScene>>(scene, noise, std::move(description));
}

std::unique_ptr<FrameSource> OpenSyntheticSource(const PlateSceneOptions& scene,
                                                 const NoiseOptions& noise) {
  return std::make_unique<SyntheticSource<PlateScene>>(scene, noise, "synthetic scene plate");
}

}  // namespace softsight
