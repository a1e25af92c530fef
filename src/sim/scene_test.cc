#include "softsight/sim/scene.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sim/actuator.h"
#include "sim/raster.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {


// Small images and few frames keep the suite fast; the geometry scales with the options.
SceneOptions SmallScene(SceneKind kind = SceneKind::kBending) {
  SceneOptions o;
  o.kind = kind;
  o.size = cv::Size(320, 240);
  o.frame_count = 40;
  o.length_px = 150;
  o.width_px = 20;
  o.marker_radius_px = 6;
  return o;
}

const MarkerTruth& Marker(const SceneTruth& truth, const std::string& name) {
  for (const MarkerTruth& m : truth.markers) {
    if (m.name == name) return m;
  }
  ADD_FAILURE() << "no marker " << name;
  return truth.markers.front();
}

double Distance(const cv::Point2d& a, const cv::Point2d& b) { return std::hypot(a.x - b.x, a.y - b.y); }

// The truth centroid of every unoccluded marker is the analytic disc centre of the actuator
// model, for every kind and over the whole motion.
TEST(SyntheticSceneTest, UnoccludedCentroidIsTheDiscCentre) {
  for (SceneKind kind : {SceneKind::kBending, SceneKind::kWedge1, SceneKind::kWedge4}) {
    const SceneOptions options = SmallScene(kind);
    SyntheticScene scene(options);
    sim::ActuatorModel model(options);
    sim::ActuatorPose pose;
    cv::Mat image;
    double worst_px = 0;
    for (int i = 0; i < options.frame_count; i += 3) {
      const SceneTruth truth = scene.render(i, image);
      model.pose(truth.bend_deg, &pose);
      ASSERT_EQ(truth.markers.size(), options.markers.size());
      for (size_t m = 0; m < truth.markers.size(); ++m) {
        ASSERT_TRUE(truth.markers[m].centroid_px.has_value());
        EXPECT_DOUBLE_EQ(truth.markers[m].visible_fraction, 1.0);
        worst_px = std::max(worst_px, Distance(*truth.markers[m].centroid_px, pose.marker_centres[m]));
      }
    }
    EXPECT_LT(worst_px, 0.005) << SceneKindName(kind);
  }
}

// The model itself is the constant-curvature arc: marker-to-marker distances are the chords
// 2 R sin(k ds / 2), and the markers lie on a circle of the centre-line radius.
TEST(SyntheticSceneTest, BendingMarkersLieOnTheCentreLineArc) {
  SceneOptions options = SmallScene();
  SyntheticScene scene(options);
  cv::Mat image;
  for (double bend : {30.0, 90.0, 180.0, 240.0}) {
    const SceneTruth truth = scene.render_at_bend(bend, 0.0, 0, image);
    ASSERT_TRUE(truth.centreline_radius_px.has_value());
    const double k = bend * std::numbers::pi / 180 / options.length_px;
    EXPECT_NEAR(*truth.centreline_radius_px, 1 / k, 1e-9);
    for (size_t a = 0; a < 3; ++a) {
      for (size_t b = a + 1; b < 3; ++b) {
        const double ds = (options.markers[b].body_fraction - options.markers[a].body_fraction) *
                          options.length_px;
        EXPECT_NEAR(Distance(*truth.markers[a].centroid_px, *truth.markers[b].centroid_px),
                    2 / k * std::sin(k * ds / 2), 0.01)
            << "bend " << bend;
      }
    }
  }
}

TEST(SyntheticSceneTest, StraightActuatorMeasuresHalfTurnAngle) {
  const SceneOptions options = SmallScene();
  SyntheticScene scene(options);
  cv::Mat image;
  const SceneTruth truth = scene.render(0, image);
  EXPECT_EQ(truth.bend_deg, 0.0);
  EXPECT_FALSE(truth.centreline_radius_px.has_value());
  ASSERT_TRUE(truth.measurement.angle_deg.has_value());
  EXPECT_NEAR(*truth.measurement.angle_deg, 180.0, 0.01);
  ASSERT_TRUE(truth.measurement.chord_px.has_value());
  EXPECT_NEAR(*truth.measurement.chord_px, 0.8 * options.length_px, 0.01);
  ASSERT_TRUE(truth.measurement.sagitta_px.has_value());
  EXPECT_LT(*truth.measurement.sagitta_px, 0.01);
  // The reference of the bending distance is the rest pose.
  ASSERT_TRUE(truth.measurement.tip_disp_px.has_value());
  EXPECT_LT(*truth.measurement.tip_disp_px, 0.01);
}

