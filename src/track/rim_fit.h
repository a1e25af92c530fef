// The centre of a partly hidden disc from its visible rim: a circle of known radius fitted to the
// edge points of what is left of it. A paddle or the frame's edge cuts the disc along a chord;
// the centroid of what is left moves towards it (0.4 radii when half is covered), but the rim
// that still shows lies on the marker's own circle. Fitted robustly (the cut's points are
// outliers: they lie inside the circle), then refined by least squares on the rim's points.
#pragma once

#include <optional>
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
// Deterministic (candidate circles from pairs of points taken in a fixed order).
std::optional<RimFit> FitRimOfRadius(const std::vector<cv::Point2d>& edge_px, double radius_px,
                                     double inlier_px = 0.75);

}  // namespace softsight
