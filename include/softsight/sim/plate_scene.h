// A hand-held plate with N dots seen in perspective: it moves across the frame, tilts about an
// axis in its plane and approaches the camera, so the dots become foreshortened ellipses that
// grow. White dots on a dark plate on a gray camera by default, the commonest markers after
// coloured ones. Rendered anti-aliased with the exact truth, like SyntheticScene.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/sim/scene.h"

namespace softsight {

struct PlateSceneOptions {
  cv::Size size{640, 480};
  int frame_count = 120;
  double fps = 30.0;
  // Dots in a zig-zag (never all on one line from 3 dots on), named "dot0".."dot<N-1>" from one
  // end of the zig-zag to the other; 1..16.
  int dot_count = 5;
  // Dot radius in pixels at scale 1 with the plate facing the camera.
  double dot_radius_px = 8.0;
  cv::Vec3b plate_bgr{40, 40, 40};
  cv::Vec3b dot_bgr{235, 235, 235};  // Black dots on a light plate: swap the two colours.
  bool gray = true;                  // B = G = R output (luma), like a mono camera.
  // Largest tilt of the plate out of the image plane (degrees, in [0, 75]); the tilt rises and
  // falls smoothly and its axis (in the plate's plane) turns over the sequence.
  double max_tilt_deg = 50.0;
  // Apparent size, 1 = the nominal dot radius when facing the camera, growing linearly from
  // scale_start to scale_end (the plate approaches the camera).
  double scale_start = 1.0, scale_end = 2.0;
  // The wood-like bench (BackgroundKind::kBench) behind the plate; false: a plain gray gradient.
  bool cluttered_background = true;
  // Blobs drawn on the backdrop (the plate passes over them), e.g. light spots that look like
  // dots; in output pixels as for SceneOptions::distractors.
  std::vector<Distractor> distractors{};
  uint64_t seed = 1;  // Background and motion path.

  // False with a one-line message naming the bad field.
  bool Check(std::string* error) const;
};

class PlateScene {
 public:
  // Throws InputError naming the option when options are unusable.
  explicit PlateScene(PlateSceneOptions options, NoiseOptions noise = {}, RenderOptions render = {});
  ~PlateScene();
  PlateScene(PlateScene&&) noexcept;
  PlateScene& operator=(PlateScene&&) noexcept;

  const PlateSceneOptions& options() const;
  int frame_count() const;

  // The plate's pose at frame `index`: plate coordinates (pixels at scale 1, origin at the
  // plate's centre) to output image pixels (pixel-centre convention).
  cv::Matx33d image_from_plate(int index) const;
  // The dots' centres in plate coordinates, in name order.
  const std::vector<cv::Point2d>& dot_centres() const;

  // Renders frame `index` into `image` (CV_8UC3, buffer reused). Markers are the dots in name
  // order; centroid_px is the centroid of the dot's rendered visible area (in perspective that is
  // not the image of the dot's centre), visible_fraction the part inside the image. bend_deg is
  // 0, there is no centre-line radius and no measurement.
  SceneTruth render(int index, cv::Mat& image);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace softsight
