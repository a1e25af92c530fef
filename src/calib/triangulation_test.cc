// Triangulation against exact truth: points projected through a known rig (exact, with noise of
// a known sigma), and markers tracked on rendered views of an actuator bending out of the image
// plane (sim/stereo_scene.h).
#include "softsight/calib/triangulation.h"

#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "calib/stereo_test_util.h"
#include "softsight/core/error.h"
#include "softsight/geometry/shape3d.h"
#include "softsight/geometry/triangle.h"
#include "softsight/sim/stereo_scene.h"
#include "softsight/track/marker_finder.h"

namespace softsight {
namespace {

using testing::CalibrationOfRig;

TEST(TriangulatorTest, ExactProjectionsGiveTheExactPoint) {
  const StereoRig rig = MakeStereoRig();
  const Triangulator triangulator(CalibrationOfRig(rig));
  for (const cv::Point3d truth : {cv::Point3d(0, 0, 300), cv::Point3d(-40, 30, 250),
                                  cv::Point3d(55, -35, 380), cv::Point3d(10, 60, 200)}) {
    const StereoPoint p =
        triangulator.triangulate(ProjectLeft(rig, truth), ProjectRight(rig, truth));
    ASSERT_TRUE(p.found()) << truth;
    EXPECT_LT(cv::norm(*p.position_mm - truth), 1e-6) << truth;
    EXPECT_LT(*p.epipolar_px, 1e-6);
    EXPECT_LT(*p.reprojection_px, 1e-6);
    // The triangulator's own projection is the renderer's.
    EXPECT_LT(cv::norm(triangulator.project_left(truth) - ProjectLeft(rig, truth)), 1e-9);
    EXPECT_LT(cv::norm(triangulator.project_right(truth) - ProjectRight(rig, truth)), 1e-9);
  }
}

TEST(TriangulatorTest, APairOffItsEpipolarLineIsNotBelieved) {
  const StereoRig rig = MakeStereoRig();
  TriangulationOptions options;
  options.max_epipolar_px = 2.0;
  const Triangulator triangulator(CalibrationOfRig(rig), options);
  const cv::Point3d truth(5, 10, 300);
  const cv::Point2d left = ProjectLeft(rig, truth), right = ProjectRight(rig, truth);
  // The cameras sit side by side: epipolar lines run nearly along the rows, so a shift down
  // the image moves the right point off its line by about the shift.
  const StereoPoint near = triangulator.triangulate(left, right + cv::Point2d(0, 1.5));
  EXPECT_TRUE(near.found());
  EXPECT_NEAR(*near.epipolar_px, 1.5, 0.1);
  const StereoPoint far = triangulator.triangulate(left, right + cv::Point2d(0, 3.0));
  EXPECT_EQ(far.status, StereoStatus::kEpipolar);
  EXPECT_FALSE(far.position_mm.has_value());
  EXPECT_NEAR(*far.epipolar_px, 3.0, 0.2);
  // Along the line it is a different depth, not a contradiction.
  EXPECT_TRUE(triangulator.triangulate(left, ProjectRight(rig, truth * 1.2)).found());
  // A view without the marker: nothing to verify.
  EXPECT_EQ(triangulator.triangulate(left, std::nullopt).status, StereoStatus::kMissing);
  EXPECT_EQ(triangulator.triangulate(std::nullopt, right).status, StereoStatus::kMissing);
}

TEST(TriangulatorTest, RaysMeetingBehindTheCamerasAreNotAPoint) {
  const StereoRig rig = MakeStereoRig();
  const Triangulator triangulator(CalibrationOfRig(rig));
  // The right camera's view of a point far to the left of the left camera's: on the epipolar
  // line, but the rays cross behind the rig.
  const cv::Point3d truth(0, 0, 300);
  const cv::Point2d left = ProjectLeft(rig, truth);
  const cv::Point2d right = ProjectRight(rig, cv::Point3d(0, 0, 300)) + cv::Point2d(250, 0);
  const StereoPoint p = triangulator.triangulate(left, right);
  EXPECT_NE(p.status, StereoStatus::kFound) << StereoStatusName(p.status);
}

TEST(TriangulatorTest, PredictedUncertaintyMatchesTheScatterOfNoisyPairs) {
  // 0.2 px Gaussian noise on both views' positions: the predicted 1-sigma radius must match the
  // RMS error of the triangulated points (within the sampling error of 400 trials).
  const StereoRig rig = MakeStereoRig();
  const Triangulator triangulator(CalibrationOfRig(rig));
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 0.2);
  const cv::Point3d truth(12, -20, 310);
  double sum_sq = 0.0, sum_sigma_sq = 0.0, sum_depth_sq = 0.0;
  const int trials = 400;
  for (int i = 0; i < trials; ++i) {
    const StereoPoint p = triangulator.triangulate(
        ProjectLeft(rig, truth) + cv::Point2d(noise(rng), noise(rng)),
        ProjectRight(rig, truth) + cv::Point2d(noise(rng), noise(rng)), 0.2, 0.2);
    ASSERT_TRUE(p.found());
    const cv::Point3d e = *p.position_mm - truth;
    sum_sq += e.dot(e);
    sum_depth_sq += e.z * e.z;
    sum_sigma_sq += *p.sigma_mm * *p.sigma_mm;
  }
  const double rms = std::sqrt(sum_sq / trials), predicted = std::sqrt(sum_sigma_sq / trials);
  EXPECT_NEAR(rms / predicted, 1.0, 0.1) << "RMS " << rms << " mm, predicted " << predicted;
  // Depth dominates: Z^2 sigma / (f B) = 310^2 * 0.2 / (600 * 100) = 0.32 mm per view, /sqrt(2)
  // for two independent views' worth of disparity noise... of the same order here.
  EXPECT_GT(std::sqrt(sum_depth_sq / trials), 0.7 * rms);
}

// Marker positions on rendered views, as the colour tracker finds them (FindMarkers verifies
// each with a colour tracker on the frame), matched to the truth's markers by projection.
std::vector<std::optional<cv::Point2d>> TrackedPositions(const cv::Mat& image,
                                                         const std::vector<cv::Point2d>& truth_px) {
  MarkerFinderOptions options;
  options.expected_count = static_cast<int>(truth_px.size());
  const MarkerFinding finding = FindMarkers(image, options);
  std::vector<std::optional<cv::Point2d>> positions(truth_px.size());
  for (const FoundMarker& found : finding.markers) {
    for (size_t i = 0; i < truth_px.size(); ++i) {
      if (cv::norm(found.position_px - truth_px[i]) < 3.0) positions[i] = found.position_px;
    }
  }
  return positions;
}

struct SceneErrors {
  double position_rms_mm = 0, angle_rms_deg = 0;
  double worst_out_of_plane_error_deg = 0;
  double worst_2d_angle_error_deg = 0, worst_3d_angle_error_deg = 0;
  int points = 0;
};

// Tracks and triangulates every frame of `scene`; the errors against its truth.
SceneErrors MeasureScene(const StereoScene& scene, int first_plane_frame) {
  const Triangulator triangulator(CalibrationOfRig(scene.rig()));
  SceneErrors errors;
  double position_sq = 0, angle_sq = 0;
  int angles = 0;
  cv::Mat left, right;
  for (int index = 0; index < scene.options().frame_count; ++index) {
    const StereoSceneTruth truth = scene.render(index, left, right);
    std::vector<cv::Point2d> truth_left, truth_right;
    for (const StereoMarkerTruth& m : truth.markers) {
      truth_left.push_back(m.left_px);
      truth_right.push_back(m.right_px);
    }
    const auto tracked_left = TrackedPositions(left, truth_left);
    const auto tracked_right = TrackedPositions(right, truth_right);
    std::vector<std::optional<cv::Point3d>> chain;
    for (size_t i = 0; i < truth.markers.size(); ++i) {
      const StereoPoint p = triangulator.triangulate(tracked_left[i], tracked_right[i]);
      EXPECT_TRUE(p.found()) << "frame " << index << " " << truth.markers[i].name << ": "
                             << StereoStatusName(p.status);
      if (!p.found()) {
        chain.emplace_back();
        continue;
      }
      const cv::Point3d e = *p.position_mm - truth.markers[i].position_mm;
      position_sq += e.dot(e);
      ++errors.points;
      chain.push_back(*p.position_mm);
    }
    const Shape3d shape = MeasureShape3d(chain, cv::Vec3d(0, 0, 1), std::nullopt);
    if (shape.angle_deg) {
      angle_sq += std::pow(*shape.angle_deg - truth.angle_deg, 2);
      ++angles;
    }
    if (index < first_plane_frame || !shape.out_of_plane_deg || !shape.angle_deg) continue;
    errors.worst_out_of_plane_error_deg =
        std::max(errors.worst_out_of_plane_error_deg,
                 std::abs(*shape.out_of_plane_deg - truth.plane_tilt_deg));
    errors.worst_3d_angle_error_deg =
        std::max(errors.worst_3d_angle_error_deg, std::abs(*shape.angle_deg - truth.angle_deg));
    if (tracked_left[0] && tracked_left[1] && tracked_left[2]) {
      const std::optional<double> flat =
          AngleAtMiddleDeg(*tracked_left[0], *tracked_left[1], *tracked_left[2]);
      if (flat) {
        errors.worst_2d_angle_error_deg =
            std::max(errors.worst_2d_angle_error_deg, std::abs(*flat - truth.angle_deg));
      }
    }
  }
  errors.position_rms_mm = errors.points ? std::sqrt(position_sq / errors.points) : 1e9;
  errors.angle_rms_deg = angles ? std::sqrt(angle_sq / angles) : 1e9;
  return errors;
}

TEST(StereoSceneTriangulationTest, MarkersAndTheAngleIn3dAtThreeHundredMillimetres) {
  // 640x480 cameras 100 mm apart, the actuator at 300 mm bending 0 to 90 degrees in a plane
  // tilted 30 degrees out of the image plane. The geometry's limit: depth error ~ Z^2 sigma /
  // (f B) = 300^2 x 0.05 px / (600 px x 100 mm) = 0.075 mm for a 0.05 px centroid error.
  StereoSceneOptions options;
  options.frame_count = 7;
  const StereoScene scene(MakeStereoRig(), options);
  const SceneErrors errors = MeasureScene(scene, 4);
  EXPECT_EQ(errors.points, 3 * options.frame_count);
  EXPECT_LT(errors.position_rms_mm, 0.2);
  EXPECT_LT(errors.angle_rms_deg, 0.3);
  std::cout << "[ figures  ] marker 3D error " << errors.position_rms_mm << " mm RMS, 3D angle "
            << errors.angle_rms_deg << " deg RMS\n";
}

TEST(StereoSceneTriangulationTest,
     ABendThirtyDegreesOutOfTheImagePlaneIsMeasuredWhereOneCameraIsNot) {
  // Bent 60 to 100 degrees in a plane tilted 30 degrees: the 3D angle and the plane's tilt
  // within 0.5 degrees, while the angle the left camera sees is off by more.
  StereoSceneOptions options;
  options.frame_count = 5;
  options.max_bend_deg = 100.0;
  const StereoScene scene(MakeStereoRig(), options);
  const SceneErrors errors = MeasureScene(scene, 3);
  EXPECT_LT(errors.worst_out_of_plane_error_deg, 0.5);
  EXPECT_LT(errors.worst_3d_angle_error_deg, 0.5);
  EXPECT_GT(errors.worst_2d_angle_error_deg, 0.5);
  std::cout << "[ figures  ] 30 deg out of plane: plane tilt error "
            << errors.worst_out_of_plane_error_deg << " deg, 3D angle error "
            << errors.worst_3d_angle_error_deg << " deg, one camera's 2D angle error "
            << errors.worst_2d_angle_error_deg << " deg\n";
}

}  // namespace
}  // namespace softsight
