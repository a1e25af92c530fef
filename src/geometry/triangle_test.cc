#include "geometry/geometry_test_util.h"
#include "softsight/geometry/triangle.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace softsight {
namespace {

using ::testing::DoubleNear;
using ::testing::Eq;
using ::testing::Optional;

using testing::kTol;

using testing::OnCircle;

TEST(TriangleTest, StraightIs180DegreesWithNoRadiusAndArcEqualToChord) {
  const TriangleMeasures m = MeasureTriangle({0, 0}, {50, 0}, {100, 0});
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(180.0, kTol)));
  EXPECT_NEAR(m.chord, 100.0, kTol);
  EXPECT_THAT(m.sagitta, Optional(DoubleNear(0.0, kTol)));
  EXPECT_EQ(m.radius, std::nullopt);
  EXPECT_THAT(m.arc_length, Optional(DoubleNear(100.0, kTol)));
  EXPECT_EQ(m.circumradius, std::nullopt);
}

TEST(TriangleTest, StraightButTiltedWithMiddleOffCentre) {
  // On the line y = 2x + 1, middle at a quarter of the way: still straight.
  const TriangleMeasures m = MeasureTriangle({1, 3}, {2, 5}, {5, 11});
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(180.0, 1e-6)));
  EXPECT_EQ(m.radius, std::nullopt);
  EXPECT_THAT(m.arc_length, Optional(DoubleNear(std::hypot(4.0, 8.0), kTol)));
}

TEST(TriangleTest, RightAngleAtMiddleIsAHalfCircle) {
  // Thales: a right angle at the middle puts base and tip on a diameter. c = 10 sqrt 2,
  // d = 5 sqrt 2 = c / 2, so R = (200 + 200) / (40 sqrt 2) = 5 sqrt 2 and L = pi R.
  const TriangleMeasures m = MeasureTriangle({0, 10}, {0, 0}, {10, 0});
  const double r = 5.0 * std::sqrt(2.0);
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(90.0, kTol)));
  EXPECT_NEAR(m.chord, 10.0 * std::sqrt(2.0), kTol);
  EXPECT_THAT(m.sagitta, Optional(DoubleNear(r, kTol)));
  EXPECT_THAT(m.radius, Optional(DoubleNear(r, kTol)));
  EXPECT_THAT(m.arc_length, Optional(DoubleNear(std::numbers::pi * r, kTol)));
  EXPECT_THAT(m.circumradius, Optional(DoubleNear(r, kTol)));
}

TEST(TriangleTest, HalfCircleOfRadius40) {
  // c = 80, d = 40: R = (6400 + 6400) / 320 = 40, theta = 2 asin(1) = pi, L = 40 pi.
  const TriangleMeasures m = MeasureTriangle({-40, 0}, {0, 40}, {40, 0});
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(90.0, kTol)));
  EXPECT_THAT(m.radius, Optional(DoubleNear(40.0, kTol)));
  EXPECT_THAT(m.arc_length, Optional(DoubleNear(40.0 * std::numbers::pi, 1e-7)));
}

TEST(TriangleTest, QuarterCircleIsTheMinorArc) {
  // 90 degree arc of radius 100, middle mid-arc: c = 100 sqrt 2, d = 100 (1 - cos 45).
  // The inscribed angle at the middle spans the 270 degree remainder: 135 degrees.
  const cv::Point2d o(10, 20);
  const TriangleMeasures m =
      MeasureTriangle(OnCircle(o, 100, -45), OnCircle(o, 100, 0), OnCircle(o, 100, 45));
  EXPECT_NEAR(m.chord, 100.0 * std::sqrt(2.0), kTol);
  EXPECT_THAT(m.sagitta, Optional(DoubleNear(100.0 * (1.0 - std::sqrt(0.5)), kTol)));
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(135.0, kTol)));
  EXPECT_THAT(m.radius, Optional(DoubleNear(100.0, kTol)));
  EXPECT_THAT(m.arc_length, Optional(DoubleNear(100.0 * std::numbers::pi / 2.0, kTol)));
  EXPECT_THAT(m.circumradius, Optional(DoubleNear(100.0, kTol)));
}

