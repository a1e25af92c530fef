// The small parts the live controller is made of, each on its own: the rate meter and the
// scale clicks (the pointer, layout and range edits are tested in live_controller_test.cc).
#include <gtest/gtest.h>

#include <chrono>

#include "gui/rate_meter.h"
#include "gui/scale_clicks.h"

namespace softsight {
namespace {

using Clock = RateMeter::Clock;
using std::chrono::milliseconds;

TEST(RateMeter, FpsIsResultsPerSecondOverTheLast30AndLatencyIsSmoothed) {
  RateMeter meter;
  const Clock::time_point t0{};
  EXPECT_FALSE(meter.fps());
  meter.result_at(t0);
  EXPECT_FALSE(meter.fps()) << "one result is no rate";
  meter.result_at(t0);
  EXPECT_FALSE(meter.fps()) << "no time passed";
  // 30 results 40 ms apart after the two at t0: the ring holds the last 30, 29 intervals.
  Clock::time_point t = t0;
  for (int i = 0; i < 30; ++i) {
    t += milliseconds(40);
    meter.result_at(t);
  }
  ASSERT_TRUE(meter.fps());
  EXPECT_NEAR(*meter.fps(), 25.0, 1e-9);
  // The window slides: 29 more 10 ms apart replace every old time but the newest.
  for (int i = 0; i < 28; ++i) {
    t += milliseconds(10);
    meter.result_at(t);
  }
  EXPECT_NEAR(*meter.fps(), 29.0 / (0.040 + 28 * 0.010), 1e-9) << "one 40 ms interval left";
  t += milliseconds(10);
  meter.result_at(t);
  EXPECT_NEAR(*meter.fps(), 100.0, 1e-9);

  EXPECT_FALSE(meter.latency_ms());
  meter.latency(10.0);
  EXPECT_DOUBLE_EQ(*meter.latency_ms(), 10.0);  // The first value as it is.
  meter.latency(20.0);
  EXPECT_DOUBLE_EQ(*meter.latency_ms(), 12.0);  // 10 + 0.2 * (20 - 10).
  meter.latency(20.0);
  EXPECT_DOUBLE_EQ(*meter.latency_ms(), 13.6);
}

TEST(ScaleClicks, TwoPointsAKnownDistanceApartGiveTheScaleInMeasurementPixels) {
  ScaleClicks scale(50.0);
  EXPECT_FALSE(scale.active());
  EXPECT_EQ(scale.start(), "scale: click point 1 of 2, 50 mm apart; Esc cancels");
  EXPECT_TRUE(scale.active());
  std::string message;
  // Image points (drawn) and measurement points (undistorted) differ: the scale uses the latter.
  EXPECT_FALSE(scale.add({10, 10}, {12, 10}, &message));
  EXPECT_EQ(message, "scale: click point 2, 50 mm from point 1; Esc cancels");
  EXPECT_EQ(scale.points().size(), 1u);
  const std::optional<MetricModel> metric = scale.add({110, 10}, {112, 10}, &message);
  ASSERT_TRUE(metric);
  EXPECT_TRUE(message.empty());
  EXPECT_DOUBLE_EQ(*metric->scale_mm_per_px, 0.5);
  ASSERT_TRUE(metric->scale_points);
  EXPECT_EQ(metric->scale_points->a_px, cv::Point2d(12, 10));
  EXPECT_EQ(metric->scale_points->b_px, cv::Point2d(112, 10));
  EXPECT_DOUBLE_EQ(metric->scale_points->distance_mm, 50.0);
  EXPECT_DOUBLE_EQ(scale.span_px(), 100.0);
  ASSERT_EQ(scale.points().size(), 2u);
  EXPECT_EQ(scale.points()[1], cv::Point2d(110, 10));  // Where the view draws the cross.
  scale.stop();
  EXPECT_FALSE(scale.active());
  EXPECT_TRUE(scale.points().empty());
}

TEST(ScaleClicks, PointsTooCloseStartOverAndWithoutADistanceItOnlySaysHow) {
  ScaleClicks scale(12.5);
  scale.start();
  std::string message;
  scale.add({100, 100}, {100, 100}, &message);
  EXPECT_FALSE(scale.add({110, 100}, {110, 100}, &message));
  EXPECT_EQ(message,
            "scale: the points are 10.0 px apart, too close (at least 20); click the first point "
            "again");
  EXPECT_TRUE(scale.active());
  EXPECT_TRUE(scale.points().empty());
  EXPECT_EQ(scale.hint(), "scale: click point 1 of 2, 12.5 mm apart; Esc cancels");

  ScaleClicks no_distance(std::nullopt);
  EXPECT_NE(no_distance.start().find("--scale-distance-mm"), std::string::npos);
  EXPECT_FALSE(no_distance.active());
}

}  // namespace
}  // namespace softsight
