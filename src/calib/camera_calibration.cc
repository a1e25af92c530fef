#include "softsight/calib/camera_calibration.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <regex>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/calibration_internals.h"
#include "softsight/core/error.h"

namespace softsight {

using calib_internal::CalibrateFromCorners;
using calib_internal::DistortionMat;
using calib_internal::kUndistortCriteria;
using calib_internal::Now;
using calib_internal::OpenForReading;
using calib_internal::FinishWriting;
using calib_internal::OpenForWriting;
using calib_internal::WriteCalibrationHeader;
using calib_internal::ReadMatrix;
using calib_internal::ReadPositiveInt;
using calib_internal::SizeText;

bool ChessboardSpec::Check(std::string* error) const {
  if (inner_corners.width < 2 || inner_corners.height < 2) {
    *error = "chessboard: needs at least 2x2 inner corners, got " + SizeText(inner_corners);
    return false;
  }
  if (!(std::isfinite(square_mm) && square_mm > 0.0)) {
    *error = "square_mm: must be > 0, got " + std::to_string(square_mm);
    return false;
  }
  return true;
}

bool CalibrationOptions::Check(std::string* error) const {
  if (!board.Check(error)) return false;
  if (min_views < 1) {
    *error = "min_views: must be >= 1, got " + std::to_string(min_views);
    return false;
  }
  return true;
}

cv::Size ParseChessboardSize(const std::string& text, const std::string& what) {
  static const std::regex kPattern(R"(\s*(\d{1,3})\s*[xX]\s*(\d{1,3})\s*)");
  std::smatch match;
  if (!std::regex_match(text, match, kPattern)) {
    throw InputError(what + ": expected inner corners as WIDTHxHEIGHT (e.g. 9x6), got '" + text +
                     "'");
  }
  const cv::Size size(std::stoi(match[1].str()), std::stoi(match[2].str()));
  if (size.width < 2 || size.height < 2) {
    throw InputError(what + ": a chessboard needs at least 2x2 inner corners, got '" + text + "'");
  }
  return size;
}

std::vector<cv::Point3f> ChessboardObjectPoints(const ChessboardSpec& spec) {
  std::vector<cv::Point3f> points;
  for (int r = 0; r < spec.inner_corners.height; ++r) {
    for (int c = 0; c < spec.inner_corners.width; ++c) {
      points.emplace_back(static_cast<float>(c * spec.square_mm),
                          static_cast<float>(r * spec.square_mm), 0.0f);
    }
  }
  return points;
}

std::optional<std::vector<cv::Point2f>> FindChessboard(const cv::Mat& image,
                                                       const cv::Size& inner_corners) {
  CV_Assert(image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3));
  cv::Mat gray;
  if (image.channels() == 3) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  } else {
    gray = image;
  }
  std::vector<cv::Point2f> corners;
  const int flags =
      cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
  if (!cv::findChessboardCorners(gray, inner_corners, corners, flags)) return std::nullopt;

  // The refinement window must stay inside the squares around each corner: a window reaching
  // the neighbouring corner pulls the estimate towards it.
  double spacing = std::numeric_limits<double>::max();
  for (int r = 0; r < inner_corners.height; ++r) {
    for (int c = 0; c < inner_corners.width; ++c) {
      const cv::Point2f p = corners[r * inner_corners.width + c];
      if (c + 1 < inner_corners.width) {
        spacing = std::min(spacing, cv::norm(corners[r * inner_corners.width + c + 1] - p));
      }
      if (r + 1 < inner_corners.height) {
        spacing = std::min(spacing, cv::norm(corners[(r + 1) * inner_corners.width + c] - p));
      }
    }
  }
  const int half = std::clamp(static_cast<int>(spacing * 0.4), 2, 11);
  cv::cornerSubPix(gray, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-4));
  return corners;
}

ChessboardCalibrator::ChessboardCalibrator(CalibrationOptions options)
    : options_(std::move(options)) {
  std::string error;
  if (!options_.Check(&error)) throw InputError("calibration: " + error);
}

bool ChessboardCalibrator::add(const std::string& name, const cv::Mat& image) {
  if (image.empty()) throw InputError(name + ": empty image");
  if (image_size_.empty()) {
    image_size_ = image.size();
  } else if (image.size() != image_size_) {
    throw InputError(name + ": image is " + SizeText(image.size()) + " but the first one was " +
                     SizeText(image_size_) + "; calibrate each camera resolution separately");
  }
  std::optional<std::vector<cv::Point2f>> corners =
      FindChessboard(image, options_.board.inner_corners);
  if (!corners) {
    not_found_.push_back(name);
    return false;
  }
  image_corners_.push_back(std::move(*corners));
  used_.push_back(name);
  return true;
}

