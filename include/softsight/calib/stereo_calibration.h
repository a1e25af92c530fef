// Two cameras looking at the actuator together (a stereo rig): each camera's intrinsics and
// distortion, where the second camera sits relative to the first, and the rectification, from
// pairs of chessboard views taken at the same moment.
//
// Frames: 3D points are in millimetres in the FIRST (left) camera's frame: x right, y down,
// z along its optical axis. The second camera sees X_right = R * X_left + T (OpenCV's
// stereoCalibrate convention), so its centre is at -R^T T in the first camera's frame and the
// baseline is |T|.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/calib/camera_calibration.h"

namespace softsight {

struct StereoCalibration {
  CameraIntrinsics left{}, right{};      // Both with the same image size.
  cv::Matx33d R = cv::Matx33d::eye();    // right_from_left rotation.
  cv::Vec3d T{};                         // right_from_left translation (mm).
  cv::Matx33d E = cv::Matx33d::zeros();  // Essential matrix (normalised coordinates).
  cv::Matx33d F = cv::Matx33d::zeros();  // Fundamental matrix, UNDISTORTED pixels left -> right.
  // Rectification (stereoRectify, alpha 0): rotations into the common rectified frame, the
  // rectified cameras' projections and the disparity-to-depth matrix.
  cv::Matx33d R1 = cv::Matx33d::eye(), R2 = cv::Matx33d::eye();
  cv::Matx34d P1 = cv::Matx34d::zeros(), P2 = cv::Matx34d::zeros();
  cv::Matx44d Q = cv::Matx44d::zeros();
  double rms_px = 0.0;  // stereoCalibrate's reprojection RMS over both views of every used pair.

  double baseline_mm() const { return cv::norm(T); }
  // Checks the sizes agree and the matrices are finite; names the bad field.
  bool Check(std::string* error) const;
};

// Fills E, F and the rectification from the intrinsics, R and T (what a renderer with known
// poses or a hand-written rig needs; stereoCalibrate gives them itself).
void CompleteStereoCalibration(StereoCalibration& stereo);

struct StereoCalibrationOptions {
  // The board, k3 and the fewest views each camera's own calibration needs (min_views also
  // counts the pairs: the fewest pairs with the board in both views).
  CalibrationOptions camera{};
  // A pair whose reprojection error (the larger of its two views') is above
  // max(outlier_factor x the median pair's, outlier_floor_px) does not fit the others (a board
  // that moved between the two exposures, a wrong corner order, motion blur): it is reported and
  // left out, and the rig is calibrated again without it. Default 3 x median, at least 1 px.
  double outlier_factor = 3.0;
  double outlier_floor_px = 1.0;

  bool Check(std::string* error) const;
};

// What happened to one pair of views.
enum class StereoPairStatus {
  kUsed,       // The board in both views, and the pair fits the others.
  kLeftOnly,   // The board was found in the left view only.
  kRightOnly,  // ... in the right view only.
  kNeither,    // ... in neither view.
  kOutlier,    // Found in both, but its reprojection error does not fit the other pairs.
};
// "used", "left_only", "right_only", "neither", "outlier".
const char* StereoPairStatusName(StereoPairStatus status);

struct StereoPairReport {
  std::string left_name{}, right_name{};
  StereoPairStatus status = StereoPairStatus::kNeither;
  // Reprojection RMS of the left and right view of the pair in the joint calibration (also for
  // an outlier: the figure that left it out); absent when the board was not in both views.
  std::optional<double> left_rms_px{}, right_rms_px{};
};

struct StereoCalibrationResult {
  StereoCalibration stereo{};
  double left_rms_px = 0.0, right_rms_px = 0.0;  // Each camera's own calibration.
  std::vector<StereoPairReport> pairs{};         // Every pair added, in order.
  int pairs_used() const;
};

// Accumulates pairs one at a time (a video need not be held in memory), then calibrates: each
// camera's intrinsics from every view of it where the board was found (a pair with the board in
// one view only still helps that camera), then stereoCalibrate on the pairs with the board in
// both (intrinsics fixed), leaving out the outliers, then stereoRectify.
class StereoCalibrator {
 public:
  // Throws InputError when options.Check fails.
  explicit StereoCalibrator(StereoCalibrationOptions options);

  // Looks for the board in both images. Throws InputError naming the file when an image is
  // empty or its size differs from the first pair's (both cameras must have one resolution).
  StereoPairStatus add(const std::string& left_name, const cv::Mat& left_image,
                       const std::string& right_name, const cv::Mat& right_image);
  // The same with corners already found (absent: board not found), e.g. from a renderer.
  StereoPairStatus add_corners(const std::string& left_name,
                               std::optional<std::vector<cv::Point2f>> left_corners,
                               const std::string& right_name,
                               std::optional<std::vector<cv::Point2f>> right_corners,
                               const cv::Size& image_size);

  // Throws InputError when fewer than min_views pairs have the board in both views (naming how
  // many pairs were looked at), or fewer remain once the outliers are left out.
  StereoCalibrationResult calibrate() const;

  int pairs_seen() const { return static_cast<int>(pairs_.size()); }

 private:
  struct Pair {
    StereoPairReport report{};
    std::optional<std::vector<cv::Point2f>> left{}, right{};
  };
  StereoCalibrationOptions options_;
  cv::Size image_size_;
  std::vector<Pair> pairs_;
};

// OpenCV FileStorage YAML: both cameras (camera_matrix_left, distortion_left, ..._right), R, T,
// E, F, R1, R2, P1, P2, Q, image size, rms, baseline_mm, the board and each pair's status and
// errors. Load throws InputError naming the file and the missing or bad key.
void SaveStereoCalibration(const StereoCalibrationResult& result, const ChessboardSpec& board,
                           const std::string& file);
StereoCalibration LoadStereoCalibration(const std::string& file);
// The board the rig was calibrated with (board_width, board_height, square_size_mm), absent when
// the file does not store it. Throws InputError naming the file when it stores a bad one.
std::optional<ChessboardSpec> LoadStereoCalibrationBoard(const std::string& file);

// Both images rectified side by side (left | right) with horizontal lines every `spacing_px`:
// on a good calibration each point of the scene lies on the same line in both halves. BGR.
cv::Mat DrawRectifiedPair(const StereoCalibration& stereo, const cv::Mat& left_image,
                          const cv::Mat& right_image, int spacing_px = 32);

}  // namespace softsight
