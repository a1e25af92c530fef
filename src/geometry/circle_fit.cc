#include "softsight/geometry/circle_fit.h"

#include <cmath>
#include <numbers>

namespace softsight {
namespace {


cv::Point2d Mean(const std::vector<cv::Point2d>& points) {
  cv::Point2d mean(0.0, 0.0);
  for (const cv::Point2d& p : points) mean += p;
  return mean * (1.0 / static_cast<double>(points.size()));
}

// Eigenvalues (largest, smallest) of the points' 2x2 scatter matrix about their mean.
std::pair<double, double> PrincipalSpreads(const std::vector<cv::Point2d>& points) {
  const cv::Point2d mean = Mean(points);
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (const cv::Point2d& p : points) {
    const cv::Point2d d = p - mean;
    sxx += d.x * d.x;
    sxy += d.x * d.y;
    syy += d.y * d.y;
  }
  const double half_trace = 0.5 * (sxx + syy);
  const double root = std::hypot(0.5 * (sxx - syy), sxy);
  return {half_trace + root, std::max(0.0, half_trace - root)};
}

}  // namespace

bool PointsAreDegenerate(const std::vector<cv::Point2d>& points) {
  for (const cv::Point2d& p : points) {
    if (p != points.front()) return false;
  }
  return true;
}

bool PointsAreCollinear(const std::vector<cv::Point2d>& points) {
  if (PointsAreDegenerate(points)) return false;
  const auto [largest, smallest] = PrincipalSpreads(points);
  // Compare spreads as lengths (square roots of the scatter eigenvalues).
  return std::sqrt(smallest) <= kCollinearRelTol * std::sqrt(largest);
}

std::optional<CircleFit> FitCircleTaubin(const std::vector<cv::Point2d>& points) {
  if (points.size() < 3 || PointsAreDegenerate(points) || PointsAreCollinear(points)) {
    return std::nullopt;
  }
  // Moments of the centred data (centring keeps the normal equations well conditioned).
  const cv::Point2d mean = Mean(points);
  double mxx = 0, myy = 0, mxy = 0, mxz = 0, myz = 0, mzz = 0;
  for (const cv::Point2d& p : points) {
    const double x = p.x - mean.x;
    const double y = p.y - mean.y;
    const double z = x * x + y * y;
    mxx += x * x;
    myy += y * y;
    mxy += x * y;
    mxz += x * z;
    myz += y * z;
    mzz += z * z;
  }
  const double n = static_cast<double>(points.size());
  mxx /= n, myy /= n, mxy /= n, mxz /= n, myz /= n, mzz /= n;

  // Taubin's constraint turns the fit into the smallest root of a cubic, found by Newton's
  // method from 0 (Chernov, "Circular and linear regression", 2010, CircleFitByTaubin).
  const double mz = mxx + myy;
  const double cov_xy = mxx * myy - mxy * mxy;
  const double var_z = mzz - mz * mz;
  const double a3 = 4.0 * mz;
  const double a2 = -3.0 * mz * mz - mzz;
  const double a1 = var_z * mz + 4.0 * cov_xy * mz - mxz * mxz - myz * myz;
  const double a0 = mxz * (mxz * myy - myz * mxy) + myz * (myz * mxx - mxz * mxy) - var_z * cov_xy;
  const double a22 = a2 + a2;
  const double a33 = a3 + a3 + a3;
  double x = 0.0;
  double y = a0;
  for (int iter = 0; iter < 99; ++iter) {
    const double dy = a1 + x * (a22 + a33 * x);
    const double x_new = x - y / dy;
    if (x_new == x || !std::isfinite(x_new)) break;
    const double y_new = a0 + x_new * (a1 + x_new * (a2 + x_new * a3));
    if (std::abs(y_new) >= std::abs(y)) break;
    x = x_new;
    y = y_new;
  }
  const double det = x * x - x * mz + cov_xy;
  if (det == 0.0 || !std::isfinite(det)) return std::nullopt;
  const double cx = (mxz * (myy - x) - myz * mxy) / det / 2.0;
  const double cy = (myz * (mxx - x) - mxz * mxy) / det / 2.0;
  const double radius = std::sqrt(cx * cx + cy * cy + mz);
  if (!std::isfinite(cx) || !std::isfinite(cy) || !std::isfinite(radius)) return std::nullopt;

  CircleFit fit;
  fit.centre = cv::Point2d(cx + mean.x, cy + mean.y);
  fit.radius = radius;
  double sum_sq = 0.0;
  for (const cv::Point2d& p : points) {
    const double r = std::hypot(p.x - fit.centre.x, p.y - fit.centre.y) - radius;
    sum_sq += r * r;
  }
  fit.rms_residual = std::sqrt(sum_sq / n);
  return fit;
}

std::optional<double> ArcLengthThroughPoints(const CircleFit& circle,
                                             const std::vector<cv::Point2d>& points) {
  if (points.size() < 2 || !(circle.radius > 0.0)) return std::nullopt;
  double total = 0.0;
  double previous = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const cv::Point2d d = points[i] - circle.centre;
    if (d.x == 0.0 && d.y == 0.0) return std::nullopt;
    const double angle = std::atan2(d.y, d.x);
    if (i > 0) {
      // Signed step in (-pi, pi]: the shorter way round between neighbours.
      double step = angle - previous;
      if (step > std::numbers::pi) step -= 2.0 * std::numbers::pi;
      if (step <= -std::numbers::pi) step += 2.0 * std::numbers::pi;
      total += step;
    }
    previous = angle;
  }
  return std::abs(total) * circle.radius;
}

}  // namespace softsight