CalibrationResult ChessboardCalibrator::calibrate() const {
  if (views_found() < options_.min_views) {
    throw InputError(
        "the " + SizeText(options_.board.inner_corners) + " chessboard was found in " +
        std::to_string(views_found()) + " of " + std::to_string(views_seen()) +
        " images, need at least " + std::to_string(options_.min_views) +
        " (--chessboard counts INNER corners; the whole board must be in view)");
  }
  CalibrationResult result;
  result.rms_px = CalibrateFromCorners(options_, image_size_, image_corners_, result.camera);
  result.used = used_;
  result.not_found = not_found_;
  return result;
}

void SaveCameraCalibration(const CalibrationResult& result, const ChessboardSpec& board,
                           const std::string& file) {
  cv::FileStorage fs = OpenForWriting(file);
  WriteCalibrationHeader(fs, result.camera.image_size, board);
  fs << "camera_matrix" << cv::Mat(result.camera.camera_matrix);
  fs << "distortion_coefficients" << DistortionMat(result.camera.distortion);
  fs << "avg_reprojection_error" << result.rms_px;
  fs << "views_used" << static_cast<int>(result.used.size());
  fs << "views_not_found" << "[";
  for (const std::string& name : result.not_found) fs << name;
  fs << "]";
  FinishWriting(fs, file);
}

CameraIntrinsics LoadCameraIntrinsics(const std::string& file) {
  cv::FileStorage fs = OpenForReading(file);
  CameraIntrinsics camera;
  camera.image_size = cv::Size(ReadPositiveInt(fs, file, "image_width"),
                               ReadPositiveInt(fs, file, "image_height"));
  camera.camera_matrix = cv::Matx33d(ReadMatrix(fs, file, "camera_matrix", 3, 3));
  const cv::Matx33d& k = camera.camera_matrix;
  if (!(k(0, 0) > 0 && k(1, 1) > 0 && k(2, 2) == 1.0 && k(1, 0) == 0 && k(2, 0) == 0 &&
        k(2, 1) == 0)) {
    throw InputError(file + ": camera_matrix: not a camera matrix [fx 0 cx; 0 fy cy; 0 0 1]");
  }
  const cv::Mat d = ReadMatrix(fs, file, "distortion_coefficients", 0, 0).reshape(1, 1);
  if (d.cols != 4 && d.cols != 5 && d.cols != 8 && d.cols != 12 && d.cols != 14) {
    throw InputError(file + ": distortion_coefficients: expected 4, 5, 8, 12 or 14 values, got " +
                     std::to_string(d.cols));
  }
  d.copyTo(camera.distortion);
  return camera;
}

Undistorter::Undistorter(const CameraIntrinsics& camera) : camera_(camera) {
  CV_Assert(!camera_.image_size.empty());
  cv::initUndistortRectifyMap(camera_.camera_matrix, DistortionMat(camera_.distortion),
                              cv::noArray(), camera_.camera_matrix, camera_.image_size, CV_16SC2,
                              map1_, map2_);
}

