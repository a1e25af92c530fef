#include "softsight/sim/plate_scene.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sim/raster.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

PlateSceneOptions SmallPlate() {
  PlateSceneOptions o;
  o.size = cv::Size(320, 240);
  o.frame_count = 30;
  o.dot_radius_px = 5;
  return o;
}

cv::Point2d Apply(const cv::Matx33d& h, const cv::Point2d& p) {
  const cv::Vec3d q = h * cv::Vec3d(p.x, p.y, 1.0);
  return cv::Point2d(q[0] / q[2], q[1] / q[2]);
}

// The centre of the image ellipse of the circle (c, r) under h: the conic's centre, from its
// matrix C' = H^-T C H^-1 (independent of the renderer's Conic class).
cv::Point2d EllipseCentre(const cv::Matx33d& h, const cv::Point2d& c, double r) {
  const cv::Matx33d circle(1, 0, -c.x, 0, 1, -c.y, -c.x, -c.y, c.x * c.x + c.y * c.y - r * r);
  const cv::Matx33d inv = h.inv();
  const cv::Matx33d m = inv.t() * circle * inv;
  const cv::Matx22d q(m(0, 0), m(0, 1), m(1, 0), m(1, 1));
  const cv::Vec2d centre = -(q.inv() * cv::Vec2d(m(0, 2), m(1, 2)));
  return cv::Point2d(centre[0], centre[1]);
}

// The truth is the centroid of each dot's image, an ellipse: its analytic centre (which in
// perspective differs from the image of the dot's centre), and the rendered gray image puts
// the dot's light there too.
TEST(PlateSceneTest, TruthIsTheCentroidOfTheDotsEllipse) {
  PlateSceneOptions options = SmallPlate();
  options.cluttered_background = false;
  PlateScene scene(options);
  cv::Mat image;
  double worst = 0, largest_shift = 0;
  for (int i = 0; i < options.frame_count; i += 3) {
    const SceneTruth truth = scene.render(i, image);
    const cv::Matx33d h = scene.image_from_plate(i);
    ASSERT_EQ(truth.markers.size(), 5u);
    for (size_t d = 0; d < truth.markers.size(); ++d) {
      EXPECT_EQ(truth.markers[d].name, "dot" + std::to_string(d));
      ASSERT_TRUE(truth.markers[d].centroid_px.has_value());
      EXPECT_NEAR(truth.markers[d].visible_fraction, 1.0, 1e-12);
      const cv::Point2d c = *truth.markers[d].centroid_px;
      const cv::Point2d centre = EllipseCentre(h, scene.dot_centres()[d], options.dot_radius_px);
      worst = std::max(worst, std::hypot(c.x - centre.x, c.y - centre.y));
      const cv::Point2d projected = Apply(h, scene.dot_centres()[d]);
      largest_shift = std::max(largest_shift, std::hypot(c.x - projected.x, c.y - projected.y));
    }
  }
  EXPECT_LT(worst, 0.005);
  EXPECT_GT(largest_shift, 0.02);  // The perspective is real: the centroid is not the projection.
}

// The rendered dot's light, above the plate's level, has its centroid at the truth.
TEST(PlateSceneTest, RenderedDotsAreWhereTheTruthIs) {
  PlateSceneOptions options = SmallPlate();
  options.cluttered_background = false;
  PlateScene scene(options);
  cv::Mat image, gray;
  for (int i : {0, 10, 29}) {
    const SceneTruth truth = scene.render(i, image);
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
    const cv::Matx33d plate_from_image = scene.image_from_plate(i).inv();
    for (size_t d = 0; d < truth.markers.size(); ++d) {
      const MarkerTruth& m = truth.markers[d];
      const cv::Point2d c = *m.centroid_px;
      const int half = cvCeil(options.dot_radius_px * 2 * 2.5);
      const cv::Rect box = cv::Rect(cvRound(c.x) - half, cvRound(c.y) - half, 2 * half + 1, 2 * half + 1) &
                           cv::Rect(0, 0, gray.cols, gray.rows);
      cv::Mat1d weight;
      gray(box).convertTo(weight, CV_64F, 1.0 / (235 - 40), -40.0 / (235 - 40));
      // Only the dot: pixels within 1.6 dot radii of its centre on the plate (the plate's margin
      // is 2.5 radii; the plate's own level, 40, weighs 0).
      const cv::Point2d local = c - cv::Point2d(box.tl());
      for (int y = 0; y < box.height; ++y) {
        for (int x = 0; x < box.width; ++x) {
          const cv::Point2d q = Apply(plate_from_image, cv::Point2d(box.x + x, box.y + y));
          const cv::Point2d e = q - scene.dot_centres()[d];
          if (std::hypot(e.x, e.y) > 1.6 * options.dot_radius_px) weight(y, x) = 0;
        }
      }
      weight = cv::max(weight, 0.0);
      const cv::Moments mom = cv::moments(weight);
      EXPECT_NEAR(mom.m10 / mom.m00, local.x, 0.02) << m.name << " frame " << i;
      EXPECT_NEAR(mom.m01 / mom.m00, local.y, 0.02) << m.name << " frame " << i;
    }
  }
}

