// A frame of reference on the bench: the calibration chessboard laid once where the actuator
// works, seen by both cameras of a calibrated rig (stereo_calibration.h). Its corners are
// triangulated (triangulation.h) and the ideal grid is fitted to them by a least-squares rigid
// motion (Kabsch: rotation and translation, no scale), so the fit's residual also tells a wrong
// square size, a bent board or another rig's calibration.
//
// The board's frame: origin at its first inner corner, X along its first row (the `width`
// corners), Y along its columns, Z = X x Y. OpenCV's corner order runs clockwise as the camera
// sees it, so Z points from the board away from the cameras (into the bench): a point above the
// board has a negative Z. The detector may start the grid at either end (a 180 degree turn);
// the origin is the end whose corner square is dark (a board with an odd x odd count of squares
// has dark squares at both ends of each diagonal; then the end nearer the first view's top-left
// corner), so laying the board again the same way gives the same frame.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/calib/camera_calibration.h"
#include "softsight/calib/triangulation.h"

namespace softsight {

struct BoardFrame {
  // camera_from_board: its columns are the board's X, Y, Z axes in the first camera's frame.
  cv::Matx33d rotation = cv::Matx33d::eye();
  cv::Vec3d origin_mm{};  // The board's first inner corner in the first camera's frame.
  // The fit: RMS and largest distance of the triangulated corners from the fitted grid, and
  // how many corners it used.
  double rms_mm = 0.0, max_mm = 0.0;
  int corners = 0;

  // A point (mm, first camera's frame) in the board's frame.
  cv::Point3d to_board(const cv::Point3d& camera_mm) const;
  // A direction (first camera's frame) in the board's frame.
  cv::Vec3d direction_to_board(const cv::Vec3d& camera) const;
  // A covariance (first camera's frame) in the board's frame.
  cv::Matx33d covariance_to_board(const cv::Matx33d& camera) const;
};

// Fits the ideal grid of `board` (corner (row r, column c) at (c, r, 0) x square_mm) to the
// measured corners (first camera's frame, row by row as the detector reports them; absent ones
// are left out). Throws InputError when `corners_mm` is not one entry per corner or fewer than
// 3 corners off one line remain.
BoardFrame FitBoardFrame(const std::vector<std::optional<cv::Point3d>>& corners_mm,
                         const ChessboardSpec& board);

struct BenchBoardOptions {
  // A fit worse than this (RMS, mm) is refused: the corners of a flat board of the given size
  // fit to 0.1-0.2 mm at 300 mm on a good rig (the renderer's); millimetres mean a wrong
  // --square-mm or --chessboard, a bent board or a calibration of another rig.
  double max_rms_mm = 2.0;
  // At least this fraction of the corners must triangulate (pass the epipolar check).
  double min_corner_fraction = 0.5;
};

// Finds `board` in both images (FindChessboard), puts the right view's corners in the left
// view's order and the origin at the dark corner (see above), triangulates each corner and fits
// the frame. Throws InputError naming the file when an image is empty or not the calibrated
// size, the board is not found in it, too few corners pass the epipolar check, or the fit's
// residual is above options.max_rms_mm.
BoardFrame LocateBenchBoard(const Triangulator& triangulator, const ChessboardSpec& board,
                            const std::string& left_name, const cv::Mat& left_image,
                            const std::string& right_name, const cv::Mat& right_image,
                            const BenchBoardOptions& options = {});

}  // namespace softsight
