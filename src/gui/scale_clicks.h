// Internal to gui (and the tests). Scale mode of the live window (`c`): two clicked points a
// known distance apart (LiveOptions::scale_distance_mm) give the mm scale. This keeps the points
// and the hints and turns two points into a MetricModel; the controller hands that to the
// session and draws nothing of it (the view draws points()).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/geometry/measurement.h"

namespace softsight {

class ScaleClicks {
 public:
  // Two clicks closer than this give no usable scale: each click is good to about 1 px, so the
  // scale would be off by several percent. A ruler across much of the image is best.
  static constexpr double kMinSpanPx = 20.0;

  explicit ScaleClicks(std::optional<double> distance_mm) : distance_mm_(distance_mm) {}

  // Enters scale mode and returns the hint; without a known distance, stays off and says how
  // to give one.
  std::string start();
  // Leaves scale mode, forgetting the points.
  void stop() {
    active_ = false;
    points_.clear();
  }
  // Forgets the points, staying in scale mode (the next click is point 1 again).
  void restart() { points_.clear(); }

  // A clicked point: in image pixels (where the view draws it) and in the pixels measurements
  // use (undistorted with a camera model; what a saved config holds as scale_from_points).
  // After the second point: the model, or none (points too close or unusable: the points are
  // forgotten). `message` says what happened or what to click next.
  std::optional<MetricModel> add(const cv::Point2d& image_px, const cv::Point2d& measurement_px,
                                 std::string* message);

  bool active() const { return active_; }
  // What to click next (only in scale mode).
  std::string hint() const;
  const std::vector<cv::Point2d>& points() const { return points_; }  // Image pixels.
  // The distance between the two measurement points of the last model, px.
  double span_px() const { return span_px_; }

 private:
  std::optional<double> distance_mm_;
  bool active_ = false;
  std::vector<cv::Point2d> points_, measurement_points_;
  double span_px_ = 0.0;
};

// 50 -> "50", 12.5 -> "12.5": a distance as a person typed it.
std::string DistanceText(double mm);

}  // namespace softsight
