// `softsight calibrate`: camera intrinsics and distortion from chessboard views, the homography
// from image pixels to millimetres in the actuator's plane, or a stereo rig (two cameras) from
// pairs of chessboard views.
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
  // Stereo mode: the two cameras' views of the board at the same moments, each a folder, a
  // numbered pattern or a video; paired one to one in order (file order, or frame index).
  std::optional<std::string> left, right;
  // Stereo mode: a picture of the first used pair, rectified side by side with horizontal lines
  // (a point of the scene must lie on one line in both halves).
  std::optional<std::string> picture_file;
  std::string chessboard;           // Inner corners, "9x6".
  double square_mm = 0.0;           // Side of one printed square in mm.
  std::string out_file;             // camera.yaml, plane.yaml or stereo.yaml (OpenCV YAML).
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
  int pairs = 0;                        // Stereo mode: pairs looked at ...
  int pairs_used = 0;                   // ... and used.
  std::vector<std::string> left_out;    // Stereo mode: "left03.jpg + right03.jpg: outlier".
  double baseline_mm = 0.0;             // Stereo mode.
};

// Does the work and prints the report to `report`. Throws InputError for bad input (missing
// folder, unreadable image, bad --chessboard, board found nowhere).
CalibrateSummary RunCalibrate(const CalibrateOptions& options, std::ostream& report);

}  // namespace softsight
