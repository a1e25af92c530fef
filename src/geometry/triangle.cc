#include "softsight/geometry/triangle.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace softsight {
namespace {


double Cross(const cv::Point2d& u, const cv::Point2d& v) { return u.x * v.y - u.y * v.x; }

bool Coincident(double distance, double scale) {
  return distance == 0.0 || distance <= kCoincidentRelTol * scale;
}

}  // namespace

std::optional<double> AngleAtMiddleDeg(const cv::Point2d& base, const cv::Point2d& middle,
                                       const cv::Point2d& tip) {
  const cv::Point2d u = base - middle;  // |u| = l1
  const cv::Point2d v = tip - middle;   // |v| = l2
  const double l1 = std::hypot(u.x, u.y);
  const double l2 = std::hypot(v.x, v.y);
  const double scale = std::max({l1, l2, Chord(base, tip)});
  if (Coincident(l1, scale) || Coincident(l2, scale)) return std::nullopt;
  // Eq. 7 with l1^2 + l2^2 - l3^2 written as 2 u.v (the same number, without the cancellation
  // that costs digits near 180 degrees); the clamp keeps rounding from leaving acos' domain.
  const double cosine = std::clamp(u.dot(v) / (l1 * l2), -1.0, 1.0);
  return std::acos(cosine) * 180.0 / std::numbers::pi;
}

double Chord(const cv::Point2d& base, const cv::Point2d& tip) {
  return std::hypot(base.x - tip.x, base.y - tip.y);
}

std::optional<double> Sagitta(const cv::Point2d& base, const cv::Point2d& middle,
                              const cv::Point2d& tip) {
  const double c = Chord(base, tip);
  const cv::Point2d m = middle - base;
  const double scale = std::max(c, std::hypot(m.x, m.y));
  if (Coincident(c, scale)) return std::nullopt;
  return std::abs(Cross(tip - base, m)) / c;
}

std::optional<double> RadiusFromChordSagitta(double chord, double sagitta) {
  if (!(chord > 0.0) || !(sagitta >= 0.0) || sagitta <= kStraightRelTol * chord) {
    return std::nullopt;
  }
  return (chord * chord + 4.0 * sagitta * sagitta) / (8.0 * sagitta);
}

std::optional<double> ArcLengthFromChordSagitta(double chord, double sagitta) {
  if (!(chord > 0.0) || !(sagitta >= 0.0)) return std::nullopt;
  const std::optional<double> radius = RadiusFromChordSagitta(chord, sagitta);
  if (!radius) return chord;  // Straight.
  // c / 2R <= 1 always holds in exact arithmetic (equality at the half circle, d = R = c / 2).
  const double half_angle = std::asin(std::min(1.0, chord / (2.0 * *radius)));
  const double theta = sagitta > *radius ? 2.0 * std::numbers::pi - 2.0 * half_angle : 2.0 * half_angle;
  return *radius * theta;
}

std::optional<double> Circumradius(const cv::Point2d& a, const cv::Point2d& b,
                                   const cv::Point2d& c) {
  const double ab = Chord(a, b);
  const double bc = Chord(b, c);
  const double ca = Chord(c, a);
  const double longest = std::max({ab, bc, ca});
  if (Coincident(ab, longest) || Coincident(bc, longest) || Coincident(ca, longest)) {
    return std::nullopt;
  }
  // Twice the area. Collinear when the height over the longest side is negligible.
  const double twice_area = std::abs(Cross(b - a, c - a));
  if (twice_area / longest <= kStraightRelTol * longest) return std::nullopt;
  return ab * bc * ca / (2.0 * twice_area);
}

TriangleMeasures MeasureTriangle(const cv::Point2d& base, const cv::Point2d& middle,
                                 const cv::Point2d& tip) {
  TriangleMeasures out;
  out.angle_deg = AngleAtMiddleDeg(base, middle, tip);
  out.chord = Chord(base, tip);
  out.circumradius = Circumradius(base, middle, tip);
  const double longest = std::max({out.chord, Chord(base, middle), Chord(middle, tip)});
  if (Coincident(out.chord, longest) || Coincident(Chord(base, middle), longest) ||
      Coincident(Chord(middle, tip), longest)) {
    return out;
  }
  out.sagitta = Sagitta(base, middle, tip);
  if (out.sagitta) {
    out.radius = RadiusFromChordSagitta(out.chord, *out.sagitta);
    out.arc_length = ArcLengthFromChordSagitta(out.chord, *out.sagitta);
  }
  return out;
}

}  // namespace softsight
