// The textured bench and the marker distractors: look-alikes that stay off the actuator's path,
// and scenes with any number of markers.
#include <cmath>
#include <variant>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sim/actuator.h"
#include "softsight/core/error.h"
#include "softsight/sim/builtin_scenes.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

SceneOptions BenchScene() {
  SceneOptions o;
  o.size = cv::Size(320, 240);
  o.frame_count = 20;
  o.length_px = 150;
  o.width_px = 20;
  o.marker_radius_px = 6;
  o.background = BackgroundKind::kBench;
  return o;
}

// The distance from point p to the polygon's area (0 inside).
double DistanceToPolygon(const std::vector<cv::Point2d>& outline, const cv::Point2d& p) {
  std::vector<cv::Point2f> poly;
  for (const cv::Point2d& q : outline) poly.emplace_back(static_cast<float>(q.x), static_cast<float>(q.y));
  return std::max(0.0, -cv::pointPolygonTest(poly, cv::Point2f(p), true));
}

TEST(MarkerDistractorsTest, FullSetPerColourInFrameAndOffTheSweptArea) {
  for (SceneKind kind : {SceneKind::kBending, SceneKind::kWedge4}) {
    SceneOptions options = BenchScene();
    options.kind = kind;
    const std::vector<Distractor> distractors = MakeMarkerDistractors(options, 3);
    ASSERT_EQ(distractors.size(), 5 * options.markers.size()) << SceneKindName(kind);
    const double r = options.marker_radius_px;
    // Every marker colour has its larger, elongated, darker and wrong-size look-alikes.
    for (const SceneMarker& m : options.markers) {
      int same_colour = 0, darker = 0, small = 0, large = 0, elongated = 0;
      for (const Distractor& d : distractors) {
        if (d.bgr == m.bgr) {
          ++same_colour;
          if (d.radii_px.width < 0.7 * r) ++small;
          if (d.radii_px.height >= 1.5 * r) ++large;
          if (d.radii_px.width > 2 * d.radii_px.height) ++elongated;
        } else if (d.bgr[0] <= m.bgr[0] && d.bgr[1] <= m.bgr[1] && d.bgr[2] <= m.bgr[2] &&
                   std::abs(d.radii_px.width - r) < 1e-9) {
          ++darker;
        }
      }
      EXPECT_EQ(same_colour, 4) << m.name;
      EXPECT_EQ(darker, 1) << m.name;
      EXPECT_EQ(small, 1) << m.name;
      EXPECT_EQ(large, 2) << m.name;
      EXPECT_EQ(elongated, 1) << m.name;
    }
    // Inside the frame, apart from each other and from everything the actuator covers at any
    // bend (sampled finer than the placement did), by at least a marker radius.
    sim::ActuatorModel model(options);
    sim::ActuatorPose pose;
    for (size_t i = 0; i < distractors.size(); ++i) {
      const Distractor& d = distractors[i];
      const double extent = std::max(d.radii_px.width, d.radii_px.height);
      EXPECT_GE(d.centre_px.x - extent, 0.0);
      EXPECT_GE(d.centre_px.y - extent, 0.0);
      EXPECT_LE(d.centre_px.x + extent, options.size.width - 1.0);
      EXPECT_LE(d.centre_px.y + extent, options.size.height - 1.0);
      for (size_t j = 0; j < i; ++j) {
        const Distractor& e = distractors[j];
        EXPECT_GT(std::hypot(d.centre_px.x - e.centre_px.x, d.centre_px.y - e.centre_px.y),
                  extent + std::max(e.radii_px.width, e.radii_px.height) + r);
      }
    }
    for (int k = 0; k <= 500; ++k) {
      model.pose(model.max_bend_deg() * k / 500, &pose);
      for (const Distractor& d : distractors) {
        const double extent = std::max(d.radii_px.width, d.radii_px.height);
        for (const sim::ShapePolygon& shape : pose.shapes) {
          ASSERT_GT(DistanceToPolygon(shape.outline, d.centre_px), extent + r) << k;
        }
        for (const cv::Point2d& c : pose.marker_centres) {
          ASSERT_GT(std::hypot(c.x - d.centre_px.x, c.y - d.centre_px.y), extent + 2 * r) << k;
        }
      }
    }
  }
}

TEST(MarkerDistractorsTest, DeterministicBySeed) {
  const SceneOptions options = BenchScene();
  const std::vector<Distractor> a = MakeMarkerDistractors(options, 5);
  const std::vector<Distractor> b = MakeMarkerDistractors(options, 5);
  const std::vector<Distractor> c = MakeMarkerDistractors(options, 6);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  double moved = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].centre_px, b[i].centre_px);
    EXPECT_EQ(a[i].angle_deg, b[i].angle_deg);
    moved += std::hypot(a[i].centre_px.x - c[i].centre_px.x, a[i].centre_px.y - c[i].centre_px.y);
  }
  EXPECT_GT(moved / a.size(), 5.0);
}