TEST(TriangleTest, PastAHalfCircleIsTheMajorArc) {
  // 270 degree arc of radius 50, middle at 90 deg, ends at 225 and -45 deg:
  // c = 50 sqrt 2, d = 50 + 25 sqrt 2 > R. R = (5000 + 4 d^2) / (8 d) = 50, L = 50 * 3 pi / 2.
  const cv::Point2d o(0, 0);
  const TriangleMeasures m =
      MeasureTriangle(OnCircle(o, 50, 225), OnCircle(o, 50, 90), OnCircle(o, 50, -45));
  EXPECT_NEAR(m.chord, 50.0 * std::sqrt(2.0), kTol);
  EXPECT_THAT(m.sagitta, Optional(DoubleNear(50.0 + 25.0 * std::sqrt(2.0), kTol)));
  EXPECT_THAT(m.radius, Optional(DoubleNear(50.0, kTol)));
  EXPECT_THAT(m.arc_length, Optional(DoubleNear(50.0 * 1.5 * std::numbers::pi, kTol)));
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(45.0, kTol)));
}

TEST(TriangleTest, ArcLengthIsContinuousThroughTheHalfCircle) {
  // Just below and above d = c / 2, theta is just below and above pi.
  const double c = 80.0;
  const double below = *ArcLengthFromChordSagitta(c, 40.0 - 1e-6);
  const double above = *ArcLengthFromChordSagitta(c, 40.0 + 1e-6);
  EXPECT_NEAR(below, 40.0 * std::numbers::pi, 1e-4);
  EXPECT_NEAR(above, 40.0 * std::numbers::pi, 1e-4);
  EXPECT_LT(below, above);
}

TEST(TriangleTest, NearlyStraightTendsToTheChord) {
  const double c = 100.0;
  const std::optional<double> r = RadiusFromChordSagitta(c, 1e-6);
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(*r, (c * c + 4e-12) / 8e-6, 1.0);
  EXPECT_THAT(ArcLengthFromChordSagitta(c, 1e-6), Optional(DoubleNear(c, 1e-9)));
  EXPECT_THAT(ArcLengthFromChordSagitta(c, 0.0), Optional(Eq(c)));
  EXPECT_EQ(RadiusFromChordSagitta(c, 0.0), std::nullopt);
}

TEST(TriangleTest, ChordSagittaFunctionsRejectNonsense) {
  EXPECT_EQ(RadiusFromChordSagitta(0.0, 5.0), std::nullopt);
  EXPECT_EQ(ArcLengthFromChordSagitta(0.0, 5.0), std::nullopt);
  EXPECT_EQ(ArcLengthFromChordSagitta(10.0, -1.0), std::nullopt);
  EXPECT_EQ(RadiusFromChordSagitta(10.0, std::nan("")), std::nullopt);
}

TEST(TriangleTest, BaseOnTipLeavesOnlyChordAndAngle) {
  // Folded back onto itself: the rays from the middle coincide (angle 0), the chord is 0, and
  // there is no chord line for a sagitta.
  const TriangleMeasures m = MeasureTriangle({5, 5}, {30, 5}, {5, 5});
  EXPECT_THAT(m.angle_deg, Optional(DoubleNear(0.0, kTol)));
  EXPECT_EQ(m.chord, 0.0);
  EXPECT_EQ(m.sagitta, std::nullopt);
  EXPECT_EQ(m.radius, std::nullopt);
  EXPECT_EQ(m.arc_length, std::nullopt);
  EXPECT_EQ(m.circumradius, std::nullopt);
  EXPECT_EQ(Sagitta({5, 5}, {30, 5}, {5, 5}), std::nullopt);
}

