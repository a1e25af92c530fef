// Per-frame cost of undistorting whole frames (Undistorter::apply), against a one-pass
// reference (BGR -> gray of the same frame) so the ratio stays meaningful on a noisy machine.
#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

#include "softsight/calib/camera_calibration.h"

namespace softsight {
namespace {

CameraIntrinsics Webcam(cv::Size size) {
  CameraIntrinsics camera;
  camera.image_size = size;
  camera.camera_matrix =
      cv::Matx33d(size.width, 0, size.width / 2.0, 0, size.width, size.height / 2.0, 0, 0, 1);
  camera.distortion = {-0.25, 0.08, 0.001, -0.0005, 0.0};
  return camera;
}

cv::Mat RandomFrame(cv::Size size) {
  cv::Mat frame(size, CV_8UC3);
  cv::RNG(1).fill(frame, cv::RNG::UNIFORM, 0, 256);
  return frame;
}

void BM_Undistort(benchmark::State& state) {
  const cv::Size size(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const Undistorter undistorter(Webcam(size));
  const cv::Mat frame = RandomFrame(size);
  cv::Mat out;
  undistorter.apply(frame, out);
  for (auto _ : state) {
    undistorter.apply(frame, out);
    benchmark::DoNotOptimize(out.data);
  }
}
BENCHMARK(BM_Undistort)->Args({640, 480})->Args({1280, 720})->Unit(benchmark::kMillisecond);

void BM_ReferenceBgrToGray(benchmark::State& state) {
  const cv::Size size(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const cv::Mat frame = RandomFrame(size);
  cv::Mat gray;
  for (auto _ : state) {
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
    benchmark::DoNotOptimize(gray.data);
  }
}
BENCHMARK(BM_ReferenceBgrToGray)->Args({640, 480})->Args({1280, 720})->Unit(benchmark::kMillisecond);

void BM_UndistortPoint(benchmark::State& state) {
  const Undistorter undistorter(Webcam({640, 480}));
  cv::Point2d p(600.5, 20.25);
  for (auto _ : state) benchmark::DoNotOptimize(undistorter.undistort_point(p));
}
BENCHMARK(BM_UndistortPoint);

}  // namespace
}  // namespace softsight
