// What TrackingSession::process costs beyond its trackers (issue 26, item 7; issue 45: at most one
// gray pass at 640x480), per frame, on the rendered bending actuator with its three markers, at
// 640x480 and 1280x720:
//   GrayReference   one cv::cvtColor BGR->GRAY of the same frame: the one-pass yardstick;
//   Trackers3       the three colour trackers alone, as the session builds them (CreateTracker);
//   Session3        TrackingSession::process whole: trackers, frame-change detector, association,
//                   plausibility and the measurement;
//   Trackers3Zncc,  the same with three ZNCC templates (the registry's defaults: gray, round
//   Session3Zncc    mask) cut around the markers on the first frame;
//   FrameChange     FrameChangeDetector::observe alone (the session's summary of the whole frame).
// Every row reports ms_per_frame and the thread's CPU time per frame (cpu_ms_per_frame; OpenCV
// runs single-threaded here, so that is the work done) and both over the gray pass's (x_gray,
// cpu_x_gray), which stay meaningful on a noisy machine. Frames are rendered before timing and
// played forth and back with increasing frame indices, so the motion stays smooth.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <map>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/frame_change.h"
#include "softsight/config/config.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/sim/scene.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"
#include "softsight/track/tracker.h"

namespace softsight {
namespace {

constexpr int kFrames = 32;

const bool kSingleThreaded = [] {
  cv::setNumThreads(1);
  return true;
}();

double ThreadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// The first kFrames of a sweep over 10 x kFrames frames: the markers move up to ~10 px per frame
// (a fast actuator at 30 fps), which the session believes as motion (a sweep in kFrames would be
// a jump every frame, and the session would spend its time re-acquiring).
const std::vector<cv::Mat>& Frames(cv::Size size) {
  static std::map<int, std::vector<cv::Mat>> cache;
  std::vector<cv::Mat>& frames = cache[size.width];
  if (frames.empty()) {
    SceneOptions options;
    options.size = size;
    options.frame_count = 10 * kFrames;
    options.max_bend_deg = 120;
    NoiseOptions noise;
    noise.sigma = 2.0;
    SyntheticScene scene(options, noise);
    for (int i = 0; i < kFrames; ++i) {
      cv::Mat image;
      scene.render(i, image);
      frames.push_back(image);
    }
  }
  return frames;
}

// Forth and back through the frames (no jump back to frame 0).
const cv::Mat& FrameAt(const std::vector<cv::Mat>& frames, int64_t i) {
  const int64_t k = i % (2 * kFrames - 2);
  return frames[static_cast<size_t>(k < kFrames ? k : 2 * kFrames - 2 - k)];
}

// The config a person writes for the scene: red, blue and green, base to tip (the hues of the
// colour tracker's benchmark).
TrackingConfig ThreeMarkerConfig() {
  TrackingConfig config;
  const char* names[] = {"red", "blue", "green"};
  const HsvRange hues[] = {{170, 10}, {100, 130}, {45, 85}};
  for (int i = 0; i < 3; ++i) {
    MarkerSpec spec;
    spec.name = names[i];
    ColourParams& colour = spec.params.get<ColourParams>();
    colour.h = hues[i];
    colour.s = {80, 255};
    colour.v = {40, 255};
    config.markers.push_back(spec);
  }
  config.measure.base = "red";
  config.measure.middle = "blue";
  config.measure.tip = "green";
  return config;
}

// The same three markers as ZNCC templates, each a square of kTemplatePx cut around its marker
// on the first frame (template_frame 0: the session cuts it there, as `track` does).
constexpr int kTemplatePx = 32;
TrackingConfig ThreeTemplateConfig(cv::Size size) {
  TrackingConfig config = ThreeMarkerConfig();
  SceneOptions options;
  options.size = size;
  options.frame_count = 10 * kFrames;
  options.max_bend_deg = 120;
  cv::Mat first;
  const SceneTruth truth = SyntheticScene(options).render(0, first);
  for (size_t i = 0; i < config.markers.size(); ++i) {
    const cv::Point2d centre = *truth.markers[i].centroid_px;
    MarkerParams& params = config.markers[i].params;
    params = ParamsForMethod("zncc", {});
    params.get<TemplateParams>().rect = cv::Rect(cvRound(centre.x) - kTemplatePx / 2,
                                                 cvRound(centre.y) - kTemplatePx / 2,
                                                 kTemplatePx, kTemplatePx);
  }
  return config;
}

cv::Size SizeOf(const benchmark::State& state) {
  return {static_cast<int>(state.range(0)), static_cast<int>(state.range(1))};
}

// Median of one BGR->GRAY conversion over the frames, in ms of wall time and of thread CPU time.
struct GrayTimes {
  double wall_ms = 0.0, cpu_ms = 0.0;
};
GrayTimes GrayMs(cv::Size size) {
  static std::map<int, GrayTimes> cache;
  auto it = cache.find(size.width);
  if (it != cache.end()) return it->second;
  const std::vector<cv::Mat>& frames = Frames(size);
  cv::Mat gray;
  std::vector<double> wall, cpu;
  for (int rep = 0; rep < 400; ++rep) {
    const double cpu_start = ThreadCpuMs();
    const auto start = std::chrono::steady_clock::now();
    cv::cvtColor(frames[static_cast<size_t>(rep % kFrames)], gray, cv::COLOR_BGR2GRAY);
    wall.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                              start).count());
    cpu.push_back(ThreadCpuMs() - cpu_start);
  }
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  GrayTimes times;
  times.wall_ms = median(wall);
  times.cpu_ms = median(cpu);
  return cache[size.width] = times;
}

