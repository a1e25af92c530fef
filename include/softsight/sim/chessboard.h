// Chessboard images seen by a camera with KNOWN intrinsics and lens distortion, for testing
// camera calibration and metric scale against exact truth.
//
// Each output pixel is supersampled: every sub-sample position is undistorted to normalised
// camera coordinates, its ray is intersected with the board plane, and the pattern is sampled
// there; the pixel is the mean of its sub-samples. So the image is exactly what the lens model
// (OpenCV's, the one calibrateCamera estimates) would produce, anti-aliased.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

// The printed board. Board coordinates (mm): inner corner (row r, column c) sits at
// (c * square_mm, r * square_mm, 0), the order OpenCV's findChessboardCorners reports.
struct ChessboardPattern {
  cv::Size inner_corners{9, 6};  // Inner corners per row (width) and per column (height).
  double square_mm = 25.0;
  double margin_mm = 25.0;       // White paper border around the squares (detection needs it).
};

// A pinhole camera with OpenCV's distortion model (k1, k2, p1, p2[, k3]).
struct CameraModel {
  cv::Size image_size{640, 480};
  cv::Matx33d camera_matrix = cv::Matx33d(600, 0, 320, 0, 600, 240, 0, 0, 1);
  std::vector<double> distortion{};  // Empty: no distortion.
};

struct ChessboardLook {
  uint8_t black = 25;           // Grey level of the dark squares.
  uint8_t white = 230;          // Grey level of the light squares and the border.
  uint8_t background = 110;     // Everything off the paper.
  // s: s * s sub-samples per pixel in an n-rooks pattern, so an edge's coverage is exact to
  // 1 / s^2 of a pixel in any direction (default 3; 1: aliased; cost grows with s^2).
  int supersample = 3;
  double noise_sigma = 0.0;     // Gaussian sensor noise in grey levels.
  uint64_t seed = 1;
};

// Where the board is: board-to-camera rotation (Rodrigues vector) and translation (mm).
struct BoardPose {
  cv::Vec3d rvec{};
  cv::Vec3d tvec{0, 0, 500};
};

// The truth for one rendered view.
struct ChessboardView {
  std::vector<cv::Point2f> corners_px{};  // Inner corners as the camera sees them (distorted).
  bool all_corners_inside = false;        // Every inner corner projects into the image.
};

// Precomputes each sub-sample's ray once per camera, then renders any number of poses.
class ChessboardRenderer {
 public:
  // Throws InputError when the camera or look is unusable (empty size, supersample < 1).
  ChessboardRenderer(CameraModel camera, ChessboardPattern pattern, ChessboardLook look = {});

  // Renders into `image` (CV_8UC1, buffer reused) and returns the truth.
  ChessboardView render(const BoardPose& pose, cv::Mat& image) const;

  // Board point (mm, z = 0) to distorted image pixel.
  cv::Point2d project(const BoardPose& pose, const cv::Point2d& board_mm) const;

  const CameraModel& camera() const { return camera_; }
  const ChessboardPattern& pattern() const { return pattern_; }

 private:
  CameraModel camera_;
  ChessboardPattern pattern_;
  ChessboardLook look_;
  cv::Mat rays_;  // CV_64FC2, (rows * supersample) x (cols * supersample): normalised x, y.
};

// A pose that looks at the board's centre from `distance_mm`, tilted by `tilt_x_deg` about the
// board's x axis and `tilt_y_deg` about its y axis, rotated `roll_deg` in its plane, with the
// board centre offset by (`shift_x_mm`, `shift_y_mm`) from the optical axis.
BoardPose LookAtBoard(const ChessboardPattern& pattern, double distance_mm, double tilt_x_deg,
                      double tilt_y_deg, double roll_deg, double shift_x_mm = 0.0,
                      double shift_y_mm = 0.0);

}  // namespace softsight
