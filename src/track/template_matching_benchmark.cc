// Template matching speed: the kernels against plain scalar loops and cv::matchTemplate, and the
// tracker (3 markers, 32x32 templates, 640x480) windowed, acquiring on the whole frame, and
// against the baseline a user would write (cv::matchTemplate on the whole frame per marker and
// frame). Inputs are prepared outside the timed loops. BM_GrayConversion (one BGR->gray pass over
// the frame) is the yardstick that keeps ratios meaningful on a noisy machine.
//
//   softsight_template_matching_benchmark --benchmark_min_time=0.5
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "softsight/sim/scene.h"
#include "softsight/track/template_tracker.h"
#include "softsight/track/tracker.h"
#include "track/match_kernels.h"

namespace softsight {
namespace {

constexpr int kTemplatePx = 32;

cv::Mat RandomGray(cv::Size size, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image(size, CV_8UC1);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

// The loop a person writes first. PlainScalarSad is kept from auto-vectorisation so that it stays
// the scalar baseline; AutoVectorisedSad is the same loop as the compiler builds it at -O3 (what
// a user gets for free), for an honest second figure.
template <typename = void>
inline void SadLoop(const cv::Mat& image, const cv::Mat& templ, cv::Mat& result) {
  result.create(image.rows - templ.rows + 1, image.cols - templ.cols + 1, CV_32S);
  for (int y = 0; y < result.rows; ++y) {
    for (int x = 0; x < result.cols; ++x) {
      int total = 0;
      for (int r = 0; r < templ.rows; ++r) {
        const uint8_t* a = image.ptr<uint8_t>(y + r) + x;
        const uint8_t* b = templ.ptr<uint8_t>(r);
        for (int c = 0; c < templ.cols; ++c) total += std::abs(int{a[c]} - int{b[c]});
      }
      result.at<int>(y, x) = total;
    }
  }
}

__attribute__((optimize("no-tree-vectorize"), noinline)) void PlainScalarSad(
    const cv::Mat& image, const cv::Mat& templ, cv::Mat& result) {
  SadLoop(image, templ, result);
}

__attribute__((noinline)) void AutoVectorisedSad(const cv::Mat& image, const cv::Mat& templ,
                                                 cv::Mat& result) {
  SadLoop(image, templ, result);
}

// ---- Kernels: a tracking window (template + 16 px margin) and the whole VGA frame --------------

struct KernelInput {
  cv::Mat image, templ;
  PreparedTemplate prepared;
  KernelInput(cv::Size size) : image(RandomGray(size, 1)), templ(RandomGray({32, 32}, 2)) {
    prepared.Prepare(templ);
  }
};

// Arg 0: the tracker's window (template + its default 8 px margin on each side);
// 1: a larger window (16 px margin); 2: the whole VGA frame.
cv::Size SizeOf(const benchmark::State& state) {
  switch (state.range(0)) {
    case 0: return {kTemplatePx + 16, kTemplatePx + 16};
    case 1: return {kTemplatePx + 32, kTemplatePx + 32};
    default: return {640, 480};
  }
}

void BM_SadVector(benchmark::State& state) {
  KernelInput in(SizeOf(state));
  cv::Mat result;
  for (auto _ : state) {
    MatchSad(in.image, in.prepared, result);
    benchmark::DoNotOptimize(result.data);
  }
}
BENCHMARK(BM_SadVector)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_SadReferenceAsCompiled(benchmark::State& state) {
  KernelInput in(SizeOf(state));
  cv::Mat result;
  for (auto _ : state) {
    MatchSadReference(in.image, in.templ, result);
    benchmark::DoNotOptimize(result.data);
  }
}
BENCHMARK(BM_SadReferenceAsCompiled)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_SadPlainScalar(benchmark::State& state) {
  KernelInput in(SizeOf(state));
  cv::Mat result;
  for (auto _ : state) {
    PlainScalarSad(in.image, in.templ, result);
    benchmark::DoNotOptimize(result.data);
  }
}
void BM_SadAutoVectorisedLoop(benchmark::State& state) {
  KernelInput in(SizeOf(state));
  cv::Mat result;
  for (auto _ : state) {
    AutoVectorisedSad(in.image, in.templ, result);
    benchmark::DoNotOptimize(result.data);
  }
}
BENCHMARK(BM_SadAutoVectorisedLoop)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

BENCHMARK(BM_SadPlainScalar)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_SsdVector(benchmark::State& state) {
  KernelInput in(SizeOf(state));
  cv::Mat result;
  ZnccScratch scratch;
  for (auto _ : state) {
    MatchSsd(in.image, in.prepared, result, scratch);
    benchmark::DoNotOptimize(result.data);
  }
}
BENCHMARK(BM_SsdVector)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_SsdOpenCv(benchmark::State& state) {
  KernelInput in(SizeOf(state));
  cv::Mat result;
  for (auto _ : state) {
    cv::matchTemplate(in.image, in.templ, result, cv::TM_SQDIFF);
    benchmark::DoNotOptimize(result.data);
  }
}
BENCHMARK(BM_SsdOpenCv)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_ZnccVector(benchmark::State& state) {
  KernelInput in(SizeOf(state));
  cv::Mat result;
  ZnccScratch scratch;
  for (auto _ : state) {
    MatchZncc(in.image, in.prepared, result, scratch);
    benchmark::DoNotOptimize(result.data);
  }
}
BENCHMARK(BM_ZnccVector)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_ZnccVectorRoundMask(benchmark::State& state) {
  KernelInput in(SizeOf(state));
  cv::Mat mask(in.templ.size(), CV_8UC1, cv::Scalar(0));
  cv::circle(mask, {16, 16}, 16, cv::Scalar(255), cv::FILLED);
  in.prepared.Prepare(in.templ, mask);
  cv::Mat result;
  ZnccScratch scratch;
  for (auto _ : state) {
    MatchZncc(in.image, in.prepared, result, scratch);
    benchmark::DoNotOptimize(result.data);
  }
}
BENCHMARK(BM_ZnccVectorRoundMask)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_ZnccOpenCv(benchmark::State& state) {
  KernelInput in(SizeOf(state));
  cv::Mat result;
  for (auto _ : state) {
    cv::matchTemplate(in.image, in.templ, result, cv::TM_CCOEFF_NORMED);
    benchmark::DoNotOptimize(result.data);
  }
}
BENCHMARK(BM_ZnccOpenCv)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

// ---- The tracker on a rendered scene ----------------------------------------------------------

// 60 frames of slow bending, played forwards and backwards so that the motion never jumps.
struct Scene {
  std::vector<cv::Mat> frames;
  std::vector<cv::Rect> rects;  // 32x32 templates around the markers on frame 0.
  Scene() {
    SceneOptions options;
    options.frame_count = 300;
    SyntheticScene scene(options);
    for (int i = 0; i < 60; ++i) {
      cv::Mat frame;
      const SceneTruth truth = scene.render(i, frame);
      frames.push_back(frame);
      if (i == 0) {
        for (const MarkerTruth& m : truth.markers) {
          rects.emplace_back(cvRound(m.centroid_px->x) - kTemplatePx / 2,
                             cvRound(m.centroid_px->y) - kTemplatePx / 2, kTemplatePx, kTemplatePx);
        }
      }
    }
  }
  const cv::Mat& frame(int64_t k) const {
    const int n = static_cast<int>(frames.size());
    const int i = static_cast<int>(k % (2 * n - 2));
    return frames[i < n ? i : 2 * n - 2 - i];
  }
};

const Scene& TheScene() {
  static const Scene scene;
  return scene;
}

// The template methods of the registry, in its order (sad, ssd, zncc: the benchmarks' argument).
const std::vector<std::string>& TemplateMethods() {
  static const std::vector<std::string> methods = [] {
    std::vector<std::string> names;
    for (const std::string& name : TrackerMethods()) {
      if (IsTemplateMethod(name)) names.push_back(name);
    }
    return names;
  }();
  return methods;
}

std::vector<std::unique_ptr<Tracker>> MakeTrackers(const std::string& method, bool colour) {
  const Scene& scene = TheScene();
  std::vector<std::unique_ptr<Tracker>> trackers;
  for (const cv::Rect& rect : scene.rects) {
    MarkerSpec spec;
    spec.name = std::string("marker");
    spec.params = ParamsForMethod(method, {});
    spec.params.get<TemplateParams>().colour = colour;
    trackers.push_back(CreateTracker(spec));
    trackers.back()->init(scene.frames[0], rect);
  }
  return trackers;
}

// Per frame: all three markers tracked in their windows (the steady state).
void BM_TrackWindowed(benchmark::State& state) {
  const Scene& scene = TheScene();
  const std::string& method = TemplateMethods()[static_cast<size_t>(state.range(0))];
  const bool colour = state.range(1) != 0;
  std::string label = method;
  label += colour ? " colour" : " gray";
  state.SetLabel(label);
  auto trackers = MakeTrackers(method, colour);
  for (auto& t : trackers) t->update(scene.frame(0));  // First acquisition, untimed.
  int64_t k = 1, missed = 0;
  for (auto _ : state) {
    const cv::Mat& frame = scene.frame(k++);
    for (auto& t : trackers) missed += t->update(frame).found() ? 0 : 1;
  }
  state.counters["missed"] = static_cast<double>(missed);
}
BENCHMARK(BM_TrackWindowed)->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMicrosecond);

// Per frame: every marker acquired on the whole frame (no known position), coarse to fine.
void BM_AcquireWholeFrame(benchmark::State& state) {
  const Scene& scene = TheScene();
  const std::string& method = TemplateMethods()[static_cast<size_t>(state.range(0))];
  const bool colour = state.range(1) != 0;
  std::string label = method;
  label += colour ? " colour, 3 markers" : " gray, 3 markers";
  state.SetLabel(label);
  auto trackers = MakeTrackers(method, colour);
  int64_t k = 0;
  for (auto _ : state) {
    const cv::Mat& frame = scene.frame(k++);
    for (auto& t : trackers) {
      t->reset();
      benchmark::DoNotOptimize(t->update(frame));
    }
  }
}
BENCHMARK(BM_AcquireWholeFrame)->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

// The baseline a user would write: gray frame, cv::matchTemplate over the whole frame for each
// marker, best location, every frame.
void BM_BaselineWholeFrameMatchTemplate(benchmark::State& state) {
  const Scene& scene = TheScene();
  const int mode = state.range(0) ? cv::TM_CCOEFF_NORMED : cv::TM_SQDIFF;
  state.SetLabel(state.range(0) ? "TM_CCOEFF_NORMED" : "TM_SQDIFF");
  std::vector<cv::Mat> templates;
  cv::Mat gray;
  cv::cvtColor(scene.frames[0], gray, cv::COLOR_BGR2GRAY);
  for (const cv::Rect& rect : scene.rects) templates.push_back(gray(rect).clone());
  cv::Mat result;
  int64_t k = 0;
  for (auto _ : state) {
    cv::cvtColor(scene.frame(k++), gray, cv::COLOR_BGR2GRAY);
    for (const cv::Mat& templ : templates) {
      cv::matchTemplate(gray, templ, result, mode);
      cv::Point best;
      if (mode == cv::TM_SQDIFF) {
        cv::minMaxLoc(result, nullptr, nullptr, &best, nullptr);
      } else {
        cv::minMaxLoc(result, nullptr, nullptr, nullptr, &best);
      }
      benchmark::DoNotOptimize(best);
    }
  }
}
BENCHMARK(BM_BaselineWholeFrameMatchTemplate)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_GrayConversion(benchmark::State& state) {
  const Scene& scene = TheScene();
  cv::Mat gray;
  for (auto _ : state) {
    cv::cvtColor(scene.frames[0], gray, cv::COLOR_BGR2GRAY);
    benchmark::DoNotOptimize(gray.data);
  }
}
BENCHMARK(BM_GrayConversion)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace softsight
