#include "softsight/sim/truth_score.h"

#include <algorithm>
#include <cmath>

namespace softsight {

TruthVerdict Judge(const MarkerTruth& truth, const Observation& observation) {
  if (truth.visible_fraction <= 0.0 || !truth.centroid_px) {
    return observation.found() ? TruthVerdict::kFalseReport : TruthVerdict::kHiddenLost;
  }
  if (truth.visible_fraction < kMustFindVisibleFraction) return TruthVerdict::kExempt;
  return observation.found() ? TruthVerdict::kHit : TruthVerdict::kMiss;
}

TruthScorer::TruthScorer(size_t marker_count) : offsets_(marker_count) {}

void TruthScorer::add(const SceneTruth& truth, const FrameResult& result) {
  CV_Assert(truth.markers.size() == offsets_.size() &&
            result.markers.size() == offsets_.size());
  ++counts_.frames;
  for (size_t i = 0; i < truth.markers.size(); ++i) {
    const MarkerTruth& marker = truth.markers[i];
    const Observation& observation = result.markers[i].observation;
    switch (Judge(marker, observation)) {
      case TruthVerdict::kFalseReport:
        ++counts_.false_reports;
        [[fallthrough]];
      case TruthVerdict::kHiddenLost:
        ++counts_.hidden;
        break;
      case TruthVerdict::kExempt:
        break;
      case TruthVerdict::kMiss:
        ++counts_.visible;
        ++counts_.misses;
        break;
      case TruthVerdict::kHit: {
        ++counts_.visible;
        ++counts_.found_visible;
        const cv::Point2d error = *observation.position_px - *marker.centroid_px;
        if (!offsets_[i]) offsets_[i] = error;
        const double absolute = std::hypot(error.x, error.y);
        const cv::Point2d residual = error - *offsets_[i];
        const double precise = std::hypot(residual.x, residual.y);
        squared_ += absolute * absolute;
        errors_.push_back(absolute);
        if (absolute > kWrongFindPx) ++counts_.wrong_finds;
        if (observation.sigma_px && *observation.sigma_px > 0) {
          // Along each axis, in units of the position's sigma: within 3 when both axes are.
          const double normalised =
              std::max(std::abs(error.x), std::abs(error.y)) / *observation.sigma_px;
          ++counts_.with_sigma;
          counts_.within_3_sigma += normalised <= 3.0;
          counts_.beyond_5_sigma += normalised > 5.0;
        }
        precise_squared_ += precise * precise;
        max_ = std::max(max_, absolute);
        precise_max_ = std::max(precise_max_, precise);
        break;
      }
    }
  }
  const std::optional<double>& angle = result.measurement.angle_deg;
  const std::optional<double>& true_angle = truth.measurement.angle_deg;
  if (angle && true_angle) {
    const double error = std::abs(*angle - *true_angle);
    angle_squared_ += error * error;
    angle_max_ = std::max(angle_max_, error);
    ++counts_.angle_frames;
  }
}

TruthScore TruthScorer::score() const {
  TruthScore score = counts_;
  if (score.found_visible > 0) {
    const double n = static_cast<double>(score.found_visible);
    score.centroid_rms_px = std::sqrt(squared_ / n);
    score.centroid_max_px = max_;
    std::vector<double> sorted = errors_;
    const size_t rank = static_cast<size_t>(std::ceil(0.95 * static_cast<double>(sorted.size())));
    std::nth_element(sorted.begin(), sorted.begin() + (rank - 1), sorted.end());
    score.centroid_p95_px = sorted[rank - 1];
    score.precision_rms_px = std::sqrt(precise_squared_ / n);
    score.precision_max_px = precise_max_;
  }
  if (score.angle_frames > 0) {
    score.angle_rms_deg = std::sqrt(angle_squared_ / static_cast<double>(score.angle_frames));
    score.angle_max_deg = angle_max_;
  }
  return score;
}

}  // namespace softsight
