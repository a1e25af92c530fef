#include "gui/overlay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "gui/strip_chart.h"

namespace softsight {
namespace {

// A status with a frame rate and a latency, nothing else.
OverlayStatus Status(double fps, double latency_ms) {
  OverlayStatus status;
  status.fps = fps;
  status.latency_ms = latency_ms;
  return status;
}


bool IsColour(const cv::Mat& image, cv::Point2d p, const cv::Scalar& bgr, int tolerance = 50) {
  const int x = cvRound(p.x), y = cvRound(p.y);
  if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) return false;
  const cv::Vec3b px = image.at<cv::Vec3b>(y, x);
  return std::abs(px[0] - bgr[0]) <= tolerance && std::abs(px[1] - bgr[1]) <= tolerance &&
         std::abs(px[2] - bgr[2]) <= tolerance;
}

bool ColourWithin(const cv::Mat& image, cv::Point2d p, const cv::Scalar& bgr, int radius) {
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      if (IsColour(image, p + cv::Point2d(dx, dy), bgr)) return true;
    }
  }
  return false;
}

int CountColour(const cv::Mat& image, const cv::Scalar& bgr, int tolerance = 50) {
  int n = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x)
      n += IsColour(image, {double(x), double(y)}, bgr, tolerance);
  }
  return n;
}

cv::Point2d OnCircle(cv::Point2d centre, double r, double deg) {
  return centre + r * cv::Point2d(std::cos(deg * CV_PI / 180), std::sin(deg * CV_PI / 180));
}

double MinDistance(const std::vector<cv::Point2d>& points, cv::Point2d p) {
  double best = 1e9;
  for (const auto& q : points) best = std::min(best, std::hypot(q.x - p.x, q.y - p.y));
  return best;
}

TEST(ArcPointsTest, MinorArcRunsFromBaseToTipThroughTheMiddle) {
  const cv::Point2d centre(100, 100);
  const double r = 50;
  const cv::Point2d base = OnCircle(centre, r, 200), tip = OnCircle(centre, r, 340);
  const cv::Point2d middle = OnCircle(centre, r, 270);
  const auto arc = ArcPoints(base, middle, tip, r, 64);
  ASSERT_EQ(arc.size(), 64u);
  EXPECT_NEAR(cv::norm(arc.front() - base), 0, 1e-9);
  EXPECT_NEAR(cv::norm(arc.back() - tip), 0, 1e-9);
  for (const auto& p : arc) EXPECT_NEAR(cv::norm(p - centre), r, 1e-9);
  EXPECT_LT(MinDistance(arc, middle), 1.5);  // 140 deg in 63 steps: 1.9 px apart.
  // Never on the far side of the circle.
  EXPECT_GT(MinDistance(arc, OnCircle(centre, r, 90)), 40);
}

TEST(ArcPointsTest, MajorArcWhenTheMiddleIsFartherThanTheRadius) {
  const cv::Point2d centre(200, 150);
  const double r = 40;
  const cv::Point2d base = OnCircle(centre, r, 60), tip = OnCircle(centre, r, 120);
  const cv::Point2d middle = OnCircle(centre, r, 270);  // Past a half circle.
  const auto arc = ArcPoints(base, middle, tip, r, 200);
  ASSERT_EQ(arc.size(), 200u);
  EXPECT_NEAR(cv::norm(arc.front() - base), 0, 1e-9);
  EXPECT_NEAR(cv::norm(arc.back() - tip), 0, 1e-9);
  for (const auto& p : arc) EXPECT_NEAR(cv::norm(p - centre), r, 1e-9);
  EXPECT_LT(MinDistance(arc, middle), 1.0);
  EXPECT_GT(MinDistance(arc, OnCircle(centre, r, 90)), 10);  // The gap between the ends.
}

TEST(ArcPointsTest, NoArcWhenItCannotBeDrawn) {
  EXPECT_TRUE(ArcPoints({0, 0}, {50, 0}, {100, 0}, 80).empty());   // Collinear.
  EXPECT_TRUE(ArcPoints({0, 0}, {50, 10}, {100, 0}, 30).empty());  // Radius < half chord.
  EXPECT_TRUE(ArcPoints({5, 5}, {5, 5}, {5, 5}, 30).empty());      // Coincident.
}

