#include "gui/scale_clicks.h"

#include <cstdio>

#include "softsight/calib/camera_calibration.h"
#include "softsight/core/error.h"

namespace softsight {

std::string DistanceText(double mm) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", mm);
  return text;
}

std::string ScaleClicks::start() {
  if (!distance_mm_) {
    return "scale: start live with --scale-distance-mm D, the true distance of the points to click";
  }
  active_ = true;
  points_.clear();
  return hint();
}

std::string ScaleClicks::hint() const {
  const std::string d = DistanceText(distance_mm_.value_or(0.0));
  return points_.empty() ? "scale: click point 1 of 2, " + d + " mm apart; Esc cancels"
                         : "scale: click point 2, " + d + " mm from point 1; Esc cancels";
}

std::optional<MetricModel> ScaleClicks::add(const cv::Point2d& image_px,
                                            const cv::Point2d& measurement_px,
                                            std::string* message) {
  points_.push_back(image_px);
  measurement_points_.resize(points_.size());
  measurement_points_.back() = measurement_px;
  if (points_.size() < 2) {
    *message = hint();
    return std::nullopt;
  }
  const cv::Point2d a = measurement_points_[0], b = measurement_points_[1];
  const double span_px = cv::norm(a - b);
  if (span_px < kMinSpanPx) {
    points_.clear();
    char text[160];
    std::snprintf(text, sizeof(text),
                  "scale: the points are %.1f px apart, too close (at least %.0f); click the "
                  "first point again",
                  span_px, kMinSpanPx);
    *message = text;
    return std::nullopt;
  }
  MetricModel metric;
  try {
    metric.scale_mm_per_px = ScaleFromTwoPoints(a, b, *distance_mm_, "scale points");
  } catch (const InputError& e) {
    points_.clear();
    *message = std::string(e.what()) + "; click the first point again";
    return std::nullopt;
  }
  metric.scale_points = MetricModel::ScalePoints{a, b, *distance_mm_};
  span_px_ = span_px;
  message->clear();
  return metric;
}

}  // namespace softsight