// At a half circle the triple spans 0.8 * 180 degrees of arc: eq. 8 and 9 give back the radius
// and arc length of the centre line.
TEST(SyntheticSceneTest, HalfCircleMeasurementMatchesTheArc) {
  const SceneOptions options = SmallScene();
  SyntheticScene scene(options);
  cv::Mat image;
  const SceneTruth truth = scene.render_at_bend(180.0, 1.0, 0, image);
  const double radius = options.length_px / std::numbers::pi;
  ASSERT_TRUE(truth.measurement.radius_px.has_value());
  EXPECT_NEAR(*truth.measurement.radius_px, radius, 0.02);
  ASSERT_TRUE(truth.measurement.arc_length_px.has_value());
  EXPECT_NEAR(*truth.measurement.arc_length_px, 0.8 * options.length_px, 0.03);
  // The angle at the middle marker of a circle: 180 - half the arc the triple spans.
  ASSERT_TRUE(truth.measurement.angle_deg.has_value());
  EXPECT_NEAR(*truth.measurement.angle_deg, 180.0 - 0.8 * 180.0 / 2, 0.01);
  EXPECT_EQ(truth.time_s, 1.0);
}

TEST(SyntheticSceneTest, HalfOccludedMarkerShiftsAwayFromTheOccluder) {
  const SceneOptions options = SmallScene();
  SyntheticScene clear(options);
  cv::Mat image;
  const cv::Point2d centre = *Marker(clear.render(10, image), "blue").centroid_px;
  // Its left edge (at x - 0.5) runs through the disc centre: it hides the right half.
  const Occluder right_half{cv::Rect2d(centre.x + 0.5, centre.y - 20, 40, 40), 10, 10};
  SyntheticScene occluded(options, {}, {}, {right_half});
  const SceneTruth truth = occluded.render(10, image);
  const MarkerTruth& blue = Marker(truth, "blue");
  ASSERT_TRUE(blue.centroid_px.has_value());
  EXPECT_NEAR(blue.visible_fraction, 0.5, 0.02);
  // A half disc's centroid lies 4 r / (3 pi) from the centre.
  const double shift = 4 * options.marker_radius_px / (3 * std::numbers::pi);
  EXPECT_NEAR(blue.centroid_px->x, centre.x - shift, 0.1);
  EXPECT_NEAR(blue.centroid_px->y, centre.y, 0.02);
  // The occluder is active only in its frame range.
  const SceneTruth later = occluded.render(11, image);
  EXPECT_DOUBLE_EQ(Marker(later, "blue").visible_fraction, 1.0);
}

TEST(SyntheticSceneTest, FullyOccludedMarkerIsAbsent) {
  const SceneOptions options = SmallScene();
  SyntheticScene clear(options);
  cv::Mat image;
  const cv::Point2d tip = *Marker(clear.render(5, image), "green").centroid_px;
  const cv::Vec3b grey(90, 90, 90);
  SyntheticScene occluded(options, {}, {},
                          {Occluder{cv::Rect2d(tip.x - 15, tip.y - 15, 30, 30), 0, 20, grey}});
  const SceneTruth truth = occluded.render(5, image);
  const MarkerTruth& green = Marker(truth, "green");
  EXPECT_FALSE(green.centroid_px.has_value());
  EXPECT_EQ(green.visible_fraction, 0.0);
  EXPECT_FALSE(truth.measurement.angle_deg.has_value());
  EXPECT_TRUE(Marker(truth, "red").centroid_px.has_value());
  // The occluder is drawn: the tip's pixel shows its colour.
  EXPECT_EQ(image.at<cv::Vec3b>(cvRound(tip.y), cvRound(tip.x)), grey);
}