// A frame with little room keeps what fits, never overlapping the actuator.
TEST(MarkerDistractorsTest, CrampedFrameGetsFewerNotWrongOnes) {
  SceneOptions options = BenchScene();
  options.size = cv::Size(160, 205);
  const std::vector<Distractor> distractors = MakeMarkerDistractors(options, 1);
  EXPECT_LT(distractors.size(), 5 * options.markers.size());
}

// Drawn distractors are where they were asked to be: the rendered colour's centroid is the
// ellipse's centre, and the actuator is drawn over the backdrop, not under it.
TEST(MarkerDistractorsTest, RenderedAtTheirPlaceBehindTheActuator) {
  SceneOptions options = BenchScene();
  options.markers.clear();
  options.background = BackgroundKind::kDefault;
  SyntheticScene plain(options);
  options.distractors = {{{40.3, 50.7}, {12.0, 5.0}, 30.0, {0, 0, 255}}};
  SyntheticScene with(options);
  cv::Mat a, b;
  plain.render(0, a);
  with.render(0, b);
  // Where the distractor is, the red channel moves towards 255; its excess weighs the area.
  cv::Mat diff;
  cv::Mat channels_a[3], channels_b[3];
  cv::split(a, channels_a);
  cv::split(b, channels_b);
  cv::Mat1d excess;
  cv::subtract(channels_b[2], channels_a[2], excess, cv::noArray(), CV_64F);
  cv::Mat1d full = 255.0 - cv::Mat1d(channels_a[2]);
  cv::Mat1d weight = excess / cv::max(full, 1.0);
  const cv::Moments mom = cv::moments(weight);
  EXPECT_NEAR(mom.m10 / mom.m00, 40.3, 0.02);
  EXPECT_NEAR(mom.m01 / mom.m00, 50.7, 0.02);
  EXPECT_NEAR(mom.m00, CV_PI * 12 * 5, 0.5);
  EXPECT_EQ(cv::norm(a(cv::Rect(100, 0, 220, 240)), b(cv::Rect(100, 0, 220, 240)), cv::NORM_INF), 0);
}

// The bench has patches of marker-like saturation (what makes it hard) and is deterministic.
TEST(BenchBackgroundTest, TexturedSaturatedPatchesDeterministic) {
  SceneOptions options = BenchScene();
  options.markers.clear();
  cv::Mat a, b, c;
  SyntheticScene(options).render(0, a);
  SyntheticScene(options).render(0, b);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
  options.seed = 2;
  SyntheticScene(options).render(0, c);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1) / a.total(), 5.0);
  for (const cv::Mat* image : {&a, &c}) {
    cv::Mat hsv;
    cv::cvtColor(*image, hsv, cv::COLOR_BGR2HSV);
    cv::Mat channels[3];
    cv::split(hsv, channels);
    const double saturated = cv::countNonZero(channels[1] >= 100) / double(image->total());
    EXPECT_GT(saturated, 0.01);
    cv::Scalar mean, stddev;
    cv::meanStdDev(channels[2], mean, stddev);
    EXPECT_GT(stddev[0], 10.0);
  }
}

// The bench is the trap it is meant to be: with the thresholds a person picks for a marker
// colour (hue +-12, saturation >= 80, value >= 40, as in the README), the marker is one of
// several blobs and not the largest, so "the largest blob of the colour" is wrong.
TEST(BenchBackgroundTest, MarkersAreNotTheLargestBlobsOfTheirColour) {
  SceneOptions options = BenchScene();
  options.distractors = MakeMarkerDistractors(options, 1);
  SyntheticScene scene(options);
  cv::Mat image, hsv;
  const SceneTruth truth = scene.render(0, image);
  cv::cvtColor(image, hsv, cv::COLOR_BGR2HSV);
  const double marker_area = CV_PI * options.marker_radius_px * options.marker_radius_px;
  for (size_t i = 0; i < options.markers.size(); ++i) {
    cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar(cv::Vec3b(options.markers[i].bgr))), pixel_hsv;
    cv::cvtColor(pixel, pixel_hsv, cv::COLOR_BGR2HSV);
    const int hue = pixel_hsv.at<cv::Vec3b>(0, 0)[0];
    cv::Mat mask = cv::Mat::zeros(hsv.size(), CV_8U), part;
    for (int shift : {-180, 0, 180}) {
      cv::inRange(hsv, cv::Scalar(hue - 12 + shift, 80, 40), cv::Scalar(hue + 12 + shift, 255, 255), part);
      mask |= part;
    }
    cv::Mat labels, stats, centroids;
    const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
    const cv::Point2d c = *truth.markers[i].centroid_px;
    const int marker_label = labels.at<int>(cvRound(c.y), cvRound(c.x));
    ASSERT_GT(marker_label, 0) << options.markers[i].name;
    int blobs = 0, larger = 0;
    for (int k = 1; k < count; ++k) {
      const int area = stats.at<int>(k, cv::CC_STAT_AREA);
      if (area < 0.2 * marker_area) continue;
      ++blobs;
      larger += area > stats.at<int>(marker_label, cv::CC_STAT_AREA);
    }
    EXPECT_GE(blobs, 5) << options.markers[i].name;
    EXPECT_GE(larger, 2) << options.markers[i].name;
  }
}

