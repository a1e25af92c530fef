// What a per-frame hook costs the loop (docs/measurements.md, "Per-frame hook"): HookSink::consume
// on a VGA frame and a three-marker result, with no hook (the baseline: nothing), a trivial C++
// hook in the run, the same on its own thread (the camera's way: the frame copied into the
// hook's slot, a hand-over and a wait), and an empty Python hook file (`--hook`), and one that
// reads the markers and returns a value, both in the run.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <memory>

#include "app/python_hook.h"
#include "softsight/pipeline/hook.h"

namespace softsight {
namespace {

class Trivial : public FrameHook {
 public:
  std::vector<std::string> columns() const override { return {"x"}; }
  void on_frame(const Frame&, const FrameResult& result, HookValues& out) override {
    out.set(size_t{0}, static_cast<double>(result.frame_index));
  }
};

Frame VgaFrame() {
  Frame frame;
  frame.image = cv::Mat(480, 640, CV_8UC3, cv::Scalar(40, 90, 160));
  return frame;
}

FrameResult ThreeMarkers() {
  FrameResult result;
  for (const char* name : {"red", "blue", "green"}) {
    MarkerObservation marker;
    marker.name = name;
    marker.observation.position_px = cv::Point2d(100, 200);
    result.markers.push_back(marker);
  }
  result.measurement.angle_deg = 150.0;
  return result;
}

void Run(benchmark::State& state, FrameHook& hook, HookOptions options) {
  HookSink sink(hook, options);
  sink.begin(RunInfo{});
  Frame frame = VgaFrame();
  FrameResult result = ThreeMarkers();
  for (auto _ : state) {
    sink.consume(frame, result);
    ++frame.index;
    ++result.frame_index;
  }
  sink.end(RunSummary{});
  if (sink.ran() != sink.frames()) state.SkipWithError("the hook missed frames");
}

void BM_CppHookInTheRun(benchmark::State& state) {
  Trivial hook;
  Run(state, hook, {});
}
BENCHMARK(BM_CppHookInTheRun);

void BM_CppHookOnItsThread(benchmark::State& state) {
  Trivial hook;
  HookOptions options;
  options.wait_ms = 1000.0;  // Never late: the cost of the hand-over itself.
  Run(state, hook, options);
}
BENCHMARK(BM_CppHookOnItsThread)->UseRealTime();

std::unique_ptr<FrameHook> PythonHookFile(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return LoadPythonHook(path);
}

void BM_PythonEmptyHook(benchmark::State& state) {
  const std::unique_ptr<FrameHook> hook = PythonHookFile(
      "softsight_bench_empty_hook.py", "columns = ['x']\ndef on_frame(frame, result):\n    pass\n");
  Run(state, *hook, {});
}
BENCHMARK(BM_PythonEmptyHook);

void BM_PythonMarkerHook(benchmark::State& state) {
  const std::unique_ptr<FrameHook> hook = PythonHookFile(
      "softsight_bench_marker_hook.py",
      "columns = ['x_sum']\ndef on_frame(frame, result):\n"
      "    return {'x_sum': sum(m.x for m in result.markers if m.found)}\n");
  Run(state, *hook, {});
}
BENCHMARK(BM_PythonMarkerHook);

}  // namespace
}  // namespace softsight
