// Measurements on marker positions in 3D (two cameras, triangulated): the angle at the middle
// marker, the bending plane and how far it leans out of a reference plane, the radius and arc
// length of the circle through the markers, the tip's displacement.
//
// Plain math on points, like triangle.h: lengths come out in the unit of the input points
// (millimetres from a stereo rig), angles in degrees. What cannot be computed is absent.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

// Angle at `middle` between the rays to `base` and `tip`, in degrees, in [0, 180] (eq. 7 in 3D:
// the bend seen by no camera in particular). Absent when `middle` coincides with an end.
std::optional<double> AngleAtMiddle3dDeg(const cv::Point3d& base, const cv::Point3d& middle,
                                         const cv::Point3d& tip);

struct PlaneFit3d {
  cv::Point3d centroid{};
  cv::Vec3d normal{};         // Unit length; its sign is set by FitPlane3d's rule.
  double rms_residual = 0.0;  // RMS distance of the points from the plane.
};

// Least-squares plane (smallest principal axis of the points' scatter). Absent for fewer than 3
// points or points on a line (no plane). The normal's sign: it points the way of
// (p1 - p0) x (p_last - p0) when that is defined, so a chain bending one way keeps one sign.
std::optional<PlaneFit3d> FitPlane3d(const std::vector<cv::Point3d>& points);

// Angle between two planes given by their normals, in degrees, in [0, 90] (a plane's normal has
// no preferred sign). Absent when a normal has zero length.
std::optional<double> AngleBetweenPlanesDeg(const cv::Vec3d& normal_a, const cv::Vec3d& normal_b);

struct CircleFit3d {
  cv::Point3d centre{};
  cv::Vec3d normal{};  // The plane the circle lies in (unit).
  double radius = 0.0;
  double rms_residual = 0.0;  // RMS distance of the points from the circle, in 3D.
};

// Fits the plane, then Taubin's circle in that plane (circle_fit.h). Absent for fewer than 3
// points, collinear points. Three points give their circumcircle.
std::optional<CircleFit3d> FitCircle3d(const std::vector<cv::Point3d>& points);

// Length along `circle` from the first to the last point through the others in order (as
// ArcLengthThroughPoints, after projecting the points into the circle's plane).
std::optional<double> ArcLength3d(const CircleFit3d& circle,
                                  const std::vector<cv::Point3d>& points);

// What a frame's 3D markers give.
struct Shape3d {
  std::optional<double> angle_deg{};         // At the chain's middle marker.
  std::optional<cv::Vec3d> plane_normal{};   // The bending plane (all found markers).
  std::optional<double> out_of_plane_deg{};  // Bending plane vs the reference plane.
  std::optional<double> radius{};            // 3D circle fit through all found markers.
  std::optional<double> arc_length{};        // Along that circle, base to tip.
  std::optional<double> tip_disp{};          // Tip from its reference position.
};

// One hinge of a chain: the circle through three consecutive markers (per-segment curvature of
// a multi-segment actuator).
struct Segment3d {
  std::optional<double> angle_deg{};   // At the middle one of the three (eq. 7 in 3D).
  std::optional<double> radius{};      // Their circumcircle; absent when they are on a line.
  std::optional<double> arc_length{};  // First to last through the middle along that circle;
                                     // the two distances added when on a line.
};

// For each inner marker chain[k] (k = 1 .. N-2) the circle through chain[k-1], chain[k] and
// chain[k+1], into `segments` (resized to N-2, or emptied for fewer than 3 markers; no
// allocation once its capacity is reached). A segment with a missing marker has no values.
void MeasureSegments3d(const std::vector<std::optional<cv::Point3d>>& chain,
                       std::vector<Segment3d>* segments);

// `chain`: the markers base to tip (3 or more), absent where not found. The angle needs the
// first, the middle (index size / 2) and the last; plane and circle need 3 found markers;
// the out-of-plane angle needs `reference_normal` (e.g. the first frame's bending plane, or
// (0, 0, 1): the first camera's image plane); the tip displacement the tip and `tip_reference`.
Shape3d MeasureShape3d(const std::vector<std::optional<cv::Point3d>>& chain,
                       const std::optional<cv::Vec3d>& reference_normal,
                       const std::optional<cv::Point3d>& tip_reference);

}  // namespace softsight
