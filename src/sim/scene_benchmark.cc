// Rendering speed of the synthetic scenes (the tests render hundreds of frames, so it matters).
#include <benchmark/benchmark.h>

#include "softsight/sim/plate_scene.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

// Args: width, height, supersample, noise sigma (0 = clean), kind.
void BM_RenderFrame(benchmark::State& state) {
  SceneOptions scene;
  scene.size = cv::Size(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  scene.kind = static_cast<SceneKind>(state.range(4));
  scene.frame_count = 300;
  const double scale = scene.size.height / 480.0;
  scene.length_px *= scale;
  scene.width_px *= scale;
  scene.marker_radius_px *= scale;
  NoiseOptions noise;
  noise.sigma = static_cast<double>(state.range(3));
  RenderOptions render;
  render.supersample = static_cast<int>(state.range(2));
  SyntheticScene synthetic(scene, noise, render);
  cv::Mat image;
  int index = 0;
  for (auto _ : state) {
    SceneTruth truth = synthetic.render(index, image);
    benchmark::DoNotOptimize(truth);
    index = (index + 7) % scene.frame_count;  // Visits the whole bend range.
  }
}
BENCHMARK(BM_RenderFrame)
    ->ArgNames({"w", "h", "ss", "noise", "kind"})
    ->Args({640, 480, 4, 0, 0})
    ->Args({640, 480, 4, 5, 0})
    ->Args({640, 480, 4, 0, 2})
    ->Args({640, 480, 8, 0, 0})
    ->Args({1280, 720, 4, 0, 0})
    ->Unit(benchmark::kMillisecond);

// Building a scene renders and caches the supersampled backdrop.
void BM_ConstructScene(benchmark::State& state) {
  for (auto _ : state) {
    SyntheticScene scene{SceneOptions{}};
    benchmark::DoNotOptimize(scene);
  }
}
BENCHMARK(BM_ConstructScene)->Unit(benchmark::kMillisecond);

// The textured bench with its distractors: the backdrop is built once, frames cost as usual.
void BM_ConstructBenchScene(benchmark::State& state) {
  SceneOptions options;
  options.background = BackgroundKind::kBench;
  for (auto _ : state) {
    options.distractors = MakeMarkerDistractors(options, 1);
    SyntheticScene scene{options};
    benchmark::DoNotOptimize(scene);
  }
}
BENCHMARK(BM_ConstructBenchScene)->Unit(benchmark::kMillisecond);

// The plate scene at VGA and 720p (the plate's region is drawn supersampled every frame).
void BM_RenderPlateFrame(benchmark::State& state) {
  PlateSceneOptions options;
  options.size = cv::Size(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  options.dot_radius_px *= options.size.height / 480.0;
  PlateScene scene(options);
  cv::Mat image;
  int index = 0;
  for (auto _ : state) {
    SceneTruth truth = scene.render(index, image);
    benchmark::DoNotOptimize(truth);
    index = (index + 7) % options.frame_count;
  }
}
BENCHMARK(BM_RenderPlateFrame)
    ->ArgNames({"w", "h"})
    ->Args({640, 480})
    ->Args({1280, 720})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace softsight
