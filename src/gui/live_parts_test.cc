// The small parts the live controller is made of, each on its own: the rate meter, the scale
// clicks and the view (the pointer, layout and range edits are tested in live_controller_test.cc).
#include <gtest/gtest.h>

#include <chrono>

#include <opencv2/imgproc.hpp>

#include "gui/live_layout.h"
#include "gui/live_view.h"
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
  meter.result_at(t0, 0.0);
  EXPECT_FALSE(meter.fps()) << "one result is no rate";
  meter.result_at(t0, 0.0);
  EXPECT_FALSE(meter.fps()) << "no time passed";
  // 30 results 40 ms apart after the two at t0, of a 25 fps file: the ring holds the last 30,
  // 29 intervals; the file plays in real time.
  Clock::time_point t = t0;
  double media = 0.0;
  for (int i = 0; i < 30; ++i) {
    t += milliseconds(40);
    media += 0.04;
    meter.result_at(t, media);
  }
  ASSERT_TRUE(meter.fps());
  EXPECT_NEAR(*meter.fps(), 25.0, 1e-9);
  EXPECT_NEAR(*meter.speed(), 1.0, 1e-9);
  // The window slides: 29 more 10 ms apart replace every old time but the newest.
  for (int i = 0; i < 28; ++i) {
    t += milliseconds(10);
    media += 0.01;
    meter.result_at(t, media);
  }
  EXPECT_NEAR(*meter.fps(), 29.0 / (0.040 + 28 * 0.010), 1e-9) << "one 40 ms interval left";
  t += milliseconds(10);
  media += 0.01;
  meter.result_at(t, media);
  EXPECT_NEAR(*meter.fps(), 100.0, 1e-9);
  // A 30 fps file (33.3 ms a frame) shown every 50 ms plays at two thirds of its speed.
  for (int i = 0; i < 30; ++i) {
    t += milliseconds(50);
    media += 1.0 / 30;
    meter.result_at(t, media);
  }
  EXPECT_NEAR(*meter.fps(), 20.0, 1e-9);
  EXPECT_NEAR(*meter.speed(), 2.0 / 3.0, 1e-9);
  meter.restart();  // A jump: no rate until two more results.
  EXPECT_FALSE(meter.fps());
  EXPECT_FALSE(meter.speed());

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

// The status and message lines never overlap, at the sizes the window shows a 1280x720 frame at
// (100 % and 74 %) and at VGA: rows are spaced by the outlined text's height (a fixed 22 px let
// them overlap once the text grew with the image), the last inside the image.
TEST(LiveView, StatusLinesAreSpacedByTheirHeightAndWrappedToTheImage) {
  const std::vector<std::string> lines = {
      "REC live-001  PAUSED  active: blue (zncc)  view 74%",
      "blue: reselected in [200, 180, 23, 22]"};
  for (const cv::Size size : {cv::Size(1280, 720), cv::Size(947, 533), cv::Size(640, 480)}) {
    double scale = 0;
    const std::vector<cv::Point> origins = PlaceStatusLines(size, lines.size(), &scale);
    ASSERT_EQ(origins.size(), 2u) << size;
    int baseline = 0;
    for (size_t i = 0; i < origins.size(); ++i) {
      const cv::Size text = cv::getTextSize(lines[i], cv::FONT_HERSHEY_SIMPLEX, scale, 4, &baseline);
      EXPECT_LE(origins[i].y + baseline, size.height) << size << " row " << i;
      if (i > 0) {
        // This row's top (origin - height) lies below the previous row's bottom (origin + baseline),
        // so the lines also come in their order, top to bottom.
        EXPECT_GT(origins[i].y - text.height, origins[i - 1].y + baseline)
            << size << " rows " << i - 1 << " and " << i << " overlap";
      }
    }
  }
}

