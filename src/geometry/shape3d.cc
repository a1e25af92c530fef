#include "softsight/geometry/shape3d.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "softsight/geometry/circle_fit.h"
#include "softsight/geometry/triangle.h"

namespace softsight {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
// Points whose second principal spread is below this fraction of the first lie on a line (a
// 100 mm chain bowing by less than 0.1 um).
constexpr double kPlaneRelTol = 1e-6;

cv::Vec3d Vec(const cv::Point3d& p) { return cv::Vec3d(p.x, p.y, p.z); }

// An in-plane orthonormal basis (u, v) for `normal`, u as close to `hint` as the plane allows.
void PlaneBasis(const cv::Vec3d& normal, const cv::Vec3d& hint, cv::Vec3d& u, cv::Vec3d& v) {
  u = hint - hint.dot(normal) * normal;
  if (cv::norm(u) < 1e-12 * std::max(1.0, cv::norm(hint))) {
    // Any direction not along the normal will do.
    const cv::Vec3d axis = std::abs(normal[0]) < 0.9 ? cv::Vec3d(1, 0, 0) : cv::Vec3d(0, 1, 0);
    u = axis - axis.dot(normal) * normal;
  }
  u = cv::normalize(u);
  v = normal.cross(u);
}

// The points in the plane's 2D coordinates around `origin`.
std::vector<cv::Point2d> InPlane(const std::vector<cv::Point3d>& points, const cv::Point3d& origin,
                                 const cv::Vec3d& u, const cv::Vec3d& v) {
  std::vector<cv::Point2d> flat;
  flat.reserve(points.size());
  for (const cv::Point3d& p : points) {
    const cv::Vec3d d = Vec(p - origin);
    flat.emplace_back(d.dot(u), d.dot(v));
  }
  return flat;
}

}  // namespace

std::optional<double> AngleAtMiddle3dDeg(const cv::Point3d& base, const cv::Point3d& middle,
                                         const cv::Point3d& tip) {
  const cv::Vec3d a = Vec(base - middle), b = Vec(tip - middle);
  const double longest = std::max({cv::norm(a), cv::norm(b), cv::norm(Vec(tip - base))});
  if (longest == 0.0 || cv::norm(a) <= kCoincidentRelTol * longest ||
      cv::norm(b) <= kCoincidentRelTol * longest) {
    return std::nullopt;
  }
  // atan2(|a x b|, a . b) stays accurate near 0 and 180 degrees, where acos loses digits.
  return std::atan2(cv::norm(a.cross(b)), a.dot(b)) * kRadToDeg;
}

std::optional<PlaneFit3d> FitPlane3d(const std::vector<cv::Point3d>& points) {
  if (points.size() < 3) return std::nullopt;
  cv::Point3d centroid(0, 0, 0);
  for (const cv::Point3d& p : points) centroid += p;
  centroid *= 1.0 / static_cast<double>(points.size());
  cv::Matx33d scatter = cv::Matx33d::zeros();
  for (const cv::Point3d& p : points) {
    const cv::Vec3d d = Vec(p - centroid);
    scatter += d * d.t();
  }
  cv::Matx31d eigenvalues;
  cv::Matx33d eigenvectors;  // Rows, largest eigenvalue first.
  cv::eigen(scatter, eigenvalues, eigenvectors);
  // Spreads (square roots of the eigenvalues) along the principal axes: a line has no second one.
  // The eigen solver leaves a rounding error of about sqrt(machine epsilon) of the largest spread
  // in the second one, hence kPlaneRelTol rather than circle_fit's kCollinearRelTol.
  const double largest = std::sqrt(std::max(0.0, eigenvalues(0)));
  const double second = std::sqrt(std::max(0.0, eigenvalues(1)));
  if (largest == 0.0 || second <= kPlaneRelTol * largest) return std::nullopt;

  PlaneFit3d plane;
  plane.centroid = centroid;
  plane.normal =
      cv::normalize(cv::Vec3d(eigenvectors(2, 0), eigenvectors(2, 1), eigenvectors(2, 2)));
  const cv::Vec3d orientation = Vec(points[1] - points[0]).cross(Vec(points.back() - points[0]));
  if (orientation.dot(plane.normal) < 0) plane.normal = -plane.normal;
  plane.rms_residual =
      std::sqrt(std::max(0.0, eigenvalues(2)) / static_cast<double>(points.size()));
  return plane;
}

std::optional<double> AngleBetweenPlanesDeg(const cv::Vec3d& normal_a, const cv::Vec3d& normal_b) {
  const double na = cv::norm(normal_a), nb = cv::norm(normal_b);
  if (na == 0.0 || nb == 0.0) return std::nullopt;
  const cv::Vec3d a = normal_a / na, b = normal_b / nb;
  // A normal's sign is arbitrary: the angle between the planes is the acute one.
  return std::atan2(cv::norm(a.cross(b)), std::abs(a.dot(b))) * kRadToDeg;
}

