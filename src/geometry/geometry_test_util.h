// What the geometry tests share: the tolerance of exact constructions and points on a circle.
#pragma once

#include <cmath>
#include <numbers>

#include <opencv2/core.hpp>

namespace softsight::testing {

inline constexpr double kTol = 1e-9;  // Exact constructions: only rounding is allowed.

// The point at `angle_deg` (image axes: x right, y down) on the circle.
inline cv::Point2d OnCircle(cv::Point2d centre, double radius, double angle_deg) {
  const double a = angle_deg * std::numbers::pi / 180.0;
  return centre + radius * cv::Point2d(std::cos(a), std::sin(a));
}

}  // namespace softsight::testing
