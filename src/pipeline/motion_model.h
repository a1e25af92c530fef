// A marker's motion: a constant-velocity Kalman filter on its image position, whose process
// noise (the marker's acceleration) is learned from the footage. Its prediction and covariance
// say where the marker can be in the next frame, and how far from there a report may lie before
// no motion explains it (the gate). A marker not seen for frames keeps being predicted, its
// uncertainty growing with the time since it was last seen, so the reach of a re-acquisition is
// what a plausible motion since the loss could have covered.
#pragma once

#include <opencv2/core.hpp>

namespace softsight {

struct MotionModelOptions {
  // Measurement noise of a report (px, 1 sigma): trackers are sub-pixel, but shape changes,
  // blur and partial views move a centroid by a few tenths.
  double measurement_sigma_px = 0.7;
  // Velocity uncertainty of a new track (px per frame, 1 sigma): its first step may be fast.
  double initial_speed_sigma_px = 40.0;
  // The learned acceleration (px per frame^2, 1 sigma) stays within these: never so small that
  // a marker starting to move is a jump, never so large that the gate is the whole frame.
  double min_accel_sigma_px = 1.0;
  double max_accel_sigma_px = 40.0;
  double initial_accel_sigma_px = 3.0;
};

class MotionModel {
 public:
  explicit MotionModel(MotionModelOptions options = {})
      : options_(options), accel_sigma_(options.initial_accel_sigma_px) {}

  // Starts a track at `position_px` with an unknown velocity (what was learned of the
  // acceleration is kept).
  void start(const cv::Point2d& position_px);
  bool started() const { return started_; }
  void clear() { started_ = false; }

  // Advances the state by one frame (called once per frame, before gate/update).
  void predict();
  // The picture moved by `shift_px` (the camera): the position moves with it, nothing else.
  void shift(const cv::Point2d& shift_px) {
    x_(0) += shift_px.x;
    x_(1) += shift_px.y;
  }
  // Folds a report of this frame in; `learn` adapts the acceleration to the innovation.
  void update(const cv::Point2d& position_px, bool learn = true);

  cv::Point2d position() const { return {x_(0), x_(1)}; }
  cv::Point2d velocity() const { return {x_(2), x_(3)}; }
  // Squared Mahalanobis distance of `position_px` from the prediction (2 degrees of freedom).
  double distance2(const cv::Point2d& position_px) const;
  // The 1-sigma position uncertainty of the prediction, its largest axis (px).
  double sigma_px() const;
  int updates() const { return updates_; }  // Reports folded in since start().

 private:
  cv::Matx22d innovation_covariance() const;
  MotionModelOptions options_;
  bool started_ = false;
  int updates_ = 0;
  cv::Vec4d x_;    // x, y, vx, vy.
  cv::Matx44d p_;  // Covariance.
  double accel_sigma_ = 3.0;
};

}  // namespace softsight