// A marker drawn later covers an earlier one; the covered marker's truth excludes the overlap.
TEST(SyntheticSceneTest, OverlappingMarkersCountOnlyTheVisiblePart) {
  SceneOptions options = SmallScene();
  options.markers = {{"red", {40, 40, 220}, 0.50}, {"blue", {220, 90, 40}, 0.54},
                     {"green", {60, 200, 60}, 0.9}};
  SyntheticScene scene(options);
  cv::Mat image;
  const SceneTruth truth = scene.render(0, image);  // Straight: blue is 6 px above red.
  const MarkerTruth& red = Marker(truth, "red");
  const MarkerTruth& blue = Marker(truth, "blue");
  EXPECT_DOUBLE_EQ(blue.visible_fraction, 1.0);
  EXPECT_GT(red.visible_fraction, 0.2);
  EXPECT_LT(red.visible_fraction, 0.8);
  // Red is seen below its centre, away from blue (y grows downwards).
  EXPECT_GT(red.centroid_px->y - blue.centroid_px->y, 6.0 + 1.0);
}

TEST(SyntheticSceneTest, BendProfileSweepsTheWholeRange) {
  for (SceneKind kind : {SceneKind::kBending, SceneKind::kWedge1, SceneKind::kWedge4}) {
    SceneOptions options = SmallScene(kind);
    SyntheticScene scene(options);
    const double expected_max = kind == SceneKind::kBending ? options.max_bend_deg
                                : kind == SceneKind::kWedge1 ? 20.0
                                                             : 80.0;
    EXPECT_EQ(scene.max_bend_deg(), expected_max);
    EXPECT_EQ(scene.bend_at(0), 0.0);
    EXPECT_NEAR(scene.bend_at(options.frame_count - 1), expected_max, 1e-9);
    for (int i = 1; i < options.frame_count; ++i) EXPECT_GT(scene.bend_at(i), scene.bend_at(i - 1));
  }
  SceneOptions options = SmallScene();
  options.oscillate = true;
  options.oscillate_cycles = 2;
  options.frame_count = 41;
  SyntheticScene scene(options);
  EXPECT_NEAR(scene.bend_at(10), options.max_bend_deg, 1e-9);
  EXPECT_NEAR(scene.bend_at(20), 0.0, 1e-9);
  EXPECT_NEAR(scene.bend_at(30), options.max_bend_deg, 1e-9);
  EXPECT_NEAR(scene.bend_at(40), 0.0, 1e-9);
  // render_at_bend clamps to the physical range and reports what it drew.
  cv::Mat image;
  EXPECT_EQ(scene.render_at_bend(400.0, 0.0, 0, image).bend_deg, options.max_bend_deg);
  EXPECT_EQ(scene.render_at_bend(-5.0, 0.0, 0, image).bend_deg, 0.0);
}

// Over the full motion the actuator (body, clamp and markers) stays inside the image, and the
// default 640x480 scene fits the default body.
TEST(SyntheticSceneTest, ActuatorStaysInsideTheImage) {
  for (SceneKind kind : {SceneKind::kBending, SceneKind::kWedge1, SceneKind::kWedge4}) {
    for (const SceneOptions& options : {SmallScene(kind), SceneOptions{.kind = kind}}) {
      sim::ActuatorModel model(options);
      sim::ActuatorPose pose;
      const cv::Rect2d image(-0.5, -0.5, options.size.width, options.size.height);
      for (int i = 0; i <= 300; ++i) {
        model.pose(model.max_bend_deg() * i / 300, &pose);
        EXPECT_EQ(pose.bounds & image, pose.bounds) << SceneKindName(kind) << " step " << i;
      }
    }
  }
  SceneOptions too_long = SmallScene();
  too_long.length_px = 400;
  too_long.width_px = 10;
  EXPECT_THROW(SyntheticScene{too_long}, InputError);
}

TEST(SyntheticSceneTest, NoiseHasTheRequestedSigma) {
  const SceneOptions options = SmallScene();
  NoiseOptions noisy;
  noisy.sigma = 5.0;
  // A flat grey patch (an occluder) in a corner, away from the actuator.
  const cv::Rect patch(4, 4, 60, 60);
  const std::vector<Occluder> flat = {Occluder{cv::Rect2d(patch), 0, 100, {128, 128, 128}}};
  SyntheticScene clean_scene(options, {}, {}, flat);
  SyntheticScene noisy_scene(options, noisy, {}, flat);
  cv::Mat clean, image;
  clean_scene.render(3, clean);
  noisy_scene.render(3, image);
  cv::Scalar mean, stddev;
  cv::meanStdDev(clean(patch).reshape(1), mean, stddev);
  ASSERT_EQ(stddev[0], 0.0);  // Really flat without noise.
  cv::meanStdDev(image(patch).reshape(1), mean, stddev);
  EXPECT_NEAR(mean[0], 128.0, 0.3);
  EXPECT_NEAR(stddev[0], 5.0, 0.15);
  // Everywhere else the noise is the same: the difference to the clean frame.
  cv::Mat diff3;
  cv::subtract(image, clean, diff3, cv::noArray(), CV_32F);
  cv::meanStdDev(diff3.reshape(1), mean, stddev);
  EXPECT_NEAR(mean[0], 0.0, 0.05);
  EXPECT_NEAR(stddev[0], 5.0, 0.1);
  // Another frame gets other noise; the same frame rendered again the same noise.
  cv::Mat other, diff4;
  noisy_scene.render(4, other);
  clean_scene.render(4, clean);
  cv::subtract(other, clean, diff4, cv::noArray(), CV_32F);
  EXPECT_GT(cv::norm(diff3, diff4, cv::NORM_L1) / diff3.total(), 5.0);
  cv::Mat again;
  noisy_scene.render(3, again);
  EXPECT_EQ(cv::norm(again, image, cv::NORM_INF), 0.0);
}

