// The centre of a partly hidden disc from its visible rim: a circle of known radius fitted to the
// edge points of what is left of it. A paddle or the frame's edge cuts the disc along a chord;
// the centroid of what is left moves towards it (0.4 radii when half is covered), but the rim
// that still shows lies on the marker's own circle. Fitted robustly (the cut's points are
// outliers: they lie inside the circle), then refined by least squares on the rim's points.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

struct RimFit {
  cv::Point2d centre_px;
  double rms_px = 0;          // Of the rim points' distances from the circle.
  double arc_deg = 0;         // The angle the rim points span around the centre.
  int rim_points = 0;         // Points on the circle (within the inlier tolerance).
};

// Fits a circle of radius `radius_px` to `edge_px` (the blob's edge pixels' centres). A point
// within `inlier_px` of the circle is on the rim. Absent when no circle has at least 6 rim points.
// Deterministic (candidate circles from pairs of points taken in a fixed order). `scratch`, when
// given, is reused storage for the rim points' angles (no allocation once warm).
std::optional<RimFit> FitRimOfRadius(const std::vector<cv::Point2d>& edge_px, double radius_px,
                                     double inlier_px = 0.75,
                                     std::vector<double>* scratch = nullptr);

// How many of `edge_px` lie within `tol` of the circle of radius `r` about `c` (|p - c| - r, as
// cv::norm gives it): FitRimOfRadius's test of each candidate circle, which was nine tenths of it
// (issue 45). Two points at a time (OpenCV universal intrinsics, the same IEEE operations as the
// reference), and only as far as needed to beat `best`: the count when it exceeds `best`,
// otherwise some count no larger than `best` (the fit asks only whether a candidate beats the
// best so far). The reference: every point, one at a time, the exact count.
int CountRimInliers(const std::vector<cv::Point2d>& edge_px, const cv::Point2d& c, double r,
                    double tol, int best);
int CountRimInliersReference(const std::vector<cv::Point2d>& edge_px, const cv::Point2d& c,
                             double r, double tol);

// How far the edge that is not on the fitted circle bulges outwards (px) beyond the straight line
// joining its two ends. A disc cut by a straight edge leaves a chord (0); a finger or a paddle
// pushes the edge inwards (negative); a whole marker seen in perspective (an ellipse narrower than
// the learned disc) has a convex arc there, bulging by its sagitta: it is not partly hidden, and
// the circle through part of its edge is not its centre. `scratch` is reused. Absent when fewer
// than three edge points lie inside the circle, off it.
std::optional<double> OffRimBulgePx(const std::vector<cv::Point2d>& edge_px, const RimFit& fit,
                                    double radius_px, double inlier_px,
                                    std::vector<std::pair<double, cv::Point2d>>* scratch);

}  // namespace softsight
