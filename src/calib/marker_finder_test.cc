// The body order of marker_finder.h on points with a known order.
#include "softsight/calib/marker_finder.h"

#include <cmath>

#include <gtest/gtest.h>

namespace softsight {
namespace {

TEST(OrderAlongBody, ShuffledPointsOnABentArcComeOutInBodyOrderFromTheGivenBase) {
  // Six points along a 200-degree arc, listed out of order.
  std::vector<cv::Point2d> arc;
  for (int i = 0; i < 6; ++i) {
    const double a = CV_PI * 200.0 / 180.0 * i / 5.0;
    arc.emplace_back(320 + 100 * std::cos(a), 240 + 100 * std::sin(a));
  }
  const std::vector<size_t> shuffled = {3, 0, 5, 1, 4, 2};
  std::vector<cv::Point2d> points;
  for (size_t i : shuffled) points.push_back(arc[i]);
  bool ambiguous = true;
  const std::vector<size_t> order =
      OrderAlongBody(points, cv::Size(640, 480), arc[5] + cv::Point2d(3, 0), &ambiguous);
  EXPECT_FALSE(ambiguous);
  ASSERT_EQ(order.size(), 6u);
  for (size_t k = 0; k < 6; ++k) EXPECT_EQ(shuffled[order[k]], 5 - k) << "position " << k;
}

TEST(OrderAlongBody, FourCornersOfASquareHaveNoClearOrder) {
  const std::vector<cv::Point2d> square = {{100, 100}, {200, 100}, {200, 200}, {100, 200}};
  bool ambiguous = false;
  OrderAlongBody(square, cv::Size(640, 480), std::nullopt, &ambiguous);
  EXPECT_TRUE(ambiguous);
}

TEST(OrderAlongBody, WithoutAHintTheBaseIsTheEndNearerTheBorder) {
  const std::vector<cv::Point2d> line = {{320, 200}, {320, 300}, {320, 460}};
  const std::vector<size_t> order = OrderAlongBody(line, cv::Size(640, 480), std::nullopt);
  EXPECT_EQ(order.front(), 2u);
  EXPECT_EQ(order.back(), 0u);
}

}  // namespace
}  // namespace softsight
