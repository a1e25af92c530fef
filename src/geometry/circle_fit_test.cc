#include "softsight/geometry/circle_fit.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "softsight/geometry/triangle.h"

namespace softsight {
namespace {

using ::testing::DoubleNear;
using ::testing::Optional;


std::vector<cv::Point2d> Arc(cv::Point2d centre, double radius, double from_deg, double to_deg,
                             int count) {
  std::vector<cv::Point2d> points;
  for (int i = 0; i < count; ++i) {
    const double a = (from_deg + (to_deg - from_deg) * i / (count - 1)) * std::numbers::pi / 180.0;
    points.push_back(centre + radius * cv::Point2d(std::cos(a), std::sin(a)));
  }
  return points;
}

TEST(CircleFitTest, ExactOnPointsOfAKnownCircle) {
  const std::vector<cv::Point2d> points = Arc({12.5, -7.0}, 33.0, 10.0, 130.0, 7);
  const std::optional<CircleFit> fit = FitCircleTaubin(points);
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->centre.x, 12.5, 1e-9);
  EXPECT_NEAR(fit->centre.y, -7.0, 1e-9);
  EXPECT_NEAR(fit->radius, 33.0, 1e-9);
  EXPECT_NEAR(fit->rms_residual, 0.0, 1e-9);
}

TEST(CircleFitTest, ExactOnAShortArcOfALargeCircleFarFromTheOrigin) {
  // 20 degrees of a 5000 px circle: nearly straight, badly conditioned for naive fits.
  const std::vector<cv::Point2d> points = Arc({-3000.0, 8000.0}, 5000.0, -10.0, 10.0, 5);
  const std::optional<CircleFit> fit = FitCircleTaubin(points);
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->radius, 5000.0, 1e-5);
  EXPECT_NEAR(fit->centre.x, -3000.0, 1e-5);
  EXPECT_NEAR(fit->centre.y, 8000.0, 1e-5);
}

TEST(CircleFitTest, ThreePointsGiveTheCircumcircle) {
  const cv::Point2d a(3, 4), b(40, -2), c(17, 30);
  const std::optional<CircleFit> fit = FitCircleTaubin({a, b, c});
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->radius, *Circumradius(a, b, c), 1e-9);
  for (const cv::Point2d& p : {a, b, c}) {
    EXPECT_NEAR(cv::norm(p - fit->centre), fit->radius, 1e-9);
  }
}

TEST(CircleFitTest, WithinToleranceOnNoisyPoints) {
  // 9 markers over 200 degrees of a 150 px circle, 0.5 px Gaussian noise per coordinate.
  // Over 200 draws the mean radius error (the fit's bias) must stay below 0.05 px, each draw
  // within 1 px, and the rms residual near the noise level.
  std::mt19937 rng(2024);
  std::normal_distribution<double> noise(0.0, 0.5);
  const cv::Point2d centre(320, 240);
  const std::vector<cv::Point2d> clean = Arc(centre, 150.0, -100.0, 100.0, 9);
  double sum_error = 0.0, sum_rms = 0.0;
  const int draws = 200;
  for (int d = 0; d < draws; ++d) {
    std::vector<cv::Point2d> points = clean;
    for (cv::Point2d& p : points) p += cv::Point2d(noise(rng), noise(rng));
    const std::optional<CircleFit> fit = FitCircleTaubin(points);
    ASSERT_TRUE(fit.has_value());
    EXPECT_NEAR(fit->radius, 150.0, 1.0);
    EXPECT_NEAR(cv::norm(fit->centre - centre), 0.0, 1.5);
    sum_error += fit->radius - 150.0;
    sum_rms += fit->rms_residual;
  }
  EXPECT_NEAR(sum_error / draws, 0.0, 0.05);
  // With 3 parameters fitted to 9 points, E[rms^2] = sigma^2 * (9 - 3) / 9.
  EXPECT_NEAR(sum_rms / draws, 0.5 * std::sqrt(6.0 / 9.0), 0.05);
}