void Undistorter::apply(const cv::Mat& in, cv::Mat& out) const {
  if (in.size() != camera_.image_size) {
    throw InputError("frame is " + SizeText(in.size()) + " but the camera calibration is for " +
                     SizeText(camera_.image_size) + " images");
  }
  CV_Assert(in.data != out.data);  // remap cannot work in place.
  cv::remap(in, out, map1_, map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
}

cv::Point2d Undistorter::undistort_point(const cv::Point2d& raw_px) const {
  const std::vector<cv::Point2d> in = {raw_px};
  std::vector<cv::Point2d> out;
  cv::undistortPoints(in, out, camera_.camera_matrix, DistortionMat(camera_.distortion),
                      cv::noArray(), camera_.camera_matrix, kUndistortCriteria);
  return out.front();
}

void Undistorter::undistort_points(const std::vector<cv::Point2f>& raw_px,
                                   std::vector<cv::Point2f>& undistorted_px) const {
  if (raw_px.empty()) {
    undistorted_px.clear();
    return;
  }
  cv::undistortPoints(raw_px, undistorted_px, camera_.camera_matrix,
                      DistortionMat(camera_.distortion), cv::noArray(), camera_.camera_matrix,
                      kUndistortCriteria);
}

PlaneCalibration PlaneFromCorners(const std::vector<cv::Point2f>& corners_px,
                                  const ChessboardSpec& board) {
  const std::vector<cv::Point3f> object3 = ChessboardObjectPoints(board);
  CV_Assert(corners_px.size() == object3.size());
  std::vector<cv::Point2f> object;
  for (const cv::Point3f& p : object3) object.emplace_back(p.x, p.y);
  // Plain least squares over every corner: a found board has no outliers to reject.
  const cv::Mat h = cv::findHomography(corners_px, object, 0);
  if (h.empty()) throw InputError("plane: the chessboard corners do not define a homography");
  PlaneCalibration plane;
  plane.board = board;
  plane.plane_mm_from_image = cv::Matx33d(h) * (1.0 / h.at<double>(2, 2));
  const cv::Matx33d& m = plane.plane_mm_from_image;

  double sum_sq = 0.0;
  cv::Point2d centre(0, 0);
  for (size_t i = 0; i < corners_px.size(); ++i) {
    const std::optional<cv::Point2d> p = MapToPlane(m, corners_px[i]);
    CV_Assert(p.has_value());
    const cv::Point2d e = *p - cv::Point2d(object[i]);
    sum_sq += e.dot(e);
    centre += cv::Point2d(corners_px[i]);
  }
  plane.rms_mm = std::sqrt(sum_sq / static_cast<double>(corners_px.size()));
  centre *= 1.0 / static_cast<double>(corners_px.size());

  // Local scale: sqrt of the Jacobian determinant of the homography at the board's centre,
  // i.e. the side of the plane square one image pixel covers there.
  const cv::Vec3d a = m * cv::Vec3d(centre.x, centre.y, 1.0);
  const double w = a[2];
  const double dudx = (m(0, 0) * w - a[0] * m(2, 0)) / (w * w);
  const double dudy = (m(0, 1) * w - a[0] * m(2, 1)) / (w * w);
  const double dvdx = (m(1, 0) * w - a[1] * m(2, 0)) / (w * w);
  const double dvdy = (m(1, 1) * w - a[1] * m(2, 1)) / (w * w);
  plane.mm_per_px = std::sqrt(std::abs(dudx * dvdy - dudy * dvdx));
  return plane;
}

PlaneCalibration CalibratePlane(const cv::Mat& raw_image, const std::string& image_name,
                                const ChessboardSpec& board,
                                const std::optional<CameraIntrinsics>& camera) {
  std::string error;
  if (!board.Check(&error)) throw InputError(error);
  if (raw_image.empty()) throw InputError(image_name + ": cannot read the image");
  std::optional<std::vector<cv::Point2f>> corners = FindChessboard(raw_image, board.inner_corners);
  if (!corners) {
    throw InputError(image_name + ": the " + SizeText(board.inner_corners) +
                     " chessboard was not found (the whole board must be in view)");
  }
  if (camera) {
    if (raw_image.size() != camera->image_size) {
      throw InputError(image_name + ": image is " + SizeText(raw_image.size()) +
                       " but the camera calibration is for " + SizeText(camera->image_size));
    }
    // Undistorting the corners (not the image) keeps their sub-pixel accuracy.
    std::vector<cv::Point2f> undistorted;
    cv::undistortPoints(*corners, undistorted, camera->camera_matrix,
                        DistortionMat(camera->distortion), cv::noArray(), camera->camera_matrix,
                        kUndistortCriteria);
    corners = std::move(undistorted);
  }
  return PlaneFromCorners(*corners, board);
}

void SavePlaneCalibration(const PlaneCalibration& plane, const std::string& file) {
  cv::FileStorage fs = OpenForWriting(file);
  fs << "calibration_time" << Now();
  fs << "plane_mm_from_image" << cv::Mat(plane.plane_mm_from_image);
  fs << "mm_per_px" << plane.mm_per_px;
  fs << "rms_mm" << plane.rms_mm;
  fs << "board_width" << plane.board.inner_corners.width;
  fs << "board_height" << plane.board.inner_corners.height;
  fs << "square_size_mm" << plane.board.square_mm;
  FinishWriting(fs, file);
}

PlaneCalibration LoadPlaneCalibration(const std::string& file) {
  cv::FileStorage fs = OpenForReading(file);
  PlaneCalibration plane;
  plane.plane_mm_from_image = cv::Matx33d(ReadMatrix(fs, file, "plane_mm_from_image", 3, 3));
  MetricModel metric;
  metric.plane_mm_from_image = plane.plane_mm_from_image;
  std::string error;
  if (!metric.Check(&error)) throw InputError(file + ": plane_mm_from_image: " + error);
  // The summaries are informative only; absent ones stay 0.
  if (!fs["mm_per_px"].empty()) plane.mm_per_px = static_cast<double>(fs["mm_per_px"]);
  if (!fs["rms_mm"].empty()) plane.rms_mm = static_cast<double>(fs["rms_mm"]);
  if (!fs["board_width"].empty()) {
    plane.board.inner_corners = cv::Size(static_cast<int>(fs["board_width"]),
                                         static_cast<int>(fs["board_height"]));
    plane.board.square_mm = static_cast<double>(fs["square_size_mm"]);
  }
  return plane;
}

double ScaleFromTwoPoints(const cv::Point2d& a_px, const cv::Point2d& b_px, double distance_mm,
                          const std::string& what) {
  if (!(std::isfinite(distance_mm) && distance_mm > 0.0)) {
    throw InputError(what + ": the known distance must be > 0 mm, got " +
                     std::to_string(distance_mm));
  }
  const double distance_px = cv::norm(a_px - b_px);
  if (!std::isfinite(distance_px) || distance_px < 1.0) {
    throw InputError(what + ": the two points are " + std::to_string(distance_px) +
                     " px apart; pick two points far apart (at least 1 px, better 100+)");
  }
  return distance_mm / distance_px;
}

}  // namespace softsight
