// Camera calibration (intrinsics and lens distortion from chessboard views), undistortion, and
// the scale from image pixels to millimetres in the actuator's plane.
//
// The chain for metric measurements: raw frame -> Undistorter -> tracked positions (undistorted
// pixels) -> MetricModel (a homography to the plane, or one scale) -> millimetres.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/geometry/measurement.h"

namespace softsight {

// The printed chessboard, as `--chessboard 9x6 --square-mm 25` gives it.
struct ChessboardSpec {
  // Inner corners per row x per column (a board of 10 x 7 squares has 9 x 6 inner corners).
  // Both >= 2; width != height lets the detector tell the board's orientation.
  cv::Size inner_corners{9, 6};
  double square_mm = 25.0;  // Side of one square, measured on the print (mm, > 0).

  bool Check(std::string* error) const;
};

// Parses "9x6" (inner corners, width x height). Throws InputError naming `what` (e.g.
// "--chessboard") and the text on anything else.
cv::Size ParseChessboardSize(const std::string& text, const std::string& what);

// Board corners in board millimetres, (c * square, r * square, 0), in detection order.
std::vector<cv::Point3f> ChessboardObjectPoints(const ChessboardSpec& spec);

// Finds the inner corners with sub-pixel refinement (findChessboardCorners + cornerSubPix, the
// refinement window sized from the detected square size). `image` is 8-bit gray or BGR. Absent
// when the whole board is not visible.
std::optional<std::vector<cv::Point2f>> FindChessboard(const cv::Mat& image,
                                                       const cv::Size& inner_corners);

// What calibrateCamera estimates. The distortion is OpenCV's (k1, k2, p1, p2, k3).
struct CameraIntrinsics {
  cv::Size image_size{};
  cv::Matx33d camera_matrix = cv::Matx33d::eye();
  std::vector<double> distortion{};
};

struct CalibrationResult {
  CameraIntrinsics camera{};
  double rms_px = 0.0;                   // Reprojection RMS over every corner of every view.
  std::vector<std::string> used{};       // Views where the board was found.
  std::vector<std::string> not_found{};  // Views where it was not (listed for the user).
};

struct CalibrationOptions {
  ChessboardSpec board{};
  // Estimate k3 too (default false: with a handful of views of a webcam lens, k3 mostly fits
  // noise; turn on for wide-angle lenses with strong barrel distortion).
  bool estimate_k3 = false;
  // Fewest views with a found board to calibrate from (default 3; the focal length is poorly
  // determined by fewer, and 10-20 tilted views are recommended).
  int min_views = 3;

  bool Check(std::string* error) const;
};

// Accumulates chessboard views one image at a time (a video need not be held in memory), then
// calibrates.
class ChessboardCalibrator {
 public:
  // Throws InputError when options.Check fails.
  explicit ChessboardCalibrator(CalibrationOptions options);

  // Looks for the board in `image` (named `name` in messages). Returns whether it was found.
  // Throws InputError when the image size differs from the first image's.
  bool add(const std::string& name, const cv::Mat& image);

  // Throws InputError when fewer than options.min_views views had the board (naming how many
  // images were looked at).
  CalibrationResult calibrate() const;

  int views_found() const { return static_cast<int>(image_corners_.size()); }
  int views_seen() const { return static_cast<int>(used_.size() + not_found_.size()); }

 private:
  CalibrationOptions options_;
  cv::Size image_size_;
  std::vector<std::vector<cv::Point2f>> image_corners_;
  std::vector<std::string> used_, not_found_;
};

// OpenCV FileStorage YAML (camera_matrix, distortion_coefficients, image_width, image_height,
// avg_reprojection_error, ...). Load throws InputError naming the file and the missing/bad key.
void SaveCameraCalibration(const CalibrationResult& result, const ChessboardSpec& board,
                           const std::string& file);
CameraIntrinsics LoadCameraIntrinsics(const std::string& file);

// Removes lens distortion from whole frames. The maps are computed once; apply() only remaps
// (no allocation once `out` has the frame's size and type). The undistorted image keeps the
// same camera matrix, so undistorted pixel coordinates are what the plane homography expects.
class Undistorter {
 public:
  explicit Undistorter(const CameraIntrinsics& camera);

  // Throws InputError when `in` does not have the calibrated image size.
  void apply(const cv::Mat& in, cv::Mat& out) const;
  // One raw (distorted) pixel position to its undistorted position.
  cv::Point2d undistort_point(const cv::Point2d& raw_px) const;
  void undistort_points(const std::vector<cv::Point2f>& raw_px,
                        std::vector<cv::Point2f>& undistorted_px) const;

  const CameraIntrinsics& camera() const { return camera_; }

 private:
  CameraIntrinsics camera_;
  cv::Mat map1_, map2_;
};

// The actuator's plane from a chessboard lying in it.
struct PlaneCalibration {
  cv::Matx33d plane_mm_from_image = cv::Matx33d::eye();  // Undistorted px -> board mm.
  double mm_per_px = 0.0;  // Local scale at the board's centre (a summary for people).
  double rms_mm = 0.0;     // Corners mapped through the homography vs their true positions.
  ChessboardSpec board{};
};

// From the board's inner corners in UNDISTORTED image pixels (detection order).
PlaneCalibration PlaneFromCorners(const std::vector<cv::Point2f>& corners_px,
                                  const ChessboardSpec& board);
// Finds the board in a raw image (undistorting its corners with `camera` when given) and fits
// the plane. Throws InputError naming `image_name` when the board is not found.
PlaneCalibration CalibratePlane(const cv::Mat& raw_image, const std::string& image_name,
                                const ChessboardSpec& board,
                                const std::optional<CameraIntrinsics>& camera);

// OpenCV FileStorage YAML with plane_mm_from_image, mm_per_px, rms_mm and the board.
void SavePlaneCalibration(const PlaneCalibration& plane, const std::string& file);
PlaneCalibration LoadPlaneCalibration(const std::string& file);

// Scale from two (undistorted) image points a known distance apart, e.g. two clicks on a ruler.
// Throws InputError (naming `what`) when the points coincide or the distance is not > 0.
double ScaleFromTwoPoints(const cv::Point2d& a_px, const cv::Point2d& b_px, double distance_mm,
                          const std::string& what = "scale_from_points");

}  // namespace softsight
