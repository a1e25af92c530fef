// Two cameras with known intrinsics, distortion and pose looking at an actuator that bends along
// a circular arc in a plane tilted out of the first camera's image plane (and may turn about its
// own axis over time: a twist of the bending plane), with the truth in 3D. Also the rig's
// chessboard pairs, for stereo calibration against a known answer.
//
// Frames: millimetres in the FIRST (left) camera's frame (x right, y down, z forward); the right
// camera sees X_right = R * X_left + T, as OpenCV's stereoCalibrate reports it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/sim/chessboard.h"

namespace softsight {

struct StereoRig {
  CameraModel left{}, right{};
  cv::Matx33d R = cv::Matx33d::eye();  // right_from_left.
  cv::Vec3d T{-100, 0, 0};  // right_from_left (mm); the right camera 100 mm to the right.
};

// Two 640x480 webcams (f 600 px, mild barrel distortion, slightly different lenses), side by
// side `baseline_mm` apart, each turned `toe_in_deg` towards the other so their axes cross
// `convergence_mm` in front of the first (the actuator's distance, where both see it centred).
StereoRig MakeStereoRig(double baseline_mm = 100.0, double convergence_mm = 300.0);

// The pose of a board in the right camera, from its pose in the left camera.
BoardPose RightBoardPose(const StereoRig& rig, const BoardPose& left_pose);

// A point (mm, left camera's frame) to raw (distorted) pixels of each camera.
cv::Point2d ProjectLeft(const StereoRig& rig, const cv::Point3d& point_mm);
cv::Point2d ProjectRight(const StereoRig& rig, const cv::Point3d& point_mm);

struct StereoMarker {
  std::string name{};
  cv::Vec3b bgr{};
  double body_fraction = 0.0;  // 0 = base, 1 = tip.
};

// A marker covered in one view for a stretch of frames (a hand or a tube in front of one camera):
// not drawn in that view; the other view and the truth are unchanged.
struct StereoHiddenMarker {
  std::string name{};   // One of StereoSceneOptions::markers.
  int view = 1;         // 0: the left (first) camera, 1: the right one.
  int first_frame = 0;  // From this frame index on ...
  int frames = 1;       // ... for this many frames (>= 1).
};

struct StereoSceneOptions {
  int frame_count = 30;
  // The base of the actuator (mm, left camera's frame) and its straight direction (unit after
  // normalising; default straight down the image from above the centre).
  cv::Point3d base_mm{0.0, -45.0, 300.0};
  cv::Vec3d straight_direction{0.0, 1.0, 0.0};
  double length_mm = 90.0;
  // Total turning of the centre line, from 0 at frame 0 to max_bend_deg at the last frame
  // (linear in the frame index).
  double max_bend_deg = 90.0;
  // When not empty: the bend of each frame (deg, frame_count values), instead of the linear
  // ramp to max_bend_deg: motion that starts, stops and changes speed (what finding the offset
  // between two cameras' videos correlates), or none at all.
  std::vector<double> bend_deg_per_frame{};
  // The bending plane contains the straight direction; it is turned this much about it out of
  // the image-parallel plane (0: the bend is seen face on, 90: edge on), at frame 0 and at the
  // last frame (linear between: a turning, i.e. twisting, actuator).
  double plane_tilt_start_deg = 30.0;
  double plane_tilt_end_deg = 30.0;
  // Flat discs stuck on the actuator, facing along the bending plane's normal (so each camera
  // sees an ellipse), centred on the centre line.
  double marker_radius_mm = 3.0;
  double body_width_mm = 12.0;
  std::vector<StereoMarker> markers = {
      {"red", {40, 40, 220}, 0.1}, {"blue", {220, 90, 40}, 0.5}, {"green", {60, 200, 60}, 0.9}};
  std::vector<StereoHiddenMarker> hidden{};
  cv::Vec3b body_bgr{200, 200, 205};
  cv::Vec3b background_bgr{105, 110, 115};
  int supersample = 4;       // Sub-samples per pixel side for the markers' edges (1..16).
  double noise_sigma = 0.0;  // Gaussian sensor noise, grey levels.
  // A flash: from frame `flash_frame` on, for `flash_length_frames` frames (0: to the end: a
  // lamp switched on), every pixel of both views is `flash_gray` grey levels brighter
  // (saturating). Absent: no flash.
  std::optional<int> flash_frame{};
  int flash_length_frames = 1;
  double flash_gray = 60.0;
  uint64_t seed = 7;

  // False with a one-line message naming the bad field.
  bool Check(std::string* error) const;
};

struct StereoMarkerTruth {
  std::string name{};
  cv::Point3d position_mm{};          // The disc's centre.
  cv::Point2d left_px{}, right_px{};  // Its projection (raw pixels) in each view.
};

struct StereoSceneTruth {
  int index = 0;
  double bend_deg = 0.0;        // Total turning of the centre line.
  double plane_tilt_deg = 0.0;  // The bending plane vs the left camera's image plane.
  cv::Vec3d plane_normal{};     // Unit normal of the bending plane.
  std::vector<StereoMarkerTruth> markers{};
  // From the true 3D centres (base, middle, tip: the first, middle and last marker).
  double angle_deg = 0.0;             // At the middle marker, in 3D.
  std::optional<double> radius_mm{};  // Of the centre line (absent when straight).
};

class StereoScene {
 public:
  // Throws InputError naming the bad field.
  StereoScene(StereoRig rig, StereoSceneOptions options = {});

  // Renders frame `index` as seen by both cameras (CV_8UC3, buffers reused).
  StereoSceneTruth render(int index, cv::Mat& left, cv::Mat& right) const;
  // The truth alone (no drawing).
  StereoSceneTruth truth(int index) const;
  // The actuator at an explicit bend (the simulated control rig's), clamped to [0, 300] deg;
  // `index` selects the plane's tilt, the hidden markers, the flash and the noise as for frame
  // `index` (past the last frame: as for the last).
  StereoSceneTruth render_at_bend(double bend_deg, int index, cv::Mat& left, cv::Mat& right) const;
  StereoSceneTruth truth_at_bend(double bend_deg, int index) const;

  const StereoRig& rig() const { return rig_; }
  const StereoSceneOptions& options() const { return options_; }

 private:
  void draw(const CameraModel& camera, const cv::Matx33d& rotation, const cv::Vec3d& translation,
            const StereoSceneTruth& truth, int index, int view, cv::Mat& image) const;

  StereoRig rig_;
  StereoSceneOptions options_;
};

}  // namespace softsight
