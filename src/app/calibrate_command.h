// `softsight calibrate`: camera intrinsics and distortion from chessboard views, or the
// homography from image pixels to millimetres in the actuator's plane.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace softsight {

struct CalibrateOptions {
  // Camera mode: chessboard views as a folder of images, a printf pattern (shots/%03d.png) or a
  // video file.
  std::optional<std::string> input;
  // Plane mode: one image of a chessboard lying in the actuator's plane.
  std::optional<std::string> plane_image;
  // Plane mode: the camera file from camera mode, to undistort the board's corners (without it
  // the lens is assumed distortion-free).
  std::optional<std::string> camera_file;
  std::string chessboard;           // Inner corners, "9x6".
  double square_mm = 0.0;           // Side of one printed square in mm.
  std::string out_file;             // camera.yaml or plane.yaml (OpenCV FileStorage YAML).
  int step = 1;                     // Video input: use every step-th frame (neighbours repeat).
  bool estimate_k3 = false;         // Also fit k3 (wide-angle lenses).
};

struct CalibrateSummary {
  int images = 0;                       // Images (or video frames) looked at.
  std::vector<std::string> not_found;   // Where the board was not found.
  double rms_px = 0.0;                  // Camera mode: reprojection RMS.
  double fx_px = 0.0, fy_px = 0.0;      // Camera mode: focal lengths.
  double mm_per_px = 0.0;               // Plane mode: scale at the board's centre.
  double rms_mm = 0.0;                  // Plane mode: homography residual on the corners.
};

// Does the work and prints the report to `report`. Throws InputError for bad input (missing
// folder, unreadable image, bad --chessboard, board found nowhere).
CalibrateSummary RunCalibrate(const CalibrateOptions& options, std::ostream& report);

}  // namespace softsight