// One timed frame, a function of its own so that an instruction count can be limited to it:
// `valgrind --tool=callgrind --toggle-collect='*TimedFrame*'` counts the timed frames only (not
// the rendering, nor the warm-up), and callgrind reports how often it was called
// (scripts/session_instructions.sh divides the one by the other).
template <typename Step>
[[gnu::noinline]] void TimedFrame(Step& step, const cv::Mat& frame, int64_t index) {
  step(frame, index);
}

// Runs `step(frame, index)` once per iteration and reports the per-frame counters. The first
// kWarmUpFrames frames are not timed: a session's first frames acquire every marker on the whole
// frame, which a run of a few iterations (under callgrind) would otherwise count as steady work.
constexpr int kWarmUpFrames = 2 * kFrames;
template <typename Step>
void PerFrame(benchmark::State& state, Step step) {
  const cv::Size size = SizeOf(state);
  const std::vector<cv::Mat>& frames = Frames(size);
  const GrayTimes gray = GrayMs(size);
  int64_t i = 0;
  for (; i < kWarmUpFrames; ++i) step(FrameAt(frames, i), i);
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadCpuMs();
  for (auto _ : state) {
    TimedFrame(step, FrameAt(frames, i), i);
    ++i;
  }
  const double wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const double n = static_cast<double>(state.iterations());
  const double per_frame = wall_ms / n, cpu_per_frame = (ThreadCpuMs() - cpu_start) / n;
  state.counters["ms_per_frame"] = per_frame;
  state.counters["x_gray"] = per_frame / gray.wall_ms;
  state.counters["cpu_ms_per_frame"] = cpu_per_frame;
  state.counters["cpu_x_gray"] = cpu_per_frame / gray.cpu_ms;
}

void BM_GrayReference(benchmark::State& state) {
  cv::Mat gray;
  PerFrame(state, [&](const cv::Mat& frame, int64_t) {
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
    benchmark::DoNotOptimize(gray.data);
  });
}

// The trackers of `config` alone, each started on the first frame as the session starts it.
void TrackersAlone(benchmark::State& state, const TrackingConfig& config) {
  std::vector<std::unique_ptr<Tracker>> trackers;
  Frame first;
  first.image = Frames(SizeOf(state)).front();
  for (const MarkerSpec& spec : config.markers) {
    trackers.push_back(CreateTracker(spec));
    if (!trackers.back()->start(first)) state.SkipWithError("a tracker did not start");
  }
  int64_t found = 0, looked = 0;
  PerFrame(state, [&](const cv::Mat& frame, int64_t) {
    for (auto& t : trackers) {
      const Observation obs = t->update(frame);
      found += obs.found();
      ++looked;
      benchmark::DoNotOptimize(obs);
    }
  });
  state.counters["found_rate"] = static_cast<double>(found) / static_cast<double>(looked);
}

void BM_Trackers3(benchmark::State& state) { TrackersAlone(state, ThreeMarkerConfig()); }
void BM_Trackers3Zncc(benchmark::State& state) {
  TrackersAlone(state, ThreeTemplateConfig(SizeOf(state)));
}

void SessionWhole(benchmark::State& state, const TrackingConfig& config) {
  TrackingSession session(config);
  Frame frame;
  int64_t found = 0, looked = 0;
  PerFrame(state, [&](const cv::Mat& image, int64_t i) {
    frame.image = image;  // A header: the pixels stay where they were rendered.
    frame.index = i;
    frame.time_s = static_cast<double>(i) / 30.0;
    const FrameResult& result = session.process(frame);
    for (const MarkerObservation& m : result.markers) {
      found += m.observation.found();
      ++looked;
    }
    benchmark::DoNotOptimize(result.measurement);
  });
  // Every marker is found in every frame: the session measured believes, not re-acquisitions.
  state.counters["found_rate"] = static_cast<double>(found) / static_cast<double>(looked);
}

void BM_Session3(benchmark::State& state) { SessionWhole(state, ThreeMarkerConfig()); }
void BM_Session3Zncc(benchmark::State& state) {
  SessionWhole(state, ThreeTemplateConfig(SizeOf(state)));
}

void BM_FrameChange(benchmark::State& state) {
  FrameChangeDetector detector;
  int64_t changed = 0;
  PerFrame(state, [&](const cv::Mat& frame, int64_t) {
    detector.observe(frame);
    changed += detector.whole_frame_changed();
  });
  state.counters["changed_frames"] = static_cast<double>(changed);
}

#define SOFTSIGHT_SIZES Args({640, 480})->Args({1280, 720})->Unit(benchmark::kMillisecond)
BENCHMARK(BM_GrayReference)->SOFTSIGHT_SIZES;
BENCHMARK(BM_Trackers3)->SOFTSIGHT_SIZES;
BENCHMARK(BM_Session3)->SOFTSIGHT_SIZES;
BENCHMARK(BM_Trackers3Zncc)->SOFTSIGHT_SIZES;
BENCHMARK(BM_Session3Zncc)->SOFTSIGHT_SIZES;
BENCHMARK(BM_FrameChange)->SOFTSIGHT_SIZES;

}  // namespace
}  // namespace softsight
