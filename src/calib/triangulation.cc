#include "softsight/calib/triangulation.h"

#include <cmath>

#include <opencv2/calib3d.hpp>

#include "calib/calibration_internals.h"
#include "softsight/core/error.h"

namespace softsight {

using calib_internal::DistortionMat;
using calib_internal::kUndistortCriteria;

namespace {

// One camera as the refinement sees it: x_cam = rotation * x + translation, then K.
struct View {
  const cv::Matx33d& camera_matrix;
  const cv::Matx33d& rotation;
  const cv::Vec3d& translation;
  cv::Point2d observed_px;  // Undistorted.
  double sigma_px;
};

// Undistorted pixel position of `point` in `view` and its 2x3 Jacobian; false behind the camera.
bool Project(const View& view, const cv::Vec3d& point, cv::Point2d& px, cv::Matx23d& jacobian) {
  const cv::Vec3d c = view.rotation * point + view.translation;
  if (!(c[2] > 0.0)) return false;
  const cv::Matx33d& k = view.camera_matrix;
  const double x = c[0] / c[2], y = c[1] / c[2];
  px = cv::Point2d(k(0, 0) * x + k(0, 1) * y + k(0, 2), k(1, 1) * y + k(1, 2));
  // d(x, y)/d(c) for the normalised coordinates, then through K and the rotation.
  const cv::Matx23d dn_dc(1.0 / c[2], 0.0, -x / c[2], 0.0, 1.0 / c[2], -y / c[2]);
  const cv::Matx22d dpx_dn(k(0, 0), k(0, 1), 0.0, k(1, 1));
  jacobian = dpx_dn * dn_dc * view.rotation;
  return true;
}

}  // namespace

bool TriangulationOptions::Check(std::string* error) const {
  if (!(std::isfinite(max_epipolar_px) && max_epipolar_px > 0.0)) {
    *error = "max_epipolar_px: must be > 0, got " + std::to_string(max_epipolar_px);
    return false;
  }
  if (refine_iterations < 0 || refine_iterations > 100) {
    *error = "refine_iterations: must be in [0, 100], got " + std::to_string(refine_iterations);
    return false;
  }
  if (!(std::isfinite(position_sigma_px) && position_sigma_px > 0.0)) {
    *error = "position_sigma_px: must be > 0, got " + std::to_string(position_sigma_px);
    return false;
  }
  return true;
}

const char* StereoStatusName(StereoStatus status) {
  switch (status) {
    case StereoStatus::kFound: return "found";
    case StereoStatus::kMissing: return "missing";
    case StereoStatus::kEpipolar: return "epipolar";
    case StereoStatus::kBehind: return "behind";
    case StereoStatus::kTiming: return "timing";
  }
  return "?";
}

Triangulator::Triangulator(StereoCalibration stereo, TriangulationOptions options)
    : stereo_(std::move(stereo)), options_(options) {
  std::string error;
  if (!stereo_.Check(&error)) throw InputError("stereo calibration: " + error);
  if (!options_.Check(&error)) throw InputError("triangulation: " + error);
  left_distortion_ = DistortionMat(stereo_.left.distortion);
  right_distortion_ = DistortionMat(stereo_.right.distortion);
  const cv::Matx34d identity(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0);
  left_projection_ = stereo_.left.camera_matrix * identity;
  const cv::Matx33d& r = stereo_.R;
  const cv::Vec3d& t = stereo_.T;
  right_projection_ =
      stereo_.right.camera_matrix * cv::Matx34d(r(0, 0), r(0, 1), r(0, 2), t[0], r(1, 0), r(1, 1),
                                                r(1, 2), t[1], r(2, 0), r(2, 1), r(2, 2), t[2]);
}

cv::Point2d Triangulator::undistort_left(const cv::Point2d& raw_px) const {
  cv::Point2d out;
  // Headers over the two points: no allocation per call.
  cv::undistortPoints(cv::Mat(1, 1, CV_64FC2, const_cast<cv::Point2d*>(&raw_px)),
                      cv::Mat(1, 1, CV_64FC2, &out), stereo_.left.camera_matrix, left_distortion_,
                      cv::noArray(), stereo_.left.camera_matrix, kUndistortCriteria);
  return out;
}

cv::Point2d Triangulator::undistort_right(const cv::Point2d& raw_px) const {
  cv::Point2d out;
  cv::undistortPoints(cv::Mat(1, 1, CV_64FC2, const_cast<cv::Point2d*>(&raw_px)),
                      cv::Mat(1, 1, CV_64FC2, &out), stereo_.right.camera_matrix, right_distortion_,
                      cv::noArray(), stereo_.right.camera_matrix, kUndistortCriteria);
  return out;
}

double Triangulator::epipolar_distance_px(const cv::Point2d& left_px,
                                          const cv::Point2d& right_px) const {
  const cv::Point2d l = undistort_left(left_px), r = undistort_right(right_px);
  const cv::Vec3d line = stereo_.F * cv::Vec3d(l.x, l.y, 1.0);
  return std::abs(line.dot(cv::Vec3d(r.x, r.y, 1.0))) / std::hypot(line[0], line[1]);
}

double Triangulator::signed_epipolar_distance_px(const cv::Point2d& left_px,
                                                 const cv::Point2d& right_px,
                                                 cv::Vec2d* line_normal) const {
  const cv::Point2d l = undistort_left(left_px), r = undistort_right(right_px);
  const cv::Vec3d line = stereo_.F * cv::Vec3d(l.x, l.y, 1.0);
  const double norm = std::hypot(line[0], line[1]);
  *line_normal = cv::Vec2d(line[0] / norm, line[1] / norm);
  return line.dot(cv::Vec3d(r.x, r.y, 1.0)) / norm;
}

cv::Point2d Triangulator::project_left(const cv::Point3d& point_mm) const {
  cv::Point2d out;
  cv::projectPoints(cv::Mat(1, 1, CV_64FC3, const_cast<cv::Point3d*>(&point_mm)), cv::Vec3d(),
                    cv::Vec3d(), stereo_.left.camera_matrix, left_distortion_,
                    cv::Mat(1, 1, CV_64FC2, &out));
  return out;
}

cv::Point2d Triangulator::project_right(const cv::Point3d& point_mm) const {
  cv::Vec3d rvec;
  cv::Rodrigues(stereo_.R, rvec);
  cv::Point2d out;
  cv::projectPoints(cv::Mat(1, 1, CV_64FC3, const_cast<cv::Point3d*>(&point_mm)), rvec, stereo_.T,
                    stereo_.right.camera_matrix, right_distortion_, cv::Mat(1, 1, CV_64FC2, &out));
  return out;
}

StereoPoint Triangulator::triangulate(const std::optional<cv::Point2d>& left_px,
                                      const std::optional<cv::Point2d>& right_px,
                                      std::optional<double> left_sigma_px,
                                      std::optional<double> right_sigma_px) const {
  StereoPoint result;
  if (!left_px || !right_px) return result;  // kMissing: nothing to verify.
  const cv::Point2d l = undistort_left(*left_px), r = undistort_right(*right_px);
  const cv::Vec3d line = stereo_.F * cv::Vec3d(l.x, l.y, 1.0);
  result.epipolar_px = std::abs(line.dot(cv::Vec3d(r.x, r.y, 1.0))) / std::hypot(line[0], line[1]);
  if (!(*result.epipolar_px <= options_.max_epipolar_px)) {
    result.status = StereoStatus::kEpipolar;
    return result;
  }

  cv::Vec4d homogeneous;
  cv::Point2d l_copy = l, r_copy = r;  // triangulatePoints reads 2 x N matrices.
  cv::triangulatePoints(left_projection_, right_projection_, cv::Mat(2, 1, CV_64F, &l_copy),
                        cv::Mat(2, 1, CV_64F, &r_copy), homogeneous);
  if (homogeneous[3] == 0.0) {
    result.status = StereoStatus::kBehind;  // Parallel rays: the point is at infinity.
    return result;
  }
  cv::Vec3d point(homogeneous[0] / homogeneous[3], homogeneous[1] / homogeneous[3],
                  homogeneous[2] / homogeneous[3]);

  static const cv::Matx33d kIdentity = cv::Matx33d::eye();
  static const cv::Vec3d kZero(0, 0, 0);
  const View views[2] = {{stereo_.left.camera_matrix, kIdentity, kZero, l,
                          left_sigma_px.value_or(options_.position_sigma_px)},
                         {stereo_.right.camera_matrix, stereo_.R, stereo_.T, r,
                          right_sigma_px.value_or(options_.position_sigma_px)}};

  // Gauss-Newton on the weighted reprojection error: the linear solution minimises an
  // algebraic error that weights the two views by their depths, not by their pixels.
  cv::Matx33d normal;  // J^T W J at the last point: its inverse is the covariance.
  double squared_error_px2 = 0.0;
  bool converged = false;
  // Each pass evaluates the error and the Jacobian at the current point; the last one (after
  // the last step, or once a step no longer moves it) only evaluates, for the covariance.
  for (int iteration = 0;; ++iteration) {
    normal = cv::Matx33d::zeros();
    cv::Vec3d gradient(0, 0, 0);
    squared_error_px2 = 0.0;
    for (const View& view : views) {
      cv::Point2d px;
      cv::Matx23d jacobian;
      if (!Project(view, point, px, jacobian)) {
        result.status = StereoStatus::kBehind;
        return result;
      }
      const cv::Point2d residual = view.observed_px - px;
      squared_error_px2 += residual.dot(residual);
      const double weight = 1.0 / (view.sigma_px * view.sigma_px);
      normal += weight * (jacobian.t() * jacobian);
      gradient += weight * (jacobian.t() * cv::Vec2d(residual.x, residual.y));
    }
    if (converged || iteration >= options_.refine_iterations) break;
    cv::Vec3d step;
    if (!cv::solve(normal, gradient, step, cv::DECOMP_CHOLESKY)) break;
    point += step;
    converged = cv::norm(step) < 1e-10 * cv::norm(point);
  }
  result.status = StereoStatus::kFound;
  result.position_mm = cv::Point3d(point[0], point[1], point[2]);
  result.reprojection_px = std::sqrt(squared_error_px2 / 2.0);
  const cv::Matx33d covariance = normal.inv(cv::DECOMP_CHOLESKY);
  result.covariance_mm2 = covariance;
  result.sigma_mm = std::sqrt(std::max(0.0, cv::trace(covariance)));
  return result;
}

}  // namespace softsight
