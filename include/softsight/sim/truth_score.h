// Tracking results against the renderer's exact truth: the one scorer behind `evaluate`, `demo`
// and the tests, with one rule for what must be found.
//
// A marker at least kMustFindVisibleFraction visible must be found (else it is a miss) and its
// error is measured; a fully hidden marker must not be found (else a false report: "found"
// means verified). In between, finding or losing a mostly covered marker are both acceptable:
// such marker-frames count neither way.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"
#include "softsight/sim/scene.h"

namespace softsight {

inline constexpr double kMustFindVisibleFraction = 0.5;
// A hit farther than this from the truth is a wrong find: the marker was reported found, but not
// where it is (the worst defect a tracker can have).
inline constexpr double kWrongFindPx = 3.0;

enum class TruthVerdict {
  kHit,          // Visible enough and found (its error counts).
  kMiss,         // Visible enough and not found.
  kFalseReport,  // Fully hidden and found.
  kHiddenLost,   // Fully hidden and not found: right.
  kExempt,       // Partly covered: either answer is accepted.
};

TruthVerdict Judge(const MarkerTruth& truth, const Observation& observation);

struct TruthScore {
  int64_t frames = 0;
  int64_t visible = 0;        // Marker-frames at least kMustFindVisibleFraction visible.
  int64_t found_visible = 0;  // ... of which found (hits).
  int64_t misses = 0;         // Visible but not found.
  int64_t hidden = 0;         // Marker-frames fully hidden.
  int64_t false_reports = 0;  // Found while fully hidden.
  // |tracked - true centroid| over the hits; absent without hits.
  std::optional<double> centroid_rms_px{};
  std::optional<double> centroid_max_px{};
  std::optional<double> centroid_p95_px{};  // 95th percentile (nearest rank) of the same errors.
  int64_t wrong_finds = 0;                  // Hits farther than kWrongFindPx from the truth.
  // The hits' reported uncertainty (Observation::sigma_px) against their errors: hits with a
  // sigma, those whose error along both axes is within 3 sigma, and those beyond 5 sigma on
  // either axis. A calibrated sigma keeps at least 99 % within 3 and none beyond 5.
  int64_t with_sigma = 0;
  int64_t within_3_sigma = 0;
  int64_t beyond_5_sigma = 0;
  // The same after subtracting, per marker, the constant offset (tracked - true) of its first
  // hit: what remains once the half-pixel placement of a dragged template is taken out.
  std::optional<double> precision_rms_px{};
  std::optional<double> precision_max_px{};
  // Angle (eq. 7) against the truth's over frames where both exist; absent when none did.
  std::optional<double> angle_rms_deg{};
  std::optional<double> angle_max_deg{};
  int64_t angle_frames = 0;
};

class TruthScorer {
 public:
  // Markers in the truth's order, which must be the results' order (a scene's config lists its
  // markers as the scene does).
  explicit TruthScorer(size_t marker_count);

  void add(const SceneTruth& truth, const FrameResult& result);
  TruthScore score() const;

 private:
  TruthScore counts_;
  std::vector<std::optional<cv::Point2d>> offsets_;  // Per marker: tracked - true, first hit.
  std::vector<double> errors_;                       // |tracked - true| of every hit, for p95.
  double squared_ = 0, precise_squared_ = 0, max_ = 0, precise_max_ = 0;
  double angle_squared_ = 0, angle_max_ = 0;
};

}  // namespace softsight
