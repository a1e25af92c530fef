// What the live window adds per frame on top of tracking: drawing the overlay, drawing the strip
// chart, and the whole controller step (track + measure + draw + compose) at VGA and 720p.
#include <benchmark/benchmark.h>

#include "gui/live_controller.h"
#include "gui/overlay.h"
#include "gui/strip_chart.h"
#include "softsight/sim/scene.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {
namespace {

// A status with a frame rate and a latency, nothing else.
OverlayStatus Status(double fps, double latency_ms) {
  OverlayStatus status;
  status.fps = fps;
  status.latency_ms = latency_ms;
  return status;
}


SceneOptions Scene(int width, int height) {
  SceneOptions scene;
  scene.size = cv::Size(width, height);
  scene.frame_count = 120;
  scene.length_px = height * 0.6;
  scene.marker_radius_px = height / 48.0;
  return scene;
}

FrameResult TruthResult(const SceneTruth& truth) {
  FrameResult result;
  result.frame_index = truth.frame_index;
  result.time_s = truth.time_s;
  for (const MarkerTruth& m : truth.markers) result.markers.push_back({m.name, {m.centroid_px, 1.0}});
  result.measurement = truth.measurement;
  return result;
}

void BM_DrawOverlay(benchmark::State& state) {
  SyntheticScene scene(Scene(state.range(0), state.range(1)));
  cv::Mat frame, canvas;
  const FrameResult result = TruthResult(scene.render(60, frame));
  MeasureOptions measure;
  measure.base = "red";
  measure.middle = "blue";
  measure.tip = "green";
  const OverlayOptions options = OverlayOptionsFor(measure);
  for (auto _ : state) {
    frame.copyTo(canvas);
    DrawOverlay(canvas, result, options, Status(30.0, 20.0));
    benchmark::DoNotOptimize(canvas.data);
  }
}
BENCHMARK(BM_DrawOverlay)->Args({640, 480})->Args({1280, 720})->Unit(benchmark::kMicrosecond);

void BM_StripChartDraw(benchmark::State& state) {
  StripChart chart;
  for (int i = 0; i < 300; ++i) {  // 10 s at 30 fps.
    FrameResult r;
    r.time_s = i / 30.0;
    r.measurement.angle_deg = 180 - i * 0.3;
    r.measurement.tip_disp_px = i * 0.5;
    r.measurement.arc_length_px = 250 + (i % 7);
    chart.add(r);
  }
  cv::Mat area(180, state.range(0), CV_8UC3);
  for (auto _ : state) {
    chart.draw(area);
    benchmark::DoNotOptimize(area.data);
  }
}
BENCHMARK(BM_StripChartDraw)->Arg(640)->Arg(1280)->Unit(benchmark::kMicrosecond);

// One live frame end to end with colour tracking: what bounds the window's frame rate.
void BM_LiveControllerFrame(benchmark::State& state) {
  SyntheticScene scene(Scene(state.range(0), state.range(1)));
  TrackingConfig config;
  auto marker = [](const char* name, HsvRange h) {
    MarkerSpec spec;
    spec.name = name;
    ColourParams& colour = spec.params.emplace<ColourParams>();
    colour.h = h;
    colour.s = {80, 255};
    colour.v = {40, 255};
    return spec;
  };
  config.markers = {marker("red", {170, 10}), marker("blue", {95, 125}),
                    marker("green", {45, 75})};
  config.measure.base = "red";
  config.measure.middle = "blue";
  config.measure.tip = "green";
  LiveController live(config, LiveOptions{});
  std::vector<Frame> frames(30);
  for (int i = 0; i < 30; ++i) {
    scene.render(40 + i, frames[i].image);
    frames[i].index = i;
    frames[i].time_s = i / 30.0;
  }
  int i = 0;
  for (auto _ : state) {
    Frame& frame = frames[i % 30];
    frame.index = i;
    frame.time_s = i / 30.0;
    live.on_frame(frame, SteadyClock::now());
    benchmark::DoNotOptimize(live.canvas().data);
    ++i;
  }
}
BENCHMARK(BM_LiveControllerFrame)
    ->Args({640, 480})
    ->Args({1280, 720})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace softsight
