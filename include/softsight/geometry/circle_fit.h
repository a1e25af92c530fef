// Least-squares circle through many marker positions (more than three markers along the body).
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

struct CircleFit {
  cv::Point2d centre{};
  double radius = 0.0;
  double rms_residual = 0.0;  // sqrt(mean((|p - centre| - radius)^2)), in the points' unit.
};

// Points spread along a line: the smallest principal spread is below kCollinearRelTol times the
// largest. Fewer than 3 distinct points count as collinear too (a line always passes through
// them). All points coincident (no spread at all) is not collinear but degenerate: see
// PointsAreDegenerate.
inline constexpr double kCollinearRelTol = 1e-9;

// True when every point coincides with the first (or fewer than one point): no direction at all.
bool PointsAreDegenerate(const std::vector<cv::Point2d>& points);
// True for non-degenerate points that lie on one line (see kCollinearRelTol).
bool PointsAreCollinear(const std::vector<cv::Point2d>& points);

// Taubin's algebraic circle fit (G. Taubin, 1991; Newton solution after N. Chernov): nearly
// unbiased for points on a short arc, no iteration over the points, no initial guess. Absent for
// fewer than 3 points, degenerate or collinear points.
std::optional<CircleFit> FitCircleTaubin(const std::vector<cv::Point2d>& points);

// Length along `circle` from the first to the last point, travelling through the intermediate
// points in order (so markers spread over more than half a circle give the major arc, and more
// than a full turn is possible). Each step between consecutive points takes the shorter way
// round, which holds when neighbouring markers are less than half a turn apart. Absent for fewer
// than 2 points or a point on the centre.
std::optional<double> ArcLengthThroughPoints(const CircleFit& circle,
                                             const std::vector<cv::Point2d>& points);

}  // namespace softsight