// The plate tilts to max_tilt_deg, grows from scale_start to scale_end, stays in the frame with
// the default path, and the output is gray.
TEST(PlateSceneTest, TiltsGrowsStaysInFrameAndIsGray) {
  PlateSceneOptions options = SmallPlate();
  options.frame_count = 61;
  PlateScene scene(options);
  cv::Mat image;
  // The foreshortening of a dot: the ratio of the image ellipse's axes.
  auto axes = [&](int i, size_t d) {
    const cv::Matx33d h = scene.image_from_plate(i);
    const cv::Point2d c = scene.dot_centres()[d];
    double lo = 1e9, hi = 0;
    for (int k = 0; k < 360; ++k) {
      const double a = k * CV_PI / 180;
      const cv::Point2d p = Apply(h, c + options.dot_radius_px * cv::Point2d(std::cos(a), std::sin(a)));
      const double l = std::hypot(p.x - Apply(h, c).x, p.y - Apply(h, c).y);
      lo = std::min(lo, l), hi = std::max(hi, l);
    }
    return std::make_pair(lo, hi);
  };
  const auto first = axes(0, 2), third = axes(20, 2), last = axes(60, 2);
  // Facing the camera, a dot off the image centre is seen obliquely by the image plane: round
  // across the line to the centre, slightly stretched along it.
  EXPECT_NEAR(first.first, options.dot_radius_px, 0.1);
  EXPECT_GE(first.second, options.dot_radius_px);
  EXPECT_LT(first.second, 1.1 * options.dot_radius_px);
  // At a third of the way the tilt is 50 degrees: axes ratio about cos(50).
  EXPECT_NEAR(third.first / third.second, std::cos(50 * CV_PI / 180), 0.05);
  EXPECT_NEAR(last.second, 2 * options.dot_radius_px, 0.6);
  for (int i = 0; i < options.frame_count; i += 4) {
    const SceneTruth truth = scene.render(i, image);
    for (const MarkerTruth& m : truth.markers) EXPECT_NEAR(m.visible_fraction, 1.0, 1e-12) << i;
    cv::Mat channels[3];
    cv::split(image, channels);
    EXPECT_EQ(cv::norm(channels[0], channels[1], cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(channels[1], channels[2], cv::NORM_INF), 0);
  }
}

// The zig-zag: three or more dots never lie on one line.
TEST(PlateSceneTest, DotsAreNotCollinear) {
  for (int count : {3, 5, 8}) {
    PlateSceneOptions options = SmallPlate();
    options.dot_count = count;
    options.dot_radius_px = 3;
    PlateScene scene(options);
    const std::vector<cv::Point2d>& d = scene.dot_centres();
    ASSERT_EQ(d.size(), static_cast<size_t>(count));
    for (int i = 0; i + 2 < count; ++i) {
      const cv::Point2d a = d[i + 1] - d[i], b = d[i + 2] - d[i];
      EXPECT_GT(std::abs(a.x * b.y - a.y * b.x), 1.0);
    }
  }
}

// A dot partly outside the image: the truth is the visible part; fully outside: absent.
TEST(PlateSceneTest, DotsLeavingTheImageGiveTheVisiblePart) {
  PlateSceneOptions options = SmallPlate();
  options.size = cv::Size(120, 100);  // The plate does not fit: dots leave the frame.
  options.cluttered_background = false;
  PlateScene scene(options);
  cv::Mat image;
  bool partial = false, absent = false;
  for (int i = 0; i < options.frame_count; ++i) {
    const SceneTruth truth = scene.render(i, image);
    for (const MarkerTruth& m : truth.markers) {
      EXPECT_GE(m.visible_fraction, 0.0);
      EXPECT_LE(m.visible_fraction, 1.0);
      if (m.visible_fraction == 0) {
        absent = true;
        EXPECT_FALSE(m.centroid_px.has_value());
      } else if (m.visible_fraction < 0.9) {
        partial = true;
        ASSERT_TRUE(m.centroid_px.has_value());
        // The visible part's centroid lies inside the image.
        EXPECT_GE(m.centroid_px->x, -0.5);
        EXPECT_LE(m.centroid_px->x, options.size.width - 0.5);
        EXPECT_GE(m.centroid_px->y, -0.5);
        EXPECT_LE(m.centroid_px->y, options.size.height - 0.5);
      }
    }
  }
  EXPECT_TRUE(partial);
  EXPECT_TRUE(absent);
}

TEST(PlateSceneTest, DeterministicAndColourOptional) {
  PlateSceneOptions options = SmallPlate();
  options.frame_count = 5;
  NoiseOptions noise;
  noise.sigma = 4;
  cv::Mat a, b, c;
  PlateScene(options, noise).render(3, a);
  PlateScene(options, noise).render(3, b);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
  options.gray = false;
  options.dot_bgr = {20, 20, 230};
  const SceneTruth truth = PlateScene(options).render(3, c);
  const cv::Point2d p = *truth.markers[0].centroid_px;
  EXPECT_EQ(c.at<cv::Vec3b>(cvRound(p.y), cvRound(p.x)), cv::Vec3b(20, 20, 230));
}

// Light look-alike spots on the backdrop: drawn where asked, hidden when the plate passes over
// them, and the dots' truth is unchanged.
TEST(PlateSceneTest, DistractorsLieBehindThePlate) {
  PlateSceneOptions options = SmallPlate();
  options.frame_count = 5;
  options.cluttered_background = false;
  PlateScene plain(options);
  cv::Mat a, b;
  const SceneTruth truth = plain.render(0, a);
  // One spot under the plate's centre in frame 0, one far from it.
  const cv::Point2d under = Apply(plain.image_from_plate(0), cv::Point2d(0, 0));
  options.distractors = {{under, {4, 4}, 0, {235, 235, 235}}, {{10, 10}, {4, 4}, 0, {235, 235, 235}}};
  PlateScene with(options);
  const SceneTruth truth_with = with.render(0, b);
  for (size_t d = 0; d < truth.markers.size(); ++d) {
    EXPECT_EQ(*truth.markers[d].centroid_px, *truth_with.markers[d].centroid_px);
  }
  EXPECT_EQ(b.at<cv::Vec3b>(10, 10), cv::Vec3b(235, 235, 235));
  EXPECT_EQ(cv::norm(a(cv::Rect(cvRound(under.x) - 6, cvRound(under.y) - 6, 13, 13)),
                     b(cv::Rect(cvRound(under.x) - 6, cvRound(under.y) - 6, 13, 13)), cv::NORM_INF),
            0);
  options.distractors = {{{10, 10}, {0, 4}, 0, {235, 235, 235}}};
  std::string error;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("distractors"), std::string::npos);
}