std::optional<CircleFit3d> FitCircle3d(const std::vector<cv::Point3d>& points) {
  const std::optional<PlaneFit3d> plane = FitPlane3d(points);
  if (!plane) return std::nullopt;
  cv::Vec3d u, v;
  PlaneBasis(plane->normal, Vec(points.back() - points.front()), u, v);
  const std::optional<CircleFit> flat = FitCircleTaubin(InPlane(points, plane->centroid, u, v));
  if (!flat) return std::nullopt;

  CircleFit3d circle;
  circle.normal = plane->normal;
  circle.radius = flat->radius;
  const cv::Vec3d centre = Vec(plane->centroid) + flat->centre.x * u + flat->centre.y * v;
  circle.centre = cv::Point3d(centre[0], centre[1], centre[2]);
  double sum_sq = 0.0;
  for (const cv::Point3d& p : points) {
    const cv::Vec3d d = Vec(p) - centre;
    const double out_of_plane = d.dot(circle.normal);
    const double in_plane = cv::norm(d - out_of_plane * circle.normal) - circle.radius;
    sum_sq += out_of_plane * out_of_plane + in_plane * in_plane;
  }
  circle.rms_residual = std::sqrt(sum_sq / static_cast<double>(points.size()));
  return circle;
}

std::optional<double> ArcLength3d(const CircleFit3d& circle,
                                  const std::vector<cv::Point3d>& points) {
  if (points.size() < 2) return std::nullopt;
  cv::Vec3d u, v;
  PlaneBasis(circle.normal, Vec(points.back() - points.front()), u, v);
  CircleFit flat;
  flat.centre = cv::Point2d(0, 0);
  flat.radius = circle.radius;
  return ArcLengthThroughPoints(flat, InPlane(points, circle.centre, u, v));
}

void MeasureSegments3d(const std::vector<std::optional<cv::Point3d>>& chain,
                       std::vector<Segment3d>* segments) {
  segments->resize(chain.size() >= 3 ? chain.size() - 2 : 0);
  for (size_t k = 0; k < segments->size(); ++k) {
    Segment3d& segment = (*segments)[k];
    segment = Segment3d{};
    const std::optional<cv::Point3d>&a = chain[k], &b = chain[k + 1], &c = chain[k + 2];
    if (!a || !b || !c) continue;
    const cv::Vec3d u = *a - *b, v = *c - *b;
    const double nu = cv::norm(u), nv = cv::norm(v);
    if (!(nu > 0) || !(nv > 0)) continue;
    // The angle at the middle, theta: an inscribed angle, so the arc through the middle spans
    // 2 pi - 2 theta of the circle, whose radius is |ac| / (2 sin theta) (law of sines).
    const double theta = std::atan2(cv::norm(u.cross(v)), u.dot(v));
    segment.angle_deg = theta * kRadToDeg;
    const double sin_theta = std::sin(theta);
    if (sin_theta < 1e-12) {
      // On a line: straight through the middle (folded back on itself: no circle either).
      if (theta > std::numbers::pi / 2) segment.arc_length = nu + nv;
      continue;
    }
    segment.radius = cv::norm(*c - *a) / (2.0 * sin_theta);
    segment.arc_length = *segment.radius * (2.0 * std::numbers::pi - 2.0 * theta);
  }
}

Shape3d MeasureShape3d(const std::vector<std::optional<cv::Point3d>>& chain,
                       const std::optional<cv::Vec3d>& reference_normal,
                       const std::optional<cv::Point3d>& tip_reference) {
  Shape3d shape;
  if (chain.empty()) return shape;
  const std::optional<cv::Point3d>& base = chain.front();
  const std::optional<cv::Point3d>& tip = chain.back();
  if (chain.size() >= 3) {
    const std::optional<cv::Point3d>& middle = chain[chain.size() / 2];
    if (base && middle && tip) shape.angle_deg = AngleAtMiddle3dDeg(*base, *middle, *tip);
  }
  std::vector<cv::Point3d> found;
  found.reserve(chain.size());
  for (const std::optional<cv::Point3d>& p : chain) {
    if (p) found.push_back(*p);
  }
  if (const std::optional<CircleFit3d> circle = FitCircle3d(found)) {
    shape.plane_normal = circle->normal;
    shape.radius = circle->radius;
    shape.arc_length = ArcLength3d(*circle, found);
    if (reference_normal)
      shape.out_of_plane_deg = AngleBetweenPlanesDeg(circle->normal, *reference_normal);
  } else if (const std::optional<PlaneFit3d> plane = FitPlane3d(found)) {
    shape.plane_normal = plane->normal;
    if (reference_normal)
      shape.out_of_plane_deg = AngleBetweenPlanesDeg(plane->normal, *reference_normal);
  }
  if (tip && tip_reference) shape.tip_disp = cv::norm(*tip - *tip_reference);
  return shape;
}

}  // namespace softsight
