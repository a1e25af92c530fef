// softsight_vpdot2_compare CONFIG INPUT [ROUNDS]: softsight's TrackingSession beside ViSP's vpDot2
// (issue 45: "the real-sequence case <= 3x vpDot2 per frame with the same dots found"), on the same
// frames, preloaded, in one process, on one thread (OpenCV single-threaded; vpDot2 is).
//   - The frames are read once as `track` reads them (OpenFrameSource: BGR); vpDot2 gets their
//     gray copy (for a gray recording, exactly its pixels), as ViSP's trackDot2 example reads them
//     (vpdot2_runner.cc: ViSP 3.5's headers compile as C++17 only).
//   - vpDot2 is set up as the mire-2 reference was made (/work/shared/real-dev/mire2/dot2ref.cpp:
//     moments on, gray-level precision 0.9), each dot started on the first frame at the centre of
//     the config's box for its marker (a colour marker's roi, a template's rect), in config order;
//     a dot whose track() throws is lost for good, as there.
//   - Each round runs the whole sequence through a fresh TrackingSession, then through fresh
//     vpDot2 trackers, each frame timed on its own (steady clock), alternating so load changes hit
//     both; ROUNDS (default 5) rounds, figures are the medians over the rounds of each round's
//     mean, wall time, and of each round's thread CPU time per frame (the work done, which a busy
//     machine does not inflate).
//   - Dots found: per frame and marker, softsight's report against vpDot2's, counted as the same
//     dot within 1.5 px (the real set's tolerance).
// Prints one Markdown table row (scripts/bench.sh). A benchmark, not a test: it asserts nothing.
// Needs ViSP (Debian: libvisp-dev); the product does not: this program is built only when CMake
// finds ViSP (SOFTSIGHT_BUILD_BENCHMARKS and find_package(VISP)).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <time.h>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "softsight/config/config.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"
#include "vpdot2_runner.h"

namespace softsight {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kSameDotPx = 1.5;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// This thread's CPU time so far, ms: on a shared machine the work done, where wall time also
// counts the time other processes had the core.
double ThreadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// The centre of the box the config draws around a marker (where a person would click for vpDot2).
cv::Point2d BoxCentre(const MarkerSpec& spec) {
  std::optional<cv::Rect> box;
  if (const auto* c = spec.params.get_if<ColourParams>()) box = c->roi;
  if (const auto* t = spec.params.get_if<TemplateParams>()) box = t->rect;
  if (!box) {
    throw std::runtime_error("marker '" + spec.name +
                             "' has no roi or template rect to start vpDot2 at");
  }
  return {box->x + (box->width - 1) / 2.0, box->y + (box->height - 1) / 2.0};
}

using Positions = std::vector<std::vector<std::optional<cv::Point2d>>>;  // [frame][marker]

struct Pass {
  std::vector<double> ms;  // Per frame, wall time.
  double cpu_ms = 0.0;     // The whole pass, thread CPU time.
  Positions found;
};

Pass RunSession(const TrackingConfig& config, const std::vector<Frame>& frames) {
  Pass pass;
  TrackingSession session(config);
  const double cpu_start = ThreadCpuMs();
  for (const Frame& frame : frames) {
    const Clock::time_point start = Clock::now();
    const FrameResult& result = session.process(frame);
    pass.ms.push_back(MsSince(start));
    std::vector<std::optional<cv::Point2d>> row;
    for (const MarkerObservation& m : result.markers) row.push_back(m.observation.position_px);
    pass.found.push_back(std::move(row));
  }
  pass.cpu_ms = ThreadCpuMs() - cpu_start;
  return pass;
}

double Mean(const std::vector<double>& v, const std::vector<bool>* only = nullptr) {
  double sum = 0.0;
  int n = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    if (only && !(*only)[i]) continue;
    sum += v[i];
    ++n;
  }
  return n ? sum / n : 0.0;
}

