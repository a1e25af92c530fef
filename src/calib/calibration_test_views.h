// Test support (tests only): a camera with known intrinsics and distortion, and a set of
// chessboard views that calibrate it well (tilted both ways, rolled, reaching the image
// corners where distortion is strongest). Shared by the calibration and calibrate-command tests.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/calib/camera_calibration.h"
#include "softsight/sim/chessboard.h"

namespace softsight::testviews {

// A webcam-like lens at a moderate size, so rendering and detection take little time.
inline CameraModel Camera() {
  CameraModel camera;
  camera.image_size = cv::Size(512, 384);
  camera.camera_matrix = cv::Matx33d(520, 0, 262, 0, 515, 185, 0, 0, 1);
  camera.distortion = {-0.25, 0.08, 0.001, -0.0005, 0.0};
  return camera;
}

inline ChessboardPattern Pattern() {
  ChessboardPattern pattern;
  pattern.inner_corners = cv::Size(9, 6);
  pattern.square_mm = 25.0;
  pattern.margin_mm = 20.0;
  return pattern;
}

inline ChessboardSpec Spec() {
  ChessboardSpec spec;
  spec.inner_corners = Pattern().inner_corners;
  spec.square_mm = Pattern().square_mm;
  return spec;
}

struct View {
  std::string name;
  BoardPose pose;
  cv::Mat image;
  ChessboardView truth;
};

// Twelve views: distance, tilt about x, tilt about y, roll, shift x, shift y.
inline std::vector<View> RenderViews(const ChessboardRenderer& renderer, int count = 12) {
  const double poses[][6] = {
      {600, 0, 0, 0, 0, 0},        {550, 25, 0, 5, -40, 20},   {550, -25, 0, -5, 40, -20},
      {550, 0, 25, 10, 30, 30},    {550, 0, -25, -10, -30, -30}, {600, 20, 20, 15, -60, -40},
      {600, -20, 20, -15, 60, 40}, {600, 20, -20, 3, 60, -40}, {600, -20, -20, -3, -60, 40},
      {650, 30, 10, 0, 0, 60},     {650, -10, -30, 20, 0, -60}, {650, 10, 30, -20, 80, 0},
  };
  std::vector<View> views;
  for (int i = 0; i < count && i < 12; ++i) {
    const double* p = poses[i];
    View view;
    view.name = "view" + std::to_string(i) + ".png";
    view.pose = LookAtBoard(renderer.pattern(), p[0], p[1], p[2], p[3], p[4], p[5]);
    view.truth = renderer.render(view.pose, view.image);
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace softsight::testviews