TEST(CircleFitTest, CollinearAndDegenerateInputIsAbsent) {
  EXPECT_EQ(FitCircleTaubin({{0, 0}, {1, 1}}), std::nullopt);
  EXPECT_EQ(FitCircleTaubin({{0, 0}, {1, 2}, {2, 4}, {3, 6}}), std::nullopt);
  EXPECT_EQ(FitCircleTaubin({{5, 5}, {5, 5}, {5, 5}}), std::nullopt);
  EXPECT_EQ(FitCircleTaubin({{5, 5}, {5, 5}, {9, 1}}), std::nullopt);  // Two distinct points.
  EXPECT_TRUE(PointsAreCollinear({{0, 0}, {1, 2}, {2, 4}, {3, 6}}));
  EXPECT_TRUE(PointsAreCollinear({{5, 5}, {5, 5}, {9, 1}}));
  EXPECT_FALSE(PointsAreCollinear({{5, 5}, {5, 5}, {5, 5}}));
  EXPECT_TRUE(PointsAreDegenerate({{5, 5}, {5, 5}, {5, 5}}));
  EXPECT_FALSE(PointsAreCollinear({{0, 0}, {1, 2}, {2, 4.001}}));
}

TEST(CircleFitTest, ArcThroughPointsTakesTheMinorArcForAShortSpread) {
  const std::vector<cv::Point2d> points = Arc({0, 0}, 80.0, 20.0, 80.0, 4);
  const std::optional<CircleFit> fit = FitCircleTaubin(points);
  ASSERT_TRUE(fit.has_value());
  EXPECT_THAT(ArcLengthThroughPoints(*fit, points), Optional(DoubleNear(80.0 * std::numbers::pi / 3, 1e-8)));
}

TEST(CircleFitTest, ArcThroughPointsTakesTheMajorArcPastAHalfCircle) {
  // 270 degrees, both directions of travel.
  std::vector<cv::Point2d> points = Arc({100, 50}, 40.0, 0.0, 270.0, 6);
  const std::optional<CircleFit> fit = FitCircleTaubin(points);
  ASSERT_TRUE(fit.has_value());
  EXPECT_THAT(ArcLengthThroughPoints(*fit, points), Optional(DoubleNear(40.0 * 1.5 * std::numbers::pi, 1e-8)));
  std::reverse(points.begin(), points.end());
  EXPECT_THAT(ArcLengthThroughPoints(*fit, points), Optional(DoubleNear(40.0 * 1.5 * std::numbers::pi, 1e-8)));
}

TEST(CircleFitTest, ArcThroughPointsCanExceedAFullTurn) {
  // A long actuator curled past one turn: 400 degrees in 9 steps of 50 degrees.
  const std::vector<cv::Point2d> points = Arc({0, 0}, 30.0, 0.0, 400.0, 9);
  const std::optional<CircleFit> fit = FitCircleTaubin(points);
  ASSERT_TRUE(fit.has_value());
  EXPECT_THAT(ArcLengthThroughPoints(*fit, points),
              Optional(DoubleNear(30.0 * 400.0 * std::numbers::pi / 180.0, 1e-8)));
}

TEST(CircleFitTest, ArcThroughThreePointsAgreesWithEq9) {
  // Major arc of 300 degrees with the middle mid-arc: the fit and eqs. 8-9 must agree.
  const std::vector<cv::Point2d> points = Arc({10, 10}, 25.0, -150.0, 150.0, 3);
  const std::optional<CircleFit> fit = FitCircleTaubin(points);
  ASSERT_TRUE(fit.has_value());
  const TriangleMeasures m = MeasureTriangle(points[0], points[1], points[2]);
  ASSERT_TRUE(m.arc_length.has_value());
  EXPECT_THAT(ArcLengthThroughPoints(*fit, points), Optional(DoubleNear(*m.arc_length, 1e-8)));
}

TEST(CircleFitTest, ArcThroughPointsNeedsTwoPointsOffTheCentre) {
  const CircleFit circle{{0, 0}, 10.0, 0.0};
  EXPECT_EQ(ArcLengthThroughPoints(circle, {{10, 0}}), std::nullopt);
  EXPECT_EQ(ArcLengthThroughPoints(circle, {{10, 0}, {0, 0}}), std::nullopt);
}

}  // namespace
}  // namespace softsight