int Main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: softsight_vpdot2_compare CONFIG INPUT [ROUNDS]\n";
    return 2;
  }
  cv::setNumThreads(1);
  const std::string config_file = argv[1], input = argv[2];
  const int rounds = argc > 3 ? std::max(1, std::atoi(argv[3])) : 5;
  const TrackingConfig config = LoadTrackingConfig(config_file);
  std::vector<cv::Point2d> starts;
  for (const MarkerSpec& spec : config.markers) starts.push_back(BoxCentre(spec));

  std::vector<Frame> frames;
  std::vector<cv::Mat> gray;
  {
    std::unique_ptr<FrameSource> source = OpenFrameSource({input, {}, 30.0});
    Frame frame;
    cv::Mat g;
    while (source->read(frame)) {
      Frame copy = frame;
      copy.image = frame.image.clone();
      frames.push_back(copy);
      cv::cvtColor(frame.image, g, cv::COLOR_BGR2GRAY);
      gray.push_back(g.clone());
    }
  }
  if (frames.empty()) {
    std::cerr << input << ": no frames\n";
    return 2;
  }

  const Dot2Sequence dot2_frames(gray);
  std::vector<Pass> sessions, dot2s;
  for (int r = 0; r < rounds; ++r) {
    sessions.push_back(RunSession(config, frames));
    dot2s.emplace_back();
    const double cpu_start = ThreadCpuMs();
    dot2_frames.run(starts, dot2s.back().ms, dot2s.back().found);
    dot2s.back().cpu_ms = ThreadCpuMs() - cpu_start;
  }
  const Pass& session = sessions.back();
  const Pass& dot2 = dot2s.back();
  // Found-counts from the last round (every round finds the same: both are deterministic).
  const size_t n = frames.size(), m = starts.size();
  int dot2_found = 0, session_found = 0, same = 0, session_not_dot2 = 0, far = 0;
  std::vector<bool> both_all(n, true);
  for (size_t f = 0; f < n; ++f) {
    for (size_t k = 0; k < m; ++k) {
      const auto& a = session.found[f][k];
      const auto& b = dot2.found[f][k];
      dot2_found += b.has_value();
      session_found += a.has_value();
      if (a && b && cv::norm(*a - *b) <= kSameDotPx) ++same;
      if (a && b && cv::norm(*a - *b) > kSameDotPx) ++far;
      if (a && !b) ++session_not_dot2;
      if (!a || !b) both_all[f] = false;
    }
  }
  // Each round's mean over all frames, and over the frames where both found every dot.
  std::vector<double> session_mean, dot2_mean, session_all, dot2_all, session_cpu, dot2_cpu;
  for (int r = 0; r < rounds; ++r) {
    session_cpu.push_back(sessions[r].cpu_ms / static_cast<double>(frames.size()));
    dot2_cpu.push_back(dot2s[r].cpu_ms / static_cast<double>(frames.size()));
    session_mean.push_back(Mean(sessions[r].ms));
    dot2_mean.push_back(Mean(dot2s[r].ms));
    session_all.push_back(Mean(sessions[r].ms, &both_all));
    dot2_all.push_back(Mean(dot2s[r].ms, &both_all));
  }
  const int both_frames = static_cast<int>(std::count(both_all.begin(), both_all.end(), true));
  const double s = Median(session_mean), d = Median(dot2_mean);
  const double sa = Median(session_all), da = Median(dot2_all);
  const double sc = Median(session_cpu), dc = Median(dot2_cpu);
  std::printf("| real sequence `%s` (%zu frames %dx%d, %zu dots), `%s`: `TrackingSession::process` "
              "per frame, thread CPU (wall) | %.3f ms (%.1fx vpDot2), wall %.3f ms (%.1fx); where "
              "both find every dot (%d frames) wall %.3f ms (%.1fx) | vpDot2 %.3f ms, wall %.3f ms "
              "(%.3f where both find every dot); dots found: vpDot2 %d of %zu, softsight %d, %d of "
              "them within %.1f px of vpDot2's, %d farther, %d where vpDot2 has none; medians of %d "
              "rounds |\n",
              input.c_str(), n, frames[0].image.cols, frames[0].image.rows, m, config_file.c_str(),
              sc, sc / dc, s, s / d, both_frames, sa, sa / da, dc, d, da, dot2_found, n * m,
              session_found, same, kSameDotPx, far, session_not_dot2, rounds);
  return 0;
}

}  // namespace
}  // namespace softsight

int main(int argc, char** argv) {
  try {
    return softsight::Main(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "softsight_vpdot2_compare: " << e.what() << "\n";
    return 1;
  }
}