FrameResult ThreeMarkers(bool tip_found) {
  // Base, middle and tip on a circle of radius 80 around (160, 200).
  const cv::Point2d centre(160, 200);
  FrameResult result;
  result.frame_index = 7;
  result.time_s = 0.25;
  result.markers = {{"red", {OnCircle(centre, 80, 200), 1.0}},
                    {"blue", {OnCircle(centre, 80, 270), 1.0}},
                    {"green", {}}};
  if (tip_found) result.markers[2].observation.position_px = OnCircle(centre, 80, 340);
  result.measurement.angle_deg = 110.0;
  result.measurement.radius_px = 80.0;
  result.measurement.sagitta_px = 80.0 * (1 - std::cos(70 * CV_PI / 180));
  result.proc_ms = 1.25;
  return result;
}

OverlayOptions Triple() {
  MeasureOptions measure;
  measure.base = "red";
  measure.middle = "blue";
  measure.tip = "green";
  return OverlayOptionsFor(measure);
}

TEST(DrawOverlayTest, RingsAtFoundMarkersArcAndTriangleBetweenThem) {
  cv::Mat frame(320, 320, CV_8UC3, cv::Scalar(90, 90, 90));
  const FrameResult result = ThreeMarkers(true);
  DrawOverlay(frame, result, Triple(), Status(30.0, 12.0));
  for (const MarkerObservation& m : result.markers) {
    const cv::Point2d p = *m.observation.position_px;
    for (double deg = 0; deg < 360; deg += 30) {
      EXPECT_TRUE(ColourWithin(frame, OnCircle(p, 12, deg), overlay_colour::kMarker, 1))
          << m.name << " ring at " << deg;
    }
    // The centroid is marked by the cross.
    EXPECT_TRUE(IsColour(frame, p, overlay_colour::kMarker, 80)) << m.name;
  }
  // Arc through the three markers (away from the rings), and the triangle's chord base-tip.
  const cv::Point2d centre(160, 200);
  for (double deg : {225.0, 250.0, 290.0, 315.0}) {
    EXPECT_TRUE(ColourWithin(frame, OnCircle(centre, 80, deg), overlay_colour::kArc, 1)) << deg;
  }
  const cv::Point2d chord_mid =
      (*result.markers[0].observation.position_px + *result.markers[2].observation.position_px) / 2;
  EXPECT_TRUE(ColourWithin(frame, chord_mid, overlay_colour::kTriangle, 1));
  EXPECT_EQ(CountColour(frame, overlay_colour::kLost, 60), 0);  // Nobody lost.
}

// A template marker's box (the template's size, centred where it matched) and its method and
// score; colour markers get none.
TEST(DrawOverlayTest, TemplateMarkersShowTheirBoxAndScore) {
  cv::Mat frame(320, 320, CV_8UC3, cv::Scalar(90, 90, 90));
  FrameResult result = ThreeMarkers(true);
  result.markers[1].observation.score = 0.97;
  OverlayStatus status;
  status.template_boxes = {std::nullopt, OverlayStatus::TemplateBox{{30, 24}, "zncc"},
                           std::nullopt};
  DrawOverlay(frame, result, Triple(), status);
  const cv::Point2d p = *result.markers[1].observation.position_px;
  for (const cv::Point2d& edge : {p + cv::Point2d(-15, 0), p + cv::Point2d(15, 0),
                                  p + cv::Point2d(0, -12), p + cv::Point2d(0, 12)}) {
    EXPECT_TRUE(ColourWithin(frame, edge, overlay_colour::kTemplate, 1)) << edge;
  }
  // The label under the box.
  EXPECT_GT(CountColour(frame(cv::Rect(cvRound(p.x) - 16, cvRound(p.y) + 13, 60, 16)),
                        overlay_colour::kTemplate, 60),
            10);
  // Only the template marker has a box.
  int boxed = 0;
  for (const MarkerObservation& m : result.markers) {
    boxed += ColourWithin(frame, *m.observation.position_px + cv::Point2d(15, 0),
                          overlay_colour::kTemplate, 1);
  }
  EXPECT_EQ(boxed, 1);
}

