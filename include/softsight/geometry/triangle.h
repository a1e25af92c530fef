// The paper's measurements on three marker positions (section 3, eqs. 7-9), as pure functions.
//
// Lengths come out in the unit of the input points (pixels in, pixels out; plane millimetres
// in, millimetres out), which is why the names here carry no unit suffix. Angles are in degrees
// at this interface. Anything that cannot be computed is absent: coincident points never yield
// NaN or infinity.
#pragma once

#include <optional>

#include <opencv2/core.hpp>

namespace softsight {

// Two points closer than kCoincidentRelTol times the triangle's longest side (or both exactly
// equal) count as coincident. A sagitta below kStraightRelTol times the chord counts as zero
// (straight actuator): at that ratio R = c / (8 * 1e-9) is beyond any camera's resolution.
inline constexpr double kCoincidentRelTol = 1e-9;
inline constexpr double kStraightRelTol = 1e-9;

// Angle at `middle` between the rays to `base` and `tip` (eq. 7), in degrees, in [0, 180];
// 180 when the three are collinear with the middle between the others. Absent when `middle`
// coincides with `base` or `tip`.
std::optional<double> AngleAtMiddleDeg(const cv::Point2d& base, const cv::Point2d& middle,
                                       const cv::Point2d& tip);

// Chord c = |base - tip| (always defined; 0 when they coincide).
double Chord(const cv::Point2d& base, const cv::Point2d& tip);

// Sagitta d: distance of `middle` from the straight line through `base` and `tip`. Absent when
// base and tip coincide (no line).
std::optional<double> Sagitta(const cv::Point2d& base, const cv::Point2d& middle,
                              const cv::Point2d& tip);

// Eq. 8, intersecting chords: R = (c^2 + 4 d^2) / (8 d). Absent when d is (numerically) zero or
// the chord is zero.
std::optional<double> RadiusFromChordSagitta(double chord, double sagitta);

// Eq. 9: L = R * theta. theta = 2 asin(c / 2R) (minor arc) when d <= R, and 2 pi - 2 asin(c / 2R)
// (major arc: bent past a half circle) when d > R. Straight (d numerically 0): L = c.
// Absent for a zero chord or a negative input.
std::optional<double> ArcLengthFromChordSagitta(double chord, double sagitta);

// Radius of the circle through the three points (a * b * c / (4 * area)): the cross-check of
// eq. 8, equal to it when the middle sits mid-arc. Absent when the points are collinear or two
// of them coincide.
std::optional<double> Circumradius(const cv::Point2d& a, const cv::Point2d& b,
                                   const cv::Point2d& c);

// Everything above for one triple. Sagitta, radius and arc length need a proper triangle: they
// are absent when any two of the points coincide (two markers on top of each other is a tracking
// fault, not a straight actuator).
struct TriangleMeasures {
  std::optional<double> angle_deg{};
  double chord = 0.0;
  std::optional<double> sagitta{};
  std::optional<double> radius{};        // Eq. 8; absent when straight.
  std::optional<double> arc_length{};    // Eq. 9; = chord when straight.
  std::optional<double> circumradius{};  // Absent when collinear.
};

TriangleMeasures MeasureTriangle(const cv::Point2d& base, const cv::Point2d& middle,
                                 const cv::Point2d& tip);

}  // namespace softsight
