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

}  // namespace
}  // namespace softsight