TEST(DrawOverlayTest, LostMarkerIsFlaggedInRedAndNotDrawn) {
  cv::Mat frame(320, 320, CV_8UC3, cv::Scalar(90, 90, 90));
  const FrameResult result = ThreeMarkers(false);
  DrawOverlay(frame, result, Triple());
  EXPECT_GT(CountColour(frame, overlay_colour::kLost, 60), 30);  // "LOST: green".
  // No triangle and no arc without the tip; no ring where the tip would have been.
  const cv::Point2d centre(160, 200);
  for (double deg : {225.0, 250.0, 290.0, 315.0}) {
    EXPECT_FALSE(ColourWithin(frame, OnCircle(centre, 80, deg), overlay_colour::kArc, 2)) << deg;
  }
  EXPECT_FALSE(ColourWithin(frame, OnCircle(centre, 80, 340), overlay_colour::kMarker, 13));
}

TEST(DrawOverlayTest, AFoundMarkerNotBelievedIsCrossedOutInRedWithWhy) {
  // The stereo window: blue was found in this view but its pair failed the epipolar check.
  cv::Mat frame(320, 320, CV_8UC3, cv::Scalar(90, 90, 90));
  const FrameResult result = ThreeMarkers(true);
  OverlayStatus status;
  status.refused = {"", "epipolar"};  // Missing entries (green): believed.
  OverlayOptions options = Triple();
  options.show_measurements = false;
  DrawOverlay(frame, result, options, status);
  const cv::Point2d blue = *result.markers[1].observation.position_px;
  int yellow_ring = 0;
  for (double deg = 0; deg < 360; deg += 30) {
    yellow_ring += ColourWithin(frame, OnCircle(blue, 12, deg), overlay_colour::kMarker, 1);
    EXPECT_TRUE(ColourWithin(frame, OnCircle(blue, 12, deg), overlay_colour::kLost, 1)) << deg;
  }
  EXPECT_EQ(yellow_ring, 0) << "drawn as found";
  // The slanted cross through the centroid, and the reason beside it.
  EXPECT_TRUE(ColourWithin(frame, blue + cv::Point2d(5, 5), overlay_colour::kLost, 1));
  EXPECT_TRUE(ColourWithin(frame, blue + cv::Point2d(-5, 5), overlay_colour::kLost, 1));
  EXPECT_GT(CountColour(frame(cv::Rect(cvRound(blue.x) + 15, cvRound(blue.y) - 30, 120, 25)),
                        overlay_colour::kLost, 60),
            30);
  // The believed markers keep their yellow rings.
  for (int i : {0, 2}) {
    EXPECT_TRUE(ColourWithin(frame, OnCircle(*result.markers[i].observation.position_px, 12, 90),
                             overlay_colour::kMarker, 1));
  }
}

TEST(DrawOverlayTest, OptionsCheckNamesTheField) {
  OverlayOptions options;
  std::string error;
  EXPECT_TRUE(options.Check(&error));
  options.marker_ring_px = 0;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("marker_ring_px"), std::string::npos);
}

