#include "softsight/geometry/shape3d.h"

#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "geometry/geometry_test_util.h"

namespace softsight {
namespace {

using ::testing::DoubleNear;
using testing::kTol;
using ::testing::Optional;

// A point on a circle of `radius` about `centre` in the plane spanned by unit vectors u and v.
cv::Point3d OnCircle3d(const cv::Point3d& centre, const cv::Vec3d& u, const cv::Vec3d& v,
                       double radius, double angle_deg) {
  const double a = angle_deg * std::numbers::pi / 180.0;
  const cv::Vec3d p = radius * (std::cos(a) * u + std::sin(a) * v);
  return centre + cv::Point3d(p[0], p[1], p[2]);
}

// The plane of the image (x, y) turned by `tilt_deg` about the x axis: its in-plane axes.
void TiltedPlane(double tilt_deg, cv::Vec3d& u, cv::Vec3d& v, cv::Vec3d& normal) {
  const double t = tilt_deg * std::numbers::pi / 180.0;
  u = cv::Vec3d(1, 0, 0);
  v = cv::Vec3d(0, std::cos(t), std::sin(t));
  normal = u.cross(v);
}

TEST(Shape3dTest, AngleAtMiddleIsTheTriangleAngleInAnyOrientation) {
  // A right angle, turned into a plane tilted 50 degrees and moved away.
  cv::Vec3d u, v, n;
  TiltedPlane(50.0, u, v, n);
  const cv::Point3d middle(10, -20, 300);
  const cv::Vec3d a = 40.0 * u, b = 25.0 * v;
  EXPECT_THAT(AngleAtMiddle3dDeg(middle + cv::Point3d(a[0], a[1], a[2]), middle,
                                 middle + cv::Point3d(b[0], b[1], b[2])),
              Optional(DoubleNear(90.0, kTol)));
  EXPECT_THAT(AngleAtMiddle3dDeg({0, 0, 0}, {1, 1, 1}, {2, 2, 2}),
              Optional(DoubleNear(180.0, kTol)));
  EXPECT_EQ(AngleAtMiddle3dDeg({1, 2, 3}, {1, 2, 3}, {5, 5, 5}), std::nullopt);
}

TEST(Shape3dTest, PlaneOfPointsOnATiltedCircleHasTheTiltedNormal) {
  cv::Vec3d u, v, n;
  TiltedPlane(30.0, u, v, n);
  std::vector<cv::Point3d> points;
  for (double a : {200.0, 240.0, 280.0, 320.0})
    points.push_back(OnCircle3d({5, 8, 310}, u, v, 60, a));
  const std::optional<PlaneFit3d> plane = FitPlane3d(points);
  ASSERT_TRUE(plane.has_value());
  EXPECT_NEAR(std::abs(plane->normal.dot(n)), 1.0, kTol);
  EXPECT_NEAR(plane->rms_residual, 0.0, 1e-9);
  EXPECT_THAT(AngleBetweenPlanesDeg(plane->normal, {0, 0, 1}), Optional(DoubleNear(30.0, 1e-7)));
  // The sign follows the chain's turning: reversing the chain flips it.
  std::vector<cv::Point3d> reversed(points.rbegin(), points.rend());
  EXPECT_NEAR(FitPlane3d(reversed)->normal.dot(plane->normal), -1.0, kTol);
}

TEST(Shape3dTest, NoPlaneThroughPointsOnALine) {
  EXPECT_EQ(FitPlane3d({{0, 0, 0}, {1, 2, 3}, {2, 4, 6}, {5, 10, 15}}), std::nullopt);
  EXPECT_EQ(FitPlane3d({{0, 0, 0}, {1, 2, 3}}), std::nullopt);
  EXPECT_EQ(FitCircle3d({{0, 0, 0}, {1, 2, 3}, {2, 4, 6}}), std::nullopt);
}

TEST(Shape3dTest, AngleBetweenPlanesIgnoresTheNormalsSign) {
  EXPECT_THAT(AngleBetweenPlanesDeg({0, 0, 1}, {0, 0, -1}), Optional(DoubleNear(0.0, kTol)));
  EXPECT_THAT(AngleBetweenPlanesDeg({0, 0, 1}, {0, 1, 0}), Optional(DoubleNear(90.0, kTol)));
  EXPECT_THAT(AngleBetweenPlanesDeg({0, 0, 1}, {0, -1, -1}), Optional(DoubleNear(45.0, 1e-9)));
  EXPECT_EQ(AngleBetweenPlanesDeg({0, 0, 0}, {0, 1, 0}), std::nullopt);
}

TEST(Shape3dTest, CircleFitRecoversRadiusCentreAndArcLengthOfATiltedArc) {
  cv::Vec3d u, v, n;
  TiltedPlane(-35.0, u, v, n);
  const cv::Point3d centre(-12, 30, 280);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 5; ++i) points.push_back(OnCircle3d(centre, u, v, 45.0, 10.0 + 50.0 * i));
  const std::optional<CircleFit3d> circle = FitCircle3d(points);
  ASSERT_TRUE(circle.has_value());
  EXPECT_NEAR(circle->radius, 45.0, 1e-7);
  EXPECT_NEAR(cv::norm(circle->centre - centre), 0.0, 1e-7);
  EXPECT_NEAR(circle->rms_residual, 0.0, 1e-7);
  // 200 degrees of arc: past a half circle, so the major arc.
  EXPECT_THAT(ArcLength3d(*circle, points),
              Optional(DoubleNear(45.0 * 200.0 * std::numbers::pi / 180.0, 1e-6)));
}

TEST(Shape3dTest, MeasureShapeOfAThreeMarkerChainBentOutOfTheImagePlane) {
  cv::Vec3d u, v, n;
  TiltedPlane(30.0, u, v, n);
  const cv::Point3d centre(0, 0, 300);
  // Markers at -60, 0, +60 degrees around the centre: the angle at the middle is 120 degrees
  // (an inscribed angle over the remaining 240 degrees of circle).
  std::vector<std::optional<cv::Point3d>> chain = {OnCircle3d(centre, u, v, 50, 150),
                                                   OnCircle3d(centre, u, v, 50, 210),
                                                   OnCircle3d(centre, u, v, 50, 270)};
  const cv::Point3d tip_reference = *chain.back() + cv::Point3d(3, 4, 0);
  const Shape3d shape = MeasureShape3d(chain, cv::Vec3d(0, 0, 1), tip_reference);
  EXPECT_THAT(shape.angle_deg, Optional(DoubleNear(120.0, 1e-9)));
  EXPECT_THAT(shape.out_of_plane_deg, Optional(DoubleNear(30.0, 1e-7)));
  EXPECT_THAT(shape.radius, Optional(DoubleNear(50.0, 1e-7)));
  EXPECT_THAT(shape.arc_length,
              Optional(DoubleNear(50.0 * 120.0 * std::numbers::pi / 180.0, 1e-6)));
  EXPECT_THAT(shape.tip_disp, Optional(DoubleNear(5.0, kTol)));

  // The middle marker lost: no angle, no plane from two points, the tip still moves.
  chain[1].reset();
  const Shape3d partial = MeasureShape3d(chain, cv::Vec3d(0, 0, 1), tip_reference);
  EXPECT_EQ(partial.angle_deg, std::nullopt);
  EXPECT_EQ(partial.plane_normal, std::nullopt);
  EXPECT_EQ(partial.radius, std::nullopt);
  EXPECT_THAT(partial.tip_disp, Optional(DoubleNear(5.0, kTol)));
}

TEST(Shape3dTest, SegmentsOfAChainWithTwoCurvaturesEachGiveTheirOwnCircle) {
  // Five markers in a tilted plane: the first three on a circle of radius 40 (30 deg apart),
  // the last three on one of radius 90 (20 deg apart), sharing the middle marker: each inner
  // marker's triple lies on one circle, except the one that straddles both.
  cv::Vec3d u, v, n;
  TiltedPlane(35.0, u, v, n);
  const cv::Point3d centre_a(0, 0, 300);
  std::vector<std::optional<cv::Point3d>> chain;
  for (double a : {0.0, 30.0, 60.0}) chain.push_back(OnCircle3d(centre_a, u, v, 40.0, a));
  // A circle of radius 90 through chain[2], tangent-free: centre on the line from chain[2]
  // through centre_a, beyond it.
  const cv::Point3d joint = *chain[2];
  const cv::Point3d centre_b = joint + (centre_a - joint) * (90.0 / 40.0);
  const cv::Point3d r0 = joint - centre_b;
  // Angles on the second circle measured from the joint's direction.
  const cv::Vec3d e1 = cv::normalize(cv::Vec3d(r0.x, r0.y, r0.z));
  const cv::Vec3d e2 = n.cross(e1);
  for (double a : {20.0, 40.0}) {
    const double t = a * std::numbers::pi / 180.0;
    const cv::Vec3d p = 90.0 * (std::cos(t) * e1 + std::sin(t) * e2);
    chain.push_back(centre_b + cv::Point3d(p[0], p[1], p[2]));
  }
  std::vector<Segment3d> segments;
  MeasureSegments3d(chain, &segments);
  ASSERT_EQ(segments.size(), 3u);
  EXPECT_THAT(segments[0].radius, Optional(DoubleNear(40.0, 1e-9)));
  EXPECT_THAT(segments[0].arc_length, Optional(DoubleNear(40.0 * std::numbers::pi / 3, 1e-9)));
  // An inscribed angle: 180 - half the arc's 60 deg.
  EXPECT_THAT(segments[0].angle_deg, Optional(DoubleNear(150.0, 1e-9)));
  EXPECT_THAT(segments[2].radius, Optional(DoubleNear(90.0, 1e-9)));
  EXPECT_THAT(segments[2].arc_length, Optional(DoubleNear(90.0 * 40.0 * std::numbers::pi / 180, 1e-9)));
  ASSERT_TRUE(segments[1].radius.has_value());  // Straddles both: between the two.
  EXPECT_GT(*segments[1].radius, 40.0);
  EXPECT_LT(*segments[1].radius, 90.0);
  // The same triples through the general 3D circle fit (the reference): the same figures.
  for (size_t k = 0; k < segments.size(); ++k) {
    const std::vector<cv::Point3d> triple = {*chain[k], *chain[k + 1], *chain[k + 2]};
    const std::optional<CircleFit3d> circle = FitCircle3d(triple);
    ASSERT_TRUE(circle.has_value());
    EXPECT_THAT(segments[k].radius, Optional(DoubleNear(circle->radius, 1e-6 * circle->radius)));
    EXPECT_THAT(segments[k].arc_length,
                Optional(DoubleNear(*ArcLength3d(*circle, triple), 1e-6 * circle->radius)));
  }

  // A missing marker empties the two segments it belongs to; a straight triple has no radius.
  chain[3].reset();
  chain.push_back(cv::Point3d(0, 0, 0));
  MeasureSegments3d(chain, &segments);
  ASSERT_EQ(segments.size(), 4u);
  EXPECT_TRUE(segments[0].radius.has_value());
  EXPECT_FALSE(segments[1].arc_length.has_value());
  EXPECT_FALSE(segments[2].angle_deg.has_value());
  const std::vector<std::optional<cv::Point3d>> straight = {
      cv::Point3d(0, 0, 300), cv::Point3d(3, 4, 300), cv::Point3d(9, 12, 300)};
  MeasureSegments3d(straight, &segments);
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_FALSE(segments[0].radius.has_value());
  EXPECT_THAT(segments[0].arc_length, Optional(DoubleNear(15.0, kTol)));
  EXPECT_THAT(segments[0].angle_deg, Optional(DoubleNear(180.0, kTol)));
}

}  // namespace
}  // namespace softsight
