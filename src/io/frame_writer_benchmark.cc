// Lossless recording speed at VGA on the rendered scene (clean and with sensor noise): encoding
// through FrameWriter and decoding through cv::VideoCapture, for the lossless codecs FrameWriter
// offers (ffv1, hfyu), beside one BGR->gray pass over the same frame as the machine's reference.
// FFmpeg decodes on helper threads, so times are the process's CPU time (every thread) on one core.
// Compare codecs by their ratio within one run (the machine may be shared); one core:
//   taskset -c 0 build/src/io/softsight_frame_writer_benchmark
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "softsight/io/frame_writer.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

constexpr int kFrames = 30;
const char* const kCodecs[] = {"ffv1", "hfyu"};

// kFrames rendered VGA frames, noise sigma 0 (clean) or 4 (a camera's sensor noise).
const std::vector<cv::Mat>& Frames(int noise_sigma) {
  static std::vector<cv::Mat> cache[2];
  std::vector<cv::Mat>& frames = cache[noise_sigma > 0 ? 1 : 0];
  if (frames.empty()) {
    SceneOptions scene;
    scene.size = cv::Size(640, 480);
    scene.frame_count = kFrames;
    NoiseOptions noise;
    noise.sigma = noise_sigma;
    SyntheticScene synthetic(scene, noise);
    for (int i = 0; i < kFrames; ++i) {
      cv::Mat image;
      synthetic.render(i, image);
      frames.push_back(image);
    }
  }
  return frames;
}

// The encoded videos, each rewritten by every timed iteration, are the run's scratch: removed
// after each benchmark, so a run leaves nothing in the temporary folder.
std::string PathFor(const char* codec, int noise_sigma) {
  return (std::filesystem::temp_directory_path() /
          ("softsight_bench_" + std::string(codec) + std::to_string(noise_sigma) + ".avi"))
      .string();
}

void RemoveVideo(const char* codec, int noise_sigma) {
  std::error_code ignored;
  std::filesystem::remove(PathFor(codec, noise_sigma), ignored);
}

void Write(const char* codec, int noise_sigma) {
  FrameWriter writer({PathFor(codec, noise_sigma), codec, 30.0});
  const std::vector<cv::Mat>& frames = Frames(noise_sigma);
  for (int i = 0; i < kFrames; ++i) writer.write(frames[i], i);
}

// Args: codec index, noise sigma.
void BM_Encode(benchmark::State& state) {
  const char* codec = kCodecs[state.range(0)];
  const int noise = static_cast<int>(state.range(1));
  Frames(noise);
  for (auto _ : state) Write(codec, noise);
  RemoveVideo(codec, noise);
  state.SetItemsProcessed(state.iterations() * kFrames);  // items/s = frames per second.
  state.SetLabel(codec);
}

void BM_Decode(benchmark::State& state) {
  const char* codec = kCodecs[state.range(0)];
  const int noise = static_cast<int>(state.range(1));
  Write(codec, noise);
  state.counters["kB_per_frame"] =
      std::filesystem::file_size(PathFor(codec, noise)) / 1024.0 / kFrames;
  cv::Mat frame;
  int64_t frames = 0;
  for (auto _ : state) {
    cv::VideoCapture video(PathFor(codec, noise), cv::CAP_FFMPEG);
    while (video.read(frame)) ++frames;
  }
  RemoveVideo(codec, noise);
  state.SetItemsProcessed(frames);
  state.SetLabel(codec);
}

void BM_GrayReference(benchmark::State& state) {
  const cv::Mat& frame = Frames(0)[0];
  cv::Mat gray;
  for (auto _ : state) {
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
    benchmark::DoNotOptimize(gray.data);
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_GrayReference)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Encode)
    ->ArgNames({"codec", "noise"})
    ->ArgsProduct({{0, 1}, {0, 4}})
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Decode)
    ->ArgNames({"codec", "noise"})
    ->ArgsProduct({{0, 1}, {0, 4}})
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace softsight