TEST(StripChartTest, CurvesScrollAndGapsStayGaps) {
  StripChart chart(StripChartOptions{.window_s = 10.0, .height_px = 240});
  for (int i = 0; i <= 600; ++i) {  // 20 s at 30 fps; the chart keeps the last 10 s.
    FrameResult r;
    r.time_s = i / 30.0;
    if (i < 450 || i > 480) r.measurement.angle_deg = 90.0 + 2.0 * r.time_s;  // Gap 15..16 s.
    r.measurement.tip_disp_px = 5.0;
    r.measurement.arc_length_px = 100.0 + r.time_s;
    // The radius: 60 px, then straight (a radius of 100 arc lengths: a gap) after 18 s.
    r.measurement.radius_px = i < 540 ? 60.0 : 100 * (100.0 + r.time_s);
    chart.add(r);
  }
  EXPECT_EQ(chart.size(), 301u);  // 10..20 s inclusive.
  cv::Mat area(240, 600, CV_8UC3);
  chart.draw(area);
  const auto& lane = chart.lane(0);
  auto y_of = [&](double v) {
    return lane.rect.y + (lane.y_max - v) / (lane.y_max - lane.y_min) * (lane.rect.height - 1);
  };
  EXPECT_LE(lane.y_min, 110.0);
  EXPECT_GE(lane.y_max, 130.0);
  for (double t : {11.0, 13.0, 17.5, 19.5}) {
    EXPECT_TRUE(ColourWithin(area, {chart.x_of(t), y_of(90.0 + 2 * t)}, StripChart::kColours[0], 1))
        << t;
  }
  // In the gap, the lane's column has no curve pixel.
  const int x = cvRound(chart.x_of(15.5));
  for (int y = lane.rect.y + 18; y < lane.rect.y + lane.rect.height; ++y) {
    ASSERT_FALSE(IsColour(area, {double(x), double(y)}, StripChart::kColours[0], 30)) << y;
  }
  // A constant lane (bending distance 5 px) still draws a flat line in the middle of its lane.
  const auto& flat = chart.lane(1);
  EXPECT_EQ(flat.label, "bending dist [px]");
  const double y_flat =
      flat.rect.y + (flat.y_max - 5.0) / (flat.y_max - flat.y_min) * (flat.rect.height - 1);
  EXPECT_TRUE(ColourWithin(area, {chart.x_of(12.0), y_flat}, StripChart::kColours[1], 1));
  // The radius lane: flat at 60 px, then a gap where it reads straight.
  const auto& radius = chart.lane(3);
  EXPECT_EQ(radius.label, "radius [px]");
  const double y_radius =
      radius.rect.y + (radius.y_max - 60.0) / (radius.y_max - radius.y_min) * (radius.rect.height - 1);
  // (The line sits between two pixel rows there: both are half its colour.)
  EXPECT_GT(CountColour(area(cv::Rect(cvRound(chart.x_of(12.0)) - 1, cvRound(y_radius) - 1, 3, 3)),
                        StripChart::kColours[3], 70),
            0);
  EXPECT_LT(radius.y_max, 100.0) << "a straight radius flattened the lane";
  EXPECT_FALSE(chart.newest(3).has_value());

  // The newest frame measured again (a paused re-track) replaces its sample.
  FrameResult again;
  again.time_s = 600 / 30.0;
  again.measurement.angle_deg = 116.9;
  chart.add(again);
  EXPECT_EQ(chart.size(), 301u);
  EXPECT_EQ(chart.newest(0), 116.9);
  EXPECT_FALSE(chart.newest(1).has_value());

  // Time going backwards (a new source) restarts the chart.
  FrameResult restart;
  restart.time_s = 0.0;
  chart.add(restart);
  EXPECT_EQ(chart.size(), 1u);
}

TEST(StripChartTest, ValueLabelsAreNotClippedWhateverTheirWidth) {
  // Wide labels: a five-digit arc length, a negative bending distance, angles near 180.
  StripChart chart(StripChartOptions{.window_s = 10.0, .height_px = 150});
  for (int i = 0; i < 50; ++i) {
    FrameResult result;
    result.time_s = i * 0.1;
    result.measurement.angle_deg = 179.0 + 0.02 * i;
    result.measurement.tip_disp_px = -1234.5 - 20.0 * i;
    result.measurement.arc_length_px = 12345.0 + 3.0 * i;
    chart.add(result);
  }
  cv::Mat area(150, 480, CV_8UC3);
  chart.draw(area);
  for (int lane = 0; lane < 3; ++lane) {
    const StripChart::Lane& l = chart.lane(lane);
    ASSERT_GE(l.tick_labels.size(), 1u) << l.label;
    for (const cv::Rect& text : l.tick_labels) {
      EXPECT_GE(text.x, 0) << l.label;
      EXPECT_LE(text.x + text.width, l.rect.x) << l.label;  // Left of the lane, not under it.
      EXPECT_GE(text.y, l.rect.y - 3) << l.label;           // Within its lane's rows.
      EXPECT_LE(text.y + text.height, l.rect.y + l.rect.height + 3) << l.label;
      EXPECT_LE(text.y + text.height, area.rows);
    }
  }
}

