#include "pipeline/motion_model.h"

#include <algorithm>
#include <cmath>

namespace softsight {
namespace {

// Exponent of the acceleration's adaptation per report: the normalised innovation (its squared
// Mahalanobis distance over its 2 degrees of freedom) is 1 on average when the noise is right;
// the noise follows its ratio slowly, so one outlier does not open the gate.
constexpr double kAdaptRate = 0.25;
// A single innovation moves the learned noise by at most this factor.
constexpr double kMaxAdaptStep = 2.0;

}  // namespace

void MotionModel::start(const cv::Point2d& position_px) {
  started_ = true;
  updates_ = 0;
  x_ = cv::Vec4d(position_px.x, position_px.y, 0.0, 0.0);
  const double r = options_.measurement_sigma_px * options_.measurement_sigma_px;
  const double v = options_.initial_speed_sigma_px * options_.initial_speed_sigma_px;
  p_ = cv::Matx44d::zeros();
  p_(0, 0) = p_(1, 1) = r;
  p_(2, 2) = p_(3, 3) = v;
}

void MotionModel::predict() {
  if (!started_) return;
  const cv::Matx44d f(1, 0, 1, 0,  //
                      0, 1, 0, 1,  //
                      0, 0, 1, 0,  //
                      0, 0, 0, 1);
  // Discrete white-noise acceleration: an acceleration constant over the frame.
  const double q = accel_sigma_ * accel_sigma_;
  const cv::Matx44d noise(0.25 * q, 0, 0.5 * q, 0,  //
                          0, 0.25 * q, 0, 0.5 * q,  //
                          0.5 * q, 0, q, 0,         //
                          0, 0.5 * q, 0, q);
  x_ = f * x_;
  p_ = f * p_ * f.t() + noise;
}

cv::Matx22d MotionModel::innovation_covariance() const {
  const double r = options_.measurement_sigma_px * options_.measurement_sigma_px;
  return cv::Matx22d(p_(0, 0) + r, p_(0, 1), p_(1, 0), p_(1, 1) + r);
}

double MotionModel::distance2(const cv::Point2d& position_px) const {
  const cv::Matx22d s = innovation_covariance();
  const cv::Vec2d d(position_px.x - x_(0), position_px.y - x_(1));
  const double det = s(0, 0) * s(1, 1) - s(0, 1) * s(1, 0);
  if (!(det > 0)) return 0.0;
  const cv::Matx22d inv(s(1, 1) / det, -s(0, 1) / det, -s(1, 0) / det, s(0, 0) / det);
  return d.dot(inv * d);
}

double MotionModel::sigma_px() const {
  const cv::Matx22d s = innovation_covariance();
  const double mean = 0.5 * (s(0, 0) + s(1, 1));
  const double diff = 0.5 * (s(0, 0) - s(1, 1));
  return std::sqrt(mean + std::sqrt(diff * diff + s(0, 1) * s(1, 0)));
}

void MotionModel::update(const cv::Point2d& position_px, bool learn) {
  if (!started_) {
    start(position_px);
    return;
  }
  const cv::Matx22d s = innovation_covariance();
  const double det = s(0, 0) * s(1, 1) - s(0, 1) * s(1, 0);
  if (!(det > 0)) return;
  const cv::Matx22d s_inv(s(1, 1) / det, -s(0, 1) / det, -s(1, 0) / det, s(0, 0) / det);
  const cv::Vec2d y(position_px.x - x_(0), position_px.y - x_(1));
  // The first two reports fix position and velocity; the acceleration is learned after them.
  if (learn && updates_ >= 2) {
    const double nis = y.dot(s_inv * y) / 2.0;
    const double step = std::clamp(std::pow(std::max(nis, 1e-6), kAdaptRate), 1.0 / kMaxAdaptStep,
                                   kMaxAdaptStep);
    accel_sigma_ = std::clamp(accel_sigma_ * std::sqrt(step), options_.min_accel_sigma_px,
                              options_.max_accel_sigma_px);
  }
  // K = P H' S^-1 with H = [I 0].
  cv::Matx<double, 4, 2> ph;
  for (int r = 0; r < 4; ++r) {
    ph(r, 0) = p_(r, 0);
    ph(r, 1) = p_(r, 1);
  }
  const cv::Matx<double, 4, 2> k = ph * s_inv;
  x_ += k * y;
  cv::Matx44d kh = cv::Matx44d::zeros();
  for (int r = 0; r < 4; ++r) {
    kh(r, 0) = k(r, 0);
    kh(r, 1) = k(r, 1);
  }
  p_ = (cv::Matx44d::eye() - kh) * p_;
  p_ = 0.5 * (p_ + p_.t());
  ++updates_;
}

}  // namespace softsight