// A long message is read whole: wrapped at spaces to the band's width, in the band under the
// image (the picture keeps every pixel, so no marker is covered). The timeline sits under the
// band, the chart under it.
TEST(LiveView, ALongMessageWrapsInTheBandUnderTheImageNeverOverIt) {
  const std::string message =
      "the box [100, 31, 32, 32] holds no marker (nothing at its centre stands out from its "
      "surroundings): drag it around a marker, with some background on every side";
  int baseline = 0;
  const std::vector<std::string> rows = WrapStatusLines({"PAUSED  active: red (sad)", message}, 320, 0.45);
  ASSERT_GE(rows.size(), 4u);
  std::string joined;
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_LE(cv::getTextSize(rows[i], cv::FONT_HERSHEY_SIMPLEX, 0.45, 1, &baseline).width, 320 - 16)
        << rows[i];
    joined += (i > 1 ? " " : "") + rows[i];
  }
  EXPECT_EQ(joined, message) << "wrapped at spaces, nothing lost";

  const cv::Mat frame(240, 320, CV_8UC3, cv::Scalar(100, 100, 100));
  const StripChart chart;
  Timeline timeline;
  timeline.set_length(100);
  timeline.set_position(50);
  LiveViewState state;
  state.frame = &frame;
  state.annotated = &frame;
  state.lines = {"PAUSED  active: red (sad)", message};
  state.chart = &chart;
  state.timeline = &timeline;
  const LiveLayout layout =
      ComputeLiveLayout(frame.size(), 180, 0, {}, StatusBandHeight(), /*timeline=*/true);
  EXPECT_EQ(layout.status, cv::Rect(0, 240, 320, StatusBandHeight()));
  EXPECT_EQ(layout.timeline, cv::Rect(0, 240 + StatusBandHeight(), 320, kTimelineHeightPx));
  EXPECT_EQ(layout.chart.y, layout.timeline.br().y);
  LiveView view;
  const cv::Mat canvas = view.compose(layout, state).clone();
  EXPECT_EQ(cv::norm(canvas(layout.image), frame, cv::NORM_INF), 0.0) << "nothing over the picture";
  cv::Mat band_text;
  cv::inRange(canvas(layout.status), cv::Scalar(200, 200, 200), cv::Scalar(255, 255, 255), band_text);
  EXPECT_GT(cv::countNonZero(band_text), 200) << "the lines are in the band";
  EXPECT_EQ(canvas.at<cv::Vec3b>(layout.timeline.y + 2, timeline.x_of(50, 320)), cv::Vec3b(255, 255, 255));
}

TEST(LiveView, TheFrameTheChartUnderItTheHelpBesideItAndTheDragBoxOrTheScalePoints) {
  const cv::Mat frame(240, 320, CV_8UC3, cv::Scalar(100, 100, 100));
  const StripChart chart;
  LiveViewState state;
  state.frame = &frame;
  state.annotated = &frame;
  state.lines = {"state line"};
  state.press = cv::Point2d(10, 10);
  state.pointer = cv::Point2d(50, 40);
  state.chart = &chart;
  const LiveLayout layout = ComputeLiveLayout(frame.size(), 180, HelpPanelWidth(), {});
  LiveView view;
  const cv::Mat canvas = view.compose(layout, state).clone();
  ASSERT_EQ(canvas.size(), layout.canvas);
  EXPECT_EQ(canvas.at<cv::Vec3b>(100, 100), cv::Vec3b(100, 100, 100));  // The frame, unscaled.
  EXPECT_EQ(canvas.at<cv::Vec3b>(10, 30), cv::Vec3b(0, 255, 0));         // The drag box's top.
  EXPECT_EQ(canvas.at<cv::Vec3b>(25, 50), cv::Vec3b(0, 255, 0));         // ... its right side.
  EXPECT_EQ(canvas.at<cv::Vec3b>(25, 30), cv::Vec3b(100, 100, 100));     // Not filled.
  ASSERT_FALSE(layout.help.empty());
  EXPECT_EQ(canvas.at<cv::Vec3b>(layout.help.y + 2, layout.help.x + 2), cv::Vec3b(24, 24, 24));
  EXPECT_EQ(layout.chart.y, 240);
  EXPECT_LT(cv::mean(canvas(layout.chart))[0], 70) << "the chart's dark background";

  // Scale mode: the first point's cross and the line to the pointer, no drag box.
  state.scale_mode = true;
  state.scale_points = {cv::Point2d(100, 60)};
  state.pointer = cv::Point2d(200, 60);
  const cv::Mat scaling = view.compose(layout, state);
  // Cyan, anti-aliased.
  const auto cyan = [](const cv::Vec3b& px) { return px[0] > 200 && px[1] > 200 && px[2] < 40; };
  EXPECT_TRUE(cyan(scaling.at<cv::Vec3b>(60, 150))) << "on the line";
  EXPECT_TRUE(cyan(scaling.at<cv::Vec3b>(54, 100))) << "the cross's upper arm";
  EXPECT_FALSE(cyan(scaling.at<cv::Vec3b>(80, 150)));
  EXPECT_EQ(scaling.at<cv::Vec3b>(10, 30), cv::Vec3b(100, 100, 100));  // No drag box.

  // No frame yet: a black image with a note, the chart still under it.
  const cv::Mat none;
  state.annotated = &none;
  const cv::Mat waiting = view.compose(layout, state);
  EXPECT_EQ(waiting.at<cv::Vec3b>(100, 300), cv::Vec3b(0, 0, 0));
}

}  // namespace
}  // namespace softsight