// One, two and five markers render with their own colours, and their truth is each disc's
// centre; the triple is measured only from three markers on.
TEST(MarkerCountTest, OneTwoAndFiveMarkers) {
  const cv::Vec3b colours[] = {{40, 40, 220}, {220, 90, 40}, {60, 200, 60}, {40, 200, 220}, {200, 60, 200}};
  for (int count : {1, 2, 5}) {
    SceneOptions options = BenchScene();
    options.markers.clear();
    for (int i = 0; i < count; ++i) {
      std::string name = "m";
      name += std::to_string(i);
      options.markers.push_back({name, colours[i],
                                 count == 1 ? 0.9 : 0.1 + 0.8 * i / (count - 1)});
    }
    options.distractors = MakeMarkerDistractors(options, 1);
    EXPECT_EQ(options.distractors.size(), 5u * count);
    const MeasureOptions measure = SceneMeasureOptions(options);
    if (count < 3) {
      EXPECT_TRUE(measure.base.empty() && measure.middle.empty() && measure.tip.empty());
      EXPECT_TRUE(measure.chain.empty());
    } else {
      EXPECT_EQ(measure.base, "m0");
      EXPECT_EQ(measure.middle, "m2");
      EXPECT_EQ(measure.tip, "m4");
      EXPECT_EQ(measure.chain.size(), 5u);
    }
    SyntheticScene scene(options);
    sim::ActuatorModel model(options);
    sim::ActuatorPose pose;
    cv::Mat image;
    for (int f : {0, 10, 19}) {
      const SceneTruth truth = scene.render(f, image);
      model.pose(truth.bend_deg, &pose);
      ASSERT_EQ(truth.markers.size(), static_cast<size_t>(count));
      for (int i = 0; i < count; ++i) {
        ASSERT_TRUE(truth.markers[i].centroid_px.has_value());
        const cv::Point2d c = *truth.markers[i].centroid_px;
        EXPECT_LT(std::hypot(c.x - pose.marker_centres[i].x, c.y - pose.marker_centres[i].y), 0.005);
        // The pixel at the disc's centre carries the marker's colour.
        EXPECT_EQ(image.at<cv::Vec3b>(cvRound(c.y), cvRound(c.x)), colours[i]);
      }
      if (count >= 3) {
        EXPECT_TRUE(truth.measurement.angle_deg.has_value());
      }
    }
  }
}

TEST(SceneOptionsTest, DistractorsAreChecked) {
  SceneOptions options = BenchScene();
  std::string error;
  options.distractors = {{{10, 10}, {0, 3}, 0, {0, 0, 255}}};
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("distractors"), std::string::npos) << error;
  options.distractors = {{{NAN, 10}, {2, 3}, 0, {0, 0, 255}}};
  EXPECT_FALSE(options.Check(&error));
  options.distractors = {{{10, 10}, {2, 3}, 0, {0, 0, 255}}};
  EXPECT_TRUE(options.Check(&error)) << error;
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

TEST(BuiltinScenesTest, NamesGiveTheirScenes) {
  EXPECT_TRUE(std::holds_alternative<PlateSceneOptions>(ParseBuiltinScene("plate")));
  const SceneOptions bench = std::get<SceneOptions>(ParseBuiltinScene("bench"));
  EXPECT_EQ(bench.kind, SceneKind::kBending);
  EXPECT_EQ(bench.background, BackgroundKind::kBench);
  EXPECT_EQ(bench.distractors.size(), 5 * bench.markers.size());
  const SceneOptions wedge = std::get<SceneOptions>(ParseBuiltinScene("wedge4"));
  EXPECT_EQ(wedge.kind, SceneKind::kWedge4);
  EXPECT_EQ(wedge.background, BackgroundKind::kDefault);
  EXPECT_TRUE(wedge.distractors.empty());
  try {
    ParseBuiltinScene("spiral");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("spiral"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("plate"), std::string::npos);
  }
}

// The bench on top of a run's own size and body: distractors fit that scene.
TEST(BuiltinScenesTest, SetActuatorSceneKeepsTheRest) {
  SceneOptions scene = BenchScene();
  scene.background = BackgroundKind::kDefault;
  SetActuatorScene("bench", &scene);
  EXPECT_EQ(scene.size, cv::Size(320, 240));
  EXPECT_EQ(scene.background, BackgroundKind::kBench);
  ASSERT_EQ(scene.distractors.size(), 15u);
  for (const Distractor& d : scene.distractors) {
    EXPECT_LT(d.centre_px.x, 320);
    EXPECT_LT(d.centre_px.y, 240);
  }
  EXPECT_THROW(SetActuatorScene("plate", &scene), InputError);
}

}  // namespace
}  // namespace softsight
