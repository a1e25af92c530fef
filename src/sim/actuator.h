// The actuator's shape at a given bend: plain geometry in output-pixel coordinates (pixel-centre
// convention), no pixels. The renderer fills these polygons and discs; the truth comes from them.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/sim/scene.h"

namespace softsight::sim {

// A filled polygon drawn over what is below it with opacity `alpha` (1 = opaque).
struct ShapePolygon {
  std::vector<cv::Point2d> outline;
  cv::Vec3b bgr;
  double alpha = 1.0;
};

struct ActuatorPose {
  double bend_deg = 0.0;
  std::vector<ShapePolygon> shapes;         // In drawing order; markers go on top of all of them.
  std::vector<cv::Point2d> marker_centres;  // Same order as SceneOptions::markers.
  std::optional<double> centreline_radius_px;
  cv::Rect2d bounds;                        // Of every shape and marker disc.
};

// Places the actuator so that it stays inside the image over its whole range of motion, then
// gives its pose at any bend in that range.
class ActuatorModel {
 public:
  // Throws InputError when the actuator cannot fit in the image.
  explicit ActuatorModel(const SceneOptions& options);

  double max_bend_deg() const { return max_bend_deg_; }
  // `pose` keeps its vectors' capacity between calls. `bend_deg` must lie in [0, max_bend_deg].
  void pose(double bend_deg, ActuatorPose* pose) const;

 private:
  // The pose with the base at `base` (the centre of the body's base end).
  void pose_at(double bend_deg, const cv::Point2d& base, ActuatorPose* pose) const;
  void bending_pose(double bend_rad, const cv::Point2d& base, ActuatorPose* pose) const;
  void wedge_pose(double bend_rad, const cv::Point2d& base, ActuatorPose* pose) const;

  SceneOptions options_;
  double max_bend_deg_ = 0.0;
  int segments_ = 0;  // Wedge chambers (0 for the bending actuator).
  cv::Point2d base_;
};

// The design opening of the wedge scenes, in degrees (0 for kBending: it uses max_bend_deg).
double WedgeOpeningDeg(SceneKind kind);
// Wedge scenes: the closed chamber's thickness and the plates' length along the centre line
// (plates and chambers add up to length_px).
double ChamberGapPx(const SceneOptions& options);
double PlateLengthPx(const SceneOptions& options);

}  // namespace softsight::sim