TEST(TriangleTest, MiddleOnAnEndGivesAbsentValuesNotNaN) {
  for (const cv::Point2d& middle : {cv::Point2d(0, 0), cv::Point2d(40, 30),
                                    cv::Point2d(1e-12, 0)}) {
    const TriangleMeasures m = MeasureTriangle({0, 0}, middle, {40, 30});
    EXPECT_EQ(m.angle_deg, std::nullopt) << middle;
    EXPECT_NEAR(m.chord, 50.0, kTol);
    EXPECT_EQ(m.sagitta, std::nullopt) << middle;
    EXPECT_EQ(m.radius, std::nullopt) << middle;
    EXPECT_EQ(m.arc_length, std::nullopt) << middle;
    EXPECT_EQ(m.circumradius, std::nullopt) << middle;
  }
}

TEST(TriangleTest, AllThreeCoincidentGivesNothingButAZeroChord) {
  const TriangleMeasures m = MeasureTriangle({7, 7}, {7, 7}, {7, 7});
  EXPECT_EQ(m.angle_deg, std::nullopt);
  EXPECT_EQ(m.chord, 0.0);
  EXPECT_EQ(m.sagitta, std::nullopt);
  EXPECT_EQ(m.arc_length, std::nullopt);
  EXPECT_EQ(m.circumradius, std::nullopt);
}

// Eq. 7 exactly as the paper writes it, for comparison.
double LawOfCosinesDeg(cv::Point2d r, cv::Point2d b, cv::Point2d g) {
  const double l1 = cv::norm(r - b), l2 = cv::norm(b - g), l3 = cv::norm(r - g);
  return std::acos((l1 * l1 + l2 * l2 - l3 * l3) / (2 * l1 * l2)) * 180.0 / std::numbers::pi;
}

TEST(TriangleTest, AngleMatchesTheLawOfCosinesOnRandomTriangles) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> coord(0.0, 640.0);
  for (int i = 0; i < 1000; ++i) {
    const cv::Point2d a(coord(rng), coord(rng)), b(coord(rng), coord(rng)),
        c(coord(rng), coord(rng));
    EXPECT_THAT(AngleAtMiddleDeg(a, b, c), Optional(DoubleNear(LawOfCosinesDeg(a, b, c), 1e-6)));
  }
}

TEST(TriangleTest, Eq8EqualsCircumradiusWhenTheMiddleIsMidArc) {
  // Random arcs (10..350 degrees) with the middle marker mid-arc: eq. 8 is exact there, and
  // eq. 9 returns radius times the arc's angle.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> span(10.0, 350.0), radius(5.0, 2000.0), angle(0, 360);
  for (int i = 0; i < 500; ++i) {
    const double s = span(rng), r = radius(rng), a = angle(rng);
    const cv::Point2d o(320, 240);
    const TriangleMeasures m = MeasureTriangle(OnCircle(o, r, a - s / 2), OnCircle(o, r, a),
                                               OnCircle(o, r, a + s / 2));
    ASSERT_TRUE(m.radius && m.circumradius && m.arc_length) << s << " " << r;
    EXPECT_NEAR(*m.radius, r, 1e-9 * r * 1e3);
    EXPECT_NEAR(*m.circumradius, r, 1e-9 * r * 1e3);
    EXPECT_NEAR(*m.arc_length, r * s * std::numbers::pi / 180.0, 1e-9 * r * 1e3) << s;
  }
}

TEST(TriangleTest, CircumradiusOfAnOffCentreMiddleDiffersFromEq8) {
  // Middle at 30 deg of a 0..90 deg arc: the circumradius still finds R = 60, while eq. 8
  // (which assumes mid-arc) does not; this is what the cross-check is for.
  const cv::Point2d o(0, 0);
  const cv::Point2d b = OnCircle(o, 60, 0), m = OnCircle(o, 60, 30), t = OnCircle(o, 60, 90);
  EXPECT_THAT(Circumradius(b, m, t), Optional(DoubleNear(60.0, kTol)));
  const TriangleMeasures tri = MeasureTriangle(b, m, t);
  ASSERT_TRUE(tri.radius.has_value());
  EXPECT_GT(std::abs(*tri.radius - 60.0), 1.0);
}

}  // namespace
}  // namespace softsight
