#include "track/rim_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core/hal/intrin.hpp>

namespace softsight {

int CountRimInliersReference(const std::vector<cv::Point2d>& pts, const cv::Point2d& c, double r,
                             double tol) {
  int n = 0;
  for (const cv::Point2d& p : pts) n += std::abs(cv::norm(p - c) - r) <= tol ? 1 : 0;
  return n;
}

int CountRimInliers(const std::vector<cv::Point2d>& pts, const cv::Point2d& c, double r,
                    double tol, int best) {
  const int n = static_cast<int>(pts.size());
  int count = 0, i = 0;
#if CV_SIMD128_64F
  // Two points at a time, each with the scalar reference's operations in its order (p - c, then
  // x^2 + y^2, sqrt, |d - r| <= tol: IEEE sqrt and no fused multiply-add), so the same
  // comparisons. Every 32 points, stop when the points left cannot take the count past `best`.
  static_assert(sizeof(cv::Point2d) == 2 * sizeof(double));
  const double* xy = reinterpret_cast<const double*>(pts.data());
  const cv::v_float64x2 cx = cv::v_setall_f64(c.x), cy = cv::v_setall_f64(c.y);
  const cv::v_float64x2 vr = cv::v_setall_f64(r), vtol = cv::v_setall_f64(tol);
  const int pairs_end = n & ~1;
  while (i < pairs_end) {
    const int block_end = std::min(pairs_end, i + 32);
    // An inlier's comparison is all ones, -1 as an integer lane: subtracted, it counts.
    cv::v_int64x2 inliers = cv::v_setzero_s64();
    for (; i < block_end; i += 2) {
      cv::v_float64x2 px, py;
      cv::v_load_deinterleave(xy + 2 * i, px, py);
      const cv::v_float64x2 dx = px - cx, dy = py - cy;
      const cv::v_float64x2 d = cv::v_sqrt(dx * dx + dy * dy);
      inliers -= cv::v_reinterpret_as_s64(cv::v_abs(d - vr) <= vtol);
    }
    count += static_cast<int>(cv::v_reduce_sum(inliers));
    if (count + (n - i) <= best) return count;
  }
#endif
  for (; i < n; ++i) count += std::abs(cv::norm(pts[i] - c) - r) <= tol ? 1 : 0;
  return count;
}

std::optional<RimFit> FitRimOfRadius(const std::vector<cv::Point2d>& edge_px, double radius_px,
                                     double inlier_px, std::vector<double>* scratch) {
  const size_t n = edge_px.size();
  if (n < 6 || !(radius_px > 0)) return std::nullopt;
  // Candidate centres: the two circles of the radius through pairs of points about a quarter of
  // the boundary apart (pairs too close give unstable centres). At most ~64 pairs.
  const size_t step = std::max<size_t>(1, n / 64);
  const size_t offset = std::max<size_t>(1, n / 4);
  cv::Point2d best_centre;
  int best_inliers = 0;
  for (size_t i = 0; i < n; i += step) {
    const cv::Point2d a = edge_px[i], b = edge_px[(i + offset) % n];
    const cv::Point2d mid = 0.5 * (a + b), ab = b - a;
    const double half = 0.5 * cv::norm(ab);
    if (half < 1.0 || half > radius_px) continue;
    const double h = std::sqrt(radius_px * radius_px - half * half);
    const cv::Point2d normal(-ab.y / (2 * half), ab.x / (2 * half));
    for (const double sign : {1.0, -1.0}) {
      const cv::Point2d c = mid + sign * h * normal;
      const int inliers = CountRimInliers(edge_px, c, radius_px, inlier_px, best_inliers);
      if (inliers > best_inliers) {
        best_inliers = inliers;
        best_centre = c;
      }
    }
  }
  if (best_inliers < 6) return std::nullopt;
  // Gauss-Newton on the rim points: minimise sum (|p - c| - r)^2 over c, re-selecting the rim.
  cv::Point2d c = best_centre;
  for (int iteration = 0; iteration < 10; ++iteration) {
    cv::Matx22d jtj = cv::Matx22d::zeros();
    cv::Vec2d jtr(0, 0);
    int used = 0;
    for (const cv::Point2d& p : edge_px) {
      const cv::Point2d d = c - p;
      const double dist = cv::norm(d);
      if (dist < 1e-9 || std::abs(dist - radius_px) > inlier_px) continue;
      const cv::Vec2d j(d.x / dist, d.y / dist);  // d(dist)/dc
      const double residual = dist - radius_px;
      jtj += j * j.t();
      jtr += j * residual;
      ++used;
    }
    if (used < 6) break;
    const double det = jtj(0, 0) * jtj(1, 1) - jtj(0, 1) * jtj(1, 0);
    if (!(std::abs(det) > 1e-12)) break;
    const cv::Vec2d delta(-(jtj(1, 1) * jtr[0] - jtj(0, 1) * jtr[1]) / det,
                          -(-jtj(1, 0) * jtr[0] + jtj(0, 0) * jtr[1]) / det);
    c += cv::Point2d(delta[0], delta[1]);
    if (std::hypot(delta[0], delta[1]) < 1e-4) break;
  }
  RimFit fit;
  fit.centre_px = c;
  std::vector<double> own_angles;
  std::vector<double>& angles = scratch ? *scratch : own_angles;
  angles.clear();
  double sum2 = 0;
  for (const cv::Point2d& p : edge_px) {
    const double residual = cv::norm(p - c) - radius_px;
    if (std::abs(residual) > inlier_px) continue;
    sum2 += residual * residual;
    angles.push_back(std::atan2(p.y - c.y, p.x - c.x));
  }
  fit.rim_points = static_cast<int>(angles.size());
  if (fit.rim_points < 6) return std::nullopt;
  fit.rms_px = std::sqrt(sum2 / fit.rim_points);
  std::sort(angles.begin(), angles.end());
  double largest_gap = angles.front() + 2 * CV_PI - angles.back();
  for (size_t k = 1; k < angles.size(); ++k) largest_gap = std::max(largest_gap, angles[k] - angles[k - 1]);
  fit.arc_deg = (2 * CV_PI - largest_gap) * 180.0 / CV_PI;
  return fit;
}

std::optional<double> OffRimBulgePx(const std::vector<cv::Point2d>& edge_px, const RimFit& fit,
                                    double radius_px, double inlier_px,
                                    std::vector<std::pair<double, cv::Point2d>>* scratch) {
  // The off-circle points by their angle around the centre.
  scratch->clear();
  for (const cv::Point2d& p : edge_px) {
    const cv::Point2d d = p - fit.centre_px;
    // Inside the circle: what a cut (or a slant) left of the disc. A stray pixel outside it is
    // neither.
    if (cv::norm(d) >= radius_px - inlier_px) continue;
    scratch->emplace_back(std::atan2(d.y, d.x), p);
  }
  if (scratch->size() < 3) return std::nullopt;
  std::sort(scratch->begin(), scratch->end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  // They span one arc of angles: its ends are either side of the largest gap between neighbours
  // (the gap that holds the rim on the circle).
  size_t last = scratch->size() - 1, first = 0;
  double gap = (*scratch)[0].first + 2 * CV_PI - (*scratch)[last].first;
  for (size_t k = 1; k < scratch->size(); ++k) {
    const double g = (*scratch)[k].first - (*scratch)[k - 1].first;
    if (g > gap) {
      gap = g;
      first = k;
      last = k - 1;
    }
  }
  const cv::Point2d a = (*scratch)[first].second, b = (*scratch)[last].second;
  const cv::Point2d ab = b - a;
  const double len = cv::norm(ab);
  if (len < 1.0) return std::nullopt;
  // The outward normal of the chord: towards the middle of the arc the points span (away from
  // the centre; the chord may pass through the centre itself).
  const double mid = (*scratch)[first].first + (2 * CV_PI - gap) / 2;
  cv::Point2d n(ab.y / len, -ab.x / len);
  if (n.dot(cv::Point2d(std::cos(mid), std::sin(mid))) < 0) n = -n;
  double bulge = -std::numeric_limits<double>::infinity();
  for (const auto& [angle, p] : *scratch) bulge = std::max(bulge, n.dot(p - a));
  return bulge;
}

}  // namespace softsight
