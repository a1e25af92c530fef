// A marker seen by both cameras of a calibrated stereo rig (stereo_calibration.h) becomes a 3D
// point in millimetres in the first camera's frame, only after the pair is verified.
//
// Per pair: both positions are undistorted; the right one must lie near the epipolar line of
// the left one (otherwise the two views did not see the same thing: status kEpipolar, no point);
// cv::triangulatePoints gives a start, refined by Gauss-Newton on the reprojection error in both
// views (each weighted by its view's sub-pixel uncertainty); the uncertainty of the point
// follows from both views' uncertainties through the projection's Jacobian.
#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "softsight/calib/stereo_calibration.h"

namespace softsight {

struct TriangulationOptions {
  // A pair whose right position lies farther than this from the left position's epipolar line
  // (undistorted pixels of the right camera) is not believed (default 2 px: a marker centroid
  // is good to a few tenths of a pixel, a calibration to about 0.5 px; a wrong match across the
  // views is usually tens of pixels off). Lower it for sharper rigs, raise it for poor sync.
  double max_epipolar_px = 2.0;
  // Gauss-Newton steps after the linear triangulation (default 5; it converges in 2-3, 0 keeps
  // the linear solution).
  int refine_iterations = 5;
  // A view's sub-pixel uncertainty (1 sigma per coordinate, px) when the caller gives none
  // (default 0.1 px: the colour tracker's centroid on a sharp 9 px marker).
  double position_sigma_px = 0.1;

  bool Check(std::string* error) const;
};

enum class StereoStatus {
  kFound,     // Both views, on the epipolar line, in front of both cameras: a verified point.
  kMissing,   // Not found in one view or both (no pair to verify).
  kEpipolar,  // Found in both, but the pair breaks the epipolar constraint.
  kBehind,    // The rays meet behind a camera: not one object either.
  // On the epipolar line, but the two views' motions say their frames are not of one moment (a
  // wrong --frame-offset): moving along the epipolar line, the point's depth would be off
  // (StereoSession's pairing check; the triangulator never sets it).
  kTiming,
};
// "found", "missing", "epipolar", "behind", "timing".
const char* StereoStatusName(StereoStatus status);

struct StereoPoint {
  StereoStatus status = StereoStatus::kMissing;
  std::optional<cv::Point3d> position_mm{};  // Only with kFound.
  std::optional<double> epipolar_px{};       // Whenever both views have the marker.
  std::optional<double> reprojection_px{};   // RMS over both views after refinement (kFound).
  // 1-sigma uncertainty of the position: the covariance (mm^2) and the RMS radius
  // sqrt(trace) of it, mostly along the depth (kFound).
  std::optional<cv::Matx33d> covariance_mm2{};
  std::optional<double> sigma_mm{};

  bool found() const { return status == StereoStatus::kFound; }
};

class Triangulator {
 public:
  // Throws InputError when the calibration or the options do not pass their Check.
  explicit Triangulator(StereoCalibration stereo, TriangulationOptions options = {});

  // Raw (distorted) image positions of one marker in the left and right view; absent where the
  // view did not find it. Sigmas absent: options.position_sigma_px.
  StereoPoint triangulate(const std::optional<cv::Point2d>& left_px,
                          const std::optional<cv::Point2d>& right_px,
                          std::optional<double> left_sigma_px = std::nullopt,
                          std::optional<double> right_sigma_px = std::nullopt) const;

  // Distance of the right point from the left point's epipolar line, both raw pixels
  // (undistorted here), in undistorted pixels of the right camera.
  double epipolar_distance_px(const cv::Point2d& left_px, const cv::Point2d& right_px) const;
  // The same, signed, with the line's unit normal in the right image (the side the distance is
  // counted positive towards): how far a motion of the right point moves it across the line.
  double signed_epipolar_distance_px(const cv::Point2d& left_px, const cv::Point2d& right_px,
                                     cv::Vec2d* line_normal) const;

  // A point (mm, first camera's frame) to raw (distorted) pixels of each camera.
  cv::Point2d project_left(const cv::Point3d& point_mm) const;
  cv::Point2d project_right(const cv::Point3d& point_mm) const;

  const StereoCalibration& stereo() const { return stereo_; }
  const TriangulationOptions& options() const { return options_; }

 private:
  cv::Point2d undistort_left(const cv::Point2d& raw_px) const;
  cv::Point2d undistort_right(const cv::Point2d& raw_px) const;

  StereoCalibration stereo_;
  TriangulationOptions options_;
  cv::Mat left_distortion_, right_distortion_;
  cv::Matx34d left_projection_, right_projection_;  // K [I | 0] and K' [R | T].
};

}  // namespace softsight