TEST(StripChartTest, LanesOfSeveralCurvesShareTheirAxis) {
  // The stereo window's chart: the 3D angle with each camera's, then the out-of-plane angle.
  const cv::Scalar a3d(255, 255, 255), left(0, 200, 0), right(200, 0, 200), tilt(0, 140, 255);
  StripChart chart(StripChartOptions{.window_s = 10.0, .height_px = 160},
                   {{"angle", "deg", {{"3D", a3d}, {"left", left}, {"right", right}}, false},
                    {"out of plane", "deg", {{"", tilt}}, false}});
  ASSERT_EQ(chart.lane_count(), 2);
  for (int i = 0; i < 60; ++i) {
    const double t = i / 10.0;
    // Each camera sees the bend foreshortened; the right camera lost a marker for 2..3 s.
    chart.add(t, {60.0 + 5 * t, 50.0 + 5 * t, (t >= 2 && t < 3) ? std::nullopt
                                                                  : std::optional(40.0 + 5 * t),
                  20.0 + 2 * t});
  }
  cv::Mat area(160, 500, CV_8UC3);
  chart.draw(area);
  EXPECT_EQ(chart.lane(0).label, "angle [deg]");
  EXPECT_EQ(chart.lane(1).label, "out of plane [deg]");
  // One axis for the three curves: all of them inside it.
  EXPECT_LE(chart.lane(0).y_min, 40.0);
  EXPECT_GE(chart.lane(0).y_max, 60.0 + 5 * 5.9);
  EXPECT_EQ(chart.newest(0), 60.0 + 5 * 5.9);
  EXPECT_EQ(chart.newest(3), 20.0 + 2 * 5.9);
  for (double t : {1.0, 4.0, 5.5}) {
    EXPECT_TRUE(ColourWithin(area, {chart.x_of(t), chart.y_of(0, 60.0 + 5 * t)}, a3d, 1)) << t;
    EXPECT_TRUE(ColourWithin(area, {chart.x_of(t), chart.y_of(0, 50.0 + 5 * t)}, left, 1)) << t;
    EXPECT_TRUE(ColourWithin(area, {chart.x_of(t), chart.y_of(0, 40.0 + 5 * t)}, right, 1)) << t;
    EXPECT_TRUE(ColourWithin(area, {chart.x_of(t), chart.y_of(1, 20.0 + 2 * t)}, tilt, 1)) << t;
  }
  // The right camera's gap stays a gap.
  EXPECT_FALSE(ColourWithin(area, {chart.x_of(2.5), chart.y_of(0, 40.0 + 5 * 2.5)}, right, 2));
}

TEST(DrawOverlayTest, TheTextNamesTheFrameAndItsTime) {
  // Two frames with identical measurements: only the frame line differs, in the text block.
  cv::Mat a(320, 320, CV_8UC3, cv::Scalar(90, 90, 90)), b = a.clone();
  FrameResult result = ThreeMarkers(true);
  DrawOverlay(a, result, Triple());
  result.frame_index = 8;
  result.time_s = 8 / 30.0;
  DrawOverlay(b, result, Triple());
  cv::Mat differs;
  cv::absdiff(a, b, differs);
  cv::cvtColor(differs, differs, cv::COLOR_BGR2GRAY);
  const cv::Rect where = cv::boundingRect(differs > 0);
  ASSERT_FALSE(where.empty());
  EXPECT_LT(where.y + where.height, 40);  // The first line of the text block.
}

TEST(DrawOverlayTest, ARadiusOfManyArcLengthsReadsStraight) {
  Measurement m;
  m.arc_length_px = 200.0;
  m.radius_px = 84178.0;  // What a nearly straight actuator gave.
  EXPECT_TRUE(ReadsStraight(m));
  m.radius_px = 25.0 * 200.0;
  EXPECT_TRUE(ReadsStraight(m));
  m.radius_px = 24.0 * 200.0;  // Bent by 2.4 deg: a radius worth showing.
  EXPECT_FALSE(ReadsStraight(m));
  m.radius_px.reset();
  EXPECT_FALSE(ReadsStraight(m));
}

}  // namespace
}  // namespace softsight
