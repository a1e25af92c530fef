// Seeking in a long recording, as the live window's End key does it: a 10-minute 640x480 video
// (18000 frames at 30 fps) in each codec a recording uses, rendered once into a temporary folder
// (removed at exit), then timed from opening the file to the last frame in hand, and from a frame
// to one in the middle of the file. The bar: within 0.3 s. Rendering the files is set-up,
// outside the timed loops (minutes: the FFV1 encoder is the slow one).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <unistd.h>

#include "gui/seekable_source.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 10 * 60 * 30;

// The temporary folder and the files rendered in it, removed when the program ends.
class LongVideos {
 public:
  ~LongVideos() {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  // A 10-minute file in `fourcc`: a moving disc and the frame number on a grey ramp.
  const std::string& get(const char* fourcc) {
    const auto known = files_.find(fourcc);
    if (known != files_.end()) return known->second;
    if (dir_.empty()) {
      dir_ = fs::temp_directory_path() / ("softsight_seek_benchmark_" + std::to_string(::getpid()));
      fs::create_directories(dir_);
    }
    const std::string path = (dir_ / (std::string(fourcc) + ".avi")).string();
    cv::VideoWriter writer(path, cv::CAP_FFMPEG,
                           cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]),
                           30.0, cv::Size(640, 480));
    if (!writer.isOpened()) throw std::runtime_error("cannot write " + path);
    cv::Mat ramp(480, 640, CV_8UC3), image;
    for (int x = 0; x < 640; ++x) ramp.col(x).setTo(cv::Scalar::all(40 + x / 4));
    for (int i = 0; i < kFrames; ++i) {
      ramp.copyTo(image);
      cv::circle(image, {320 + (i % 200) - 100, 240}, 20, cv::Scalar(40, 200, 40), cv::FILLED);
      cv::putText(image, std::to_string(i), {20, 60}, cv::FONT_HERSHEY_SIMPLEX, 1.5,
                  cv::Scalar(255, 255, 255), 3);
      writer.write(image);
    }
    return files_[fourcc] = path;
  }

 private:
  fs::path dir_;
  std::map<std::string, std::string> files_;
};

LongVideos& Videos() {
  static LongVideos videos;
  return videos;
}

const char* Codec(int i) {
  static const char* const kCodecs[] = {"HFYU", "MJPG", "FFV1"};
  return kCodecs[i];
}

// A freshly opened file, then End: the last frame read, as the window shows it.
void BM_OpenAndSeekToEnd10MinVga(benchmark::State& state) {
  const char* codec = Codec(static_cast<int>(state.range(0)));
  state.SetLabel(codec);
  FrameSourceSpec spec;
  spec.input = Videos().get(codec);
  Frame frame;
  for (auto _ : state) {
    SeekableSource source(OpenFrameSource(spec), [spec] { return OpenFrameSource(spec); });
    if (!source.seek_last() || !source.read(frame) || frame.index != kFrames - 1) {
      state.SkipWithError("the last frame was not reached");
      break;
    }
  }
}
BENCHMARK(BM_OpenAndSeekToEnd10MinVga)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

// An open file, alternately at its start and its middle, with a ring of two frames so that
// every seek leaves it (with the window's 192 MB ring both would stay cached: copies).
void BM_SeekAcross10MinVga(benchmark::State& state) {
  const char* codec = Codec(static_cast<int>(state.range(0)));
  state.SetLabel(codec);
  FrameSourceSpec spec;
  spec.input = Videos().get(codec);
  SeekableSource source(OpenFrameSource(spec), [spec] { return OpenFrameSource(spec); },
                        2 * 640 * 480 * 3);
  Frame frame;
  int64_t target = 0;
  for (auto _ : state) {
    target = target == 0 ? kFrames / 2 : 0;  // Both even: the same slot of the two-frame ring.
    source.seek(target);
    if (!source.read(frame) || frame.index != target) {
      state.SkipWithError("the frame sought was not read");
      break;
    }
  }
  // A ring hit would time a copy, not a seek.
  if (source.direct_seeks() < static_cast<int64_t>(state.iterations())) {
    state.SkipWithError("a seek stayed in the ring");
  }
}
BENCHMARK(BM_SeekAcross10MinVga)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace softsight