TEST(SyntheticSceneTest, GainRampScalesIntensities) {
  SceneOptions options = SmallScene();
  options.frame_count = 3;
  NoiseOptions ramp;
  ramp.gain_start = 0.5;
  ramp.gain_end = 1.0;
  SyntheticScene reference(options);
  SyntheticScene scene(options, ramp);
  cv::Mat ref, image;
  for (int i = 0; i < 3; ++i) {
    reference.render(i, ref);
    scene.render(i, image);
    const double gain = 0.5 + 0.25 * i;
    cv::Mat expected;
    ref.convertTo(expected, CV_32F, gain);
    cv::Mat got;
    image.convertTo(got, CV_32F);
    EXPECT_LE(cv::norm(got, expected, cv::NORM_INF), 0.5 + 1e-4) << "frame " << i;
  }
}

TEST(SyntheticSceneTest, BlurSoftensEdges) {
  const SceneOptions options = SmallScene();
  NoiseOptions blur;
  blur.blur_sigma_px = 1.5;
  SyntheticScene sharp_scene(options), blurred_scene(options, blur);
  cv::Mat sharp, blurred, lap;
  sharp_scene.render(5, sharp);
  blurred_scene.render(5, blurred);
  cv::Scalar m1, s1, m2, s2;
  cv::Laplacian(sharp, lap, CV_32F);
  cv::meanStdDev(lap.reshape(1), m1, s1);
  cv::Laplacian(blurred, lap, CV_32F);
  cv::meanStdDev(lap.reshape(1), m2, s2);
  EXPECT_LT(s2[0], 0.5 * s1[0]);
}

TEST(SyntheticSceneTest, SameSeedSameFramesOtherSeedOtherBackdrop) {
  const SceneOptions options = SmallScene();
  NoiseOptions noise;
  noise.sigma = 3;
  SyntheticScene a(options, noise), b(options, noise);
  cv::Mat ia, ib;
  a.render(7, ia);
  b.render(7, ib);
  EXPECT_EQ(cv::norm(ia, ib, cv::NORM_INF), 0.0);
  SceneOptions other = options;
  other.seed = 2;
  SyntheticScene c(other);
  SyntheticScene d(options);
  d.render(7, ia);
  c.render(7, ib);
  EXPECT_GT(cv::norm(ia, ib, cv::NORM_L1) / ia.total(), 5.0);
}

// The backdrop carries texture but no colour a marker threshold (saturation >= 80) could take.
TEST(SyntheticSceneTest, BackdropIsTexturedAndLowSaturation) {
  SceneOptions options = SmallScene();
  options.markers.clear();
  for (uint64_t seed : {1u, 2u, 3u}) {
    options.seed = seed;
    SyntheticScene scene(options);
    cv::Mat image, hsv;
    scene.render(0, image);
    cv::cvtColor(image, hsv, cv::COLOR_BGR2HSV);
    std::vector<cv::Mat> channels;
    cv::split(hsv, channels);
    double min_s, max_s;
    cv::minMaxLoc(channels[1], &min_s, &max_s);
    EXPECT_LT(max_s, 80) << "seed " << seed;
    cv::Scalar mean, stddev;
    cv::meanStdDev(channels[2], mean, stddev);
    EXPECT_GT(stddev[0], 8.0) << "seed " << seed;
  }
}