TEST(PlateSceneTest, CheckNamesTheBadField) {
  std::string error;
  PlateSceneOptions options = SmallPlate();
  EXPECT_TRUE(options.Check(&error)) << error;
  options.dot_count = 0;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("dot_count"), std::string::npos);
  options = SmallPlate();
  options.max_tilt_deg = 80;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("max_tilt_deg"), std::string::npos);
  options = SmallPlate();
  options.scale_end = NAN;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("scale_end"), std::string::npos);
  options = SmallPlate();
  options.dot_radius_px = -1;
  EXPECT_THROW(PlateScene{options}, InputError);
  // So large and so tilted that the plate would reach behind the camera.
  options = SmallPlate();
  options.dot_count = 16;
  options.dot_radius_px = 30;
  options.max_tilt_deg = 75;
  options.scale_end = 8;
  EXPECT_THROW(PlateScene{options}, InputError);
}

// The conic rasteriser against a brute-force supersampled ellipse: the same area and centre.
TEST(ConicTest, CoverageMatchesTheEllipse) {
  cv::RNG rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const cv::Point2d centre(rng.uniform(20.0, 40.0), rng.uniform(20.0, 40.0));
    const cv::Size2d radii(rng.uniform(6.0, 40.0), rng.uniform(6.0, 40.0));
    const double angle = rng.uniform(0.0, 180.0);
    const sim::Conic conic = sim::Conic::Ellipse(centre, radii, angle);
    EXPECT_NEAR(conic.centre().x, centre.x, 1e-9);
    EXPECT_NEAR(conic.centre().y, centre.y, 1e-9);
    double area = 0, sx = 0, sy = 0;
    const cv::Rect box = conic.bounds();
    for (int y = box.y - 2; y < box.y + box.height + 2; ++y) {
      for (int x = box.x - 2; x < box.x + box.width + 2; ++x) {
        const double c = conic.coverage(x, y);
        if (!box.contains(cv::Point(x, y))) {
          EXPECT_EQ(c, 0.0);
        }
        area += c, sx += c * x, sy += c * y;
      }
    }
    EXPECT_NEAR(area, CV_PI * radii.width * radii.height, 0.02 * CV_PI * radii.width * radii.height + 0.5);
    EXPECT_NEAR(sx / area, centre.x, 0.01);
    EXPECT_NEAR(sy / area, centre.y, 0.01);
  }
}

}  // namespace
}  // namespace softsight
