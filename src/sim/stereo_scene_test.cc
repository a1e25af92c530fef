#include "softsight/sim/stereo_scene.h"

#include <cmath>

#include <gtest/gtest.h>

#include "softsight/core/error.h"

namespace softsight {
namespace {

// The centroid of `colour` painted over `under`: each pixel weighted by how much of it the
// colour covers, estimated on the channel where the two differ most.
cv::Point2d BlendCentroid(const cv::Mat& image, const cv::Vec3b& colour, const cv::Vec3b& under,
                          const cv::Point2d& near_px) {
  int channel = 0;
  for (int c = 1; c < 3; ++c) {
    if (std::abs(colour[c] - under[c]) > std::abs(colour[channel] - under[channel])) channel = c;
  }
  double sw = 0, sx = 0, sy = 0;
  for (int y = static_cast<int>(near_px.y) - 8; y <= static_cast<int>(near_px.y) + 8; ++y) {
    for (int x = static_cast<int>(near_px.x) - 8; x <= static_cast<int>(near_px.x) + 8; ++x) {
      const double w = (image.at<cv::Vec3b>(y, x)[channel] - under[channel]) /
                       static_cast<double>(colour[channel] - under[channel]);
      if (w <= 0.02) continue;
      sw += w;
      sx += w * x;
      sy += w * y;
    }
  }
  return {sx / sw, sy / sw};
}

TEST(StereoSceneTest, MarkersAreDrawnWhereTheTruthProjectsThemInBothViews) {
  StereoSceneOptions options;
  options.frame_count = 3;
  const StereoScene scene(MakeStereoRig(), options);
  cv::Mat left, right;
  for (int index = 0; index < 3; ++index) {
    const StereoSceneTruth truth = scene.render(index, left, right);
    for (size_t m = 0; m < truth.markers.size(); ++m) {
      const cv::Vec3b colour = options.markers[m].bgr;
      EXPECT_LT(cv::norm(BlendCentroid(left, colour, options.body_bgr, truth.markers[m].left_px) -
                         truth.markers[m].left_px),
                0.05)
          << "frame " << index << " " << truth.markers[m].name;
      EXPECT_LT(cv::norm(BlendCentroid(right, colour, options.body_bgr, truth.markers[m].right_px) -
                         truth.markers[m].right_px),
                0.05)
          << "frame " << index << " " << truth.markers[m].name;
    }
  }
}

TEST(StereoSceneTest, TheTruthIsAnArcInTheTiltedPlane) {
  StereoSceneOptions options;
  options.frame_count = 2;
  options.max_bend_deg = 90.0;
  options.plane_tilt_start_deg = 10.0;
  options.plane_tilt_end_deg = 40.0;  // Turning about its axis while it bends.
  const StereoScene scene(MakeStereoRig(), options);
  const StereoSceneTruth straight = scene.truth(0), bent = scene.truth(1);
  EXPECT_NEAR(straight.plane_tilt_deg, 10.0, 1e-9);
  EXPECT_NEAR(bent.plane_tilt_deg, 40.0, 1e-9);
  EXPECT_FALSE(straight.radius_mm.has_value());
  EXPECT_NEAR(straight.angle_deg, 180.0, 1e-9);
  // 90 degrees over 90 mm: R = 57.3 mm; markers 0.1 / 0.5 / 0.9 of the length: 36 mm of arc
  // apart, 2 R sin(36 / 2R) chords; each in the bending plane through the base.
  const double radius = 90.0 / (CV_PI / 2.0);
  ASSERT_TRUE(bent.radius_mm.has_value());
  EXPECT_NEAR(*bent.radius_mm, radius, 1e-9);
  const double chord = 2.0 * radius * std::sin(36.0 / (2.0 * radius));
  EXPECT_NEAR(cv::norm(bent.markers[1].position_mm - bent.markers[0].position_mm), chord, 1e-9);
  EXPECT_NEAR(cv::norm(bent.markers[2].position_mm - bent.markers[1].position_mm), chord, 1e-9);
  for (const StereoMarkerTruth& m : bent.markers) {
    const cv::Point3d d = m.position_mm - options.base_mm;
    EXPECT_NEAR(cv::Vec3d(d.x, d.y, d.z).dot(bent.plane_normal), 0.0, 1e-9) << m.name;
  }
}

TEST(StereoSceneTest, UnusableOptionsAreRefusedByName) {
  StereoSceneOptions options;
  options.supersample = 0;
  EXPECT_THROW(StereoScene(MakeStereoRig(), options), InputError);
  options = StereoSceneOptions();
  options.markers[1].body_fraction = 1.5;
  try {
    StereoScene scene(MakeStereoRig(), options);
    FAIL() << "accepted a marker beyond the tip";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("markers: blue"), std::string::npos) << e.what();
  }
}

// The simulated control rig's frames: an explicit bend renders exactly what the time profile's
// frame of that bend does; a marker hidden in one view is missing there only, for its frames.
TEST(StereoSceneTest, AnExplicitBendAndAMarkerHiddenInOneView) {
  StereoSceneOptions options;
  options.frame_count = 5;
  options.max_bend_deg = 80.0;
  options.hidden = {{"green", 1, 2, 2}};
  const StereoScene scene(MakeStereoRig(), options);
  cv::Mat left, right, left_at, right_at;
  const StereoSceneTruth profile = scene.render(1, left, right);
  const StereoSceneTruth at = scene.render_at_bend(20.0, 1, left_at, right_at);
  EXPECT_DOUBLE_EQ(at.bend_deg, profile.bend_deg);
  EXPECT_DOUBLE_EQ(at.angle_deg, profile.angle_deg);
  EXPECT_EQ(cv::norm(left, left_at, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(right, right_at, cv::NORM_INF), 0.0);
  EXPECT_DOUBLE_EQ(scene.truth_at_bend(400.0, 0).bend_deg, 300.0);  // Clamped.

  // Whether the pixel at the marker's projected centre has the marker's colour.
  const auto drawn = [&](const cv::Mat& image, const cv::Point2d& at_px, size_t marker) {
    const cv::Vec3b pixel = image.at<cv::Vec3b>(static_cast<int>(std::lround(at_px.y)),
                                                static_cast<int>(std::lround(at_px.x)));
    return cv::norm(cv::Vec3d(pixel) - cv::Vec3d(options.markers[marker].bgr)) < 10.0;
  };
  for (int index = 0; index < 5; ++index) {
    const StereoSceneTruth truth = scene.render_at_bend(60.0, index, left, right);
    const bool hidden = index == 2 || index == 3;
    EXPECT_TRUE(drawn(left, truth.markers[2].left_px, 2)) << index;
    EXPECT_EQ(drawn(right, truth.markers[2].right_px, 2), !hidden) << index;
    EXPECT_TRUE(drawn(right, truth.markers[1].right_px, 1)) << index;
  }
  options.hidden = {{"purple", 0, 0, 1}};
  EXPECT_THROW(StereoScene(MakeStereoRig(), options), InputError);
}

}  // namespace
}  // namespace softsight