// The pixel convention: a supersampled disc's centroid, mapped to output pixels, is the disc
// centre, and the area-averaged output image has its intensity centroid at the same place.
TEST(RasterTest, SupersampledCentroidMapsToOutputPixels) {
  constexpr int kS = 4;
  cv::RNG rng(11);
  double worst_truth = 0, worst_image = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const cv::Point2d centre(rng.uniform(12.0, 28.0), rng.uniform(12.0, 28.0));
    const double radius = rng.uniform(4.0, 10.0);
    cv::Mat canvas(40 * kS, 40 * kS, CV_8UC3, cv::Scalar::all(0));
    sim::FillDisc(sim::ToSupersampled(centre, kS), radius * kS, cv::Point(0, 0),
                  cv::Vec3b(255, 255, 255), canvas);
    cv::Mat small, gray, ss_gray;
    cv::resize(canvas, small, cv::Size(40, 40), 0, 0, cv::INTER_AREA);
    cv::extractChannel(small, gray, 0);
    cv::extractChannel(canvas, ss_gray, 0);
    const cv::Moments ss = cv::moments(ss_gray, false);
    const cv::Moments out = cv::moments(gray, false);
    const cv::Point2d drawn(sim::FromSupersampled(ss.m10 / ss.m00, kS),
                            sim::FromSupersampled(ss.m01 / ss.m00, kS));
    worst_truth = std::max(worst_truth, Distance(drawn, centre));
    worst_image = std::max(worst_image, Distance(cv::Point2d(out.m10 / out.m00, out.m01 / out.m00), drawn));
  }
  EXPECT_LT(worst_truth, 0.005);
  // Only the 8-bit rounding of the averaged edge pixels separates the two.
  EXPECT_LT(worst_image, 0.01);
}

TEST(RasterTest, SupersampledRectCoversWholePixels) {
  EXPECT_EQ(sim::SupersampledRect(cv::Rect2d(10, 20, 5, 3), 4), cv::Rect(40, 80, 20, 12));
  EXPECT_EQ(sim::SupersampledRect(cv::Rect2d(10, 20, 5, 3), 1), cv::Rect(10, 20, 5, 3));
  // Half a pixel: two of the four sub-columns.
  EXPECT_EQ(sim::SupersampledRect(cv::Rect2d(10.5, 0, 1, 1), 4), cv::Rect(42, 0, 4, 4));
  EXPECT_TRUE(sim::SupersampledRect(cv::Rect2d(10, 0, 0.1, 1), 4).empty());
}

TEST(SceneOptionsTest, CheckNamesTheBadField) {
  std::string error;
  SceneOptions o;
  EXPECT_TRUE(o.Check(&error)) << error;
  o.frame_count = 0;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("frame_count"), std::string::npos) << error;
  o = SceneOptions{};
  o.max_bend_deg = 400;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("max_bend_deg"), std::string::npos) << error;
  o = SceneOptions{};
  o.width_px = 250;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("width_px"), std::string::npos) << error;
  o = SceneOptions{};
  o.markers.push_back(o.markers.front());
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("used twice"), std::string::npos) << error;
  NoiseOptions n;
  n.sigma = -1;
  EXPECT_FALSE(n.Check(&error));
  EXPECT_NE(error.find("sigma"), std::string::npos) << error;
  n = NoiseOptions{};
  n.gain_end = 0;
  EXPECT_FALSE(n.Check(&error));
  EXPECT_NE(error.find("gain_end"), std::string::npos) << error;
  RenderOptions r;
  r.supersample = 0;
  EXPECT_FALSE(r.Check(&error));
  EXPECT_NE(error.find("supersample"), std::string::npos) << error;

  SceneOptions zero_frames;
  zero_frames.frame_count = 0;
  EXPECT_THROW(SyntheticScene{zero_frames}, InputError);
  EXPECT_THROW(SyntheticScene(SceneOptions{}, {}, {},
                              {Occluder{cv::Rect2d(0, 0, 10, 10), 5, 2}}),
               InputError);
}

TEST(SceneOptionsTest, SceneKindNamesRoundTrip) {
  for (SceneKind kind : {SceneKind::kBending, SceneKind::kWedge1, SceneKind::kWedge4}) {
    EXPECT_EQ(ParseSceneKind(SceneKindName(kind)), kind);
  }
  try {
    ParseSceneKind("spiral");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("spiral"), std::string::npos);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace softsight
