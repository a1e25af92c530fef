// The bench frame against exact truth: a chessboard rendered through the two-view renderer's rig
// at a known pose, found in both views, triangulated with the rig's exact calibration and fitted.
#include "softsight/calib/board_frame.h"

#include <cmath>
#include <iostream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "calib/stereo_test_util.h"
#include "softsight/core/error.h"
#include "softsight/sim/stereo_scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;

double BenchRotationErrorDeg(const cv::Matx33d& a, const cv::Matx33d& b) {
  cv::Vec3d rvec;
  cv::Rodrigues(a.t() * b, rvec);
  return cv::norm(rvec) * 180.0 / CV_PI;
}

ChessboardPattern BenchPattern() {
  ChessboardPattern pattern;
  pattern.inner_corners = cv::Size(9, 6);
  pattern.square_mm = 20.0;
  pattern.margin_mm = 15.0;
  return pattern;
}

ChessboardSpec BenchSpec(double square_mm = 20.0) {
  ChessboardSpec spec;
  spec.inner_corners = BenchPattern().inner_corners;
  spec.square_mm = square_mm;
  return spec;
}

cv::Matx33d BenchPoseRotation(const BoardPose& pose) {
  cv::Matx33d r;
  cv::Rodrigues(pose.rvec, r);
  return r;
}

TEST(FitBoardFrame, RecoversAnExactRigidMotionAndLeavesOutAbsentCorners) {
  const ChessboardSpec board = BenchSpec();
  const BoardPose pose = LookAtBoard(BenchPattern(), 320, 40, -15, 25, 10, -5);
  const cv::Matx33d rotation = BenchPoseRotation(pose);
  std::vector<std::optional<cv::Point3d>> corners;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 9; ++c) {
      const cv::Vec3d p = rotation * cv::Vec3d(c * 20.0, r * 20.0, 0.0) + pose.tvec;
      corners.emplace_back(cv::Point3d(p[0], p[1], p[2]));
    }
  }
  corners[0].reset();  // The origin itself missing: the grid still places it.
  corners[17].reset();
  const BoardFrame frame = FitBoardFrame(corners, board);
  EXPECT_EQ(frame.corners, 52);
  EXPECT_LT(BenchRotationErrorDeg(frame.rotation, rotation), 1e-6);
  EXPECT_LT(cv::norm(frame.origin_mm - pose.tvec), 1e-6);
  EXPECT_LT(frame.rms_mm, 1e-6);
  // A point 10 mm along the board's Z from its corner (1, 2).
  const cv::Vec3d p = rotation * cv::Vec3d(20.0, 40.0, 10.0) + pose.tvec;
  const cv::Point3d in_board = frame.to_board({p[0], p[1], p[2]});
  EXPECT_NEAR(in_board.x, 20.0, 1e-6);
  EXPECT_NEAR(in_board.y, 40.0, 1e-6);
  EXPECT_NEAR(in_board.z, 10.0, 1e-6);

  // The wrong square size cannot be absorbed (no scale in the fit): millimetres of residual.
  EXPECT_GT(FitBoardFrame(corners, BenchSpec(25.0)).rms_mm, 10.0);
  // Too few corners, or all on one row: no pose.
  std::vector<std::optional<cv::Point3d>> row(corners.size());
  for (int c = 1; c < 9; ++c) row[c] = corners[c];
  EXPECT_THROW(FitBoardFrame(row, board), InputError);
  EXPECT_THROW(FitBoardFrame({}, board), InputError);
}

// The board lying on the bench, seen obliquely from about 300 mm by both cameras.
class RenderedBenchBoard : public ::testing::Test {
 protected:
  static void Render(const BoardPose& pose, cv::Mat& left, cv::Mat& right) {
    const StereoRig rig = MakeStereoRig();
    ChessboardLook look;
    look.supersample = 2;
    ChessboardRenderer(rig.left, BenchPattern(), look).render(pose, left);
    ChessboardRenderer(rig.right, BenchPattern(), look).render(RightBoardPose(rig, pose), right);
  }
  static Triangulator ExactRig() {
    return Triangulator(testing::CalibrationOfRig(MakeStereoRig()));
  }
};

TEST_F(RenderedBenchBoard, PoseMatchesTheTruthWhicheverWayTheBoardIsTurned) {
  // Tilted 35-50 deg towards the cameras, turned in its plane; roll 180: the board the other way
  // round, so the detector starts its grid at the other end of the board: the dark corner square
  // still gives the board's own origin.
  const double poses[][6] = {{300, 40, 0, 0, 0, 0},
                             {300, 40, 0, 180, 0, 0},
                             {310, 50, 10, 15, 10, 5},
                             {290, 35, -10, 190, -10, 0}};
  const Triangulator triangulator = ExactRig();
  for (const auto& p : poses) {
    const BoardPose pose = LookAtBoard(BenchPattern(), p[0], p[1], p[2], p[3], p[4], p[5]);
    cv::Mat left, right;
    Render(pose, left, right);
    const BoardFrame frame =
        LocateBenchBoard(triangulator, BenchSpec(), "left.png", left, "right.png", right);
    const double angle_deg = BenchRotationErrorDeg(frame.rotation, BenchPoseRotation(pose));
    const double origin_mm = cv::norm(frame.origin_mm - pose.tvec);
    EXPECT_EQ(frame.corners, 54);
    EXPECT_LT(angle_deg, 0.1) << "roll " << p[3];
    EXPECT_LT(origin_mm, 0.5) << "roll " << p[3];
    EXPECT_LT(frame.rms_mm, 0.3);  // Corner detection on an oblique board: 0.1-0.2 mm.
    std::cout << "[ figures  ] bench board at " << p[0] << " mm, tilt " << p[1] << ", roll "
              << p[3] << ": rotation off " << angle_deg << " deg, origin off " << origin_mm
              << " mm, fit " << frame.rms_mm << " mm RMS (max " << frame.max_mm << ")\n";
  }
}

TEST_F(RenderedBenchBoard, ABoardWithDarkSquaresAtBothEndsStartsNearestTheTopLeft) {
  // 8x6 inner corners: 9x7 squares, dark at both ends of the diagonal. The colour cannot tell
  // the ends apart; the origin is the end nearer the left view's top-left corner: the board's
  // own origin when it lies the right way round, its far corner (axes turned 180 deg about Z)
  // when it lies the other way round.
  ChessboardPattern pattern = BenchPattern();
  pattern.inner_corners = cv::Size(8, 6);
  ChessboardSpec spec = BenchSpec();
  spec.inner_corners = pattern.inner_corners;
  const StereoRig rig = MakeStereoRig();
  ChessboardLook look;
  look.supersample = 2;
  const Triangulator triangulator = ExactRig();
  for (const double roll : {0.0, 180.0}) {
    const BoardPose pose = LookAtBoard(pattern, 300, 40, 0, roll);
    cv::Mat left, right;
    ChessboardRenderer(rig.left, pattern, look).render(pose, left);
    ChessboardRenderer(rig.right, pattern, look).render(RightBoardPose(rig, pose), right);
    const BoardFrame frame =
        LocateBenchBoard(triangulator, spec, "left.png", left, "right.png", right);
    cv::Matx33d rotation = BenchPoseRotation(pose);
    cv::Vec3d origin = pose.tvec;
    if (roll == 180.0) {
      origin = rotation * cv::Vec3d(7 * 20.0, 5 * 20.0, 0.0) + pose.tvec;
      rotation = rotation * cv::Matx33d(-1, 0, 0, 0, -1, 0, 0, 0, 1);
    }
    EXPECT_LT(BenchRotationErrorDeg(frame.rotation, rotation), 0.1) << "roll " << roll;
    EXPECT_LT(cv::norm(frame.origin_mm - origin), 0.5) << "roll " << roll;
  }
}

TEST_F(RenderedBenchBoard, RefusesAMissingBoardOrAWrongSquareNamingTheFiles) {
  const Triangulator triangulator = ExactRig();
  cv::Mat left, right;
  Render(LookAtBoard(BenchPattern(), 300, 40, 0, 0), left, right);
  const cv::Mat blank(left.size(), CV_8UC1, cv::Scalar(110));
  const auto error_of = [&](const cv::Mat& l, const cv::Mat& r, const ChessboardSpec& board) {
    try {
      LocateBenchBoard(triangulator, board, "bench_left.png", l, "bench_right.png", r);
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(error_of(blank, right, BenchSpec()),
              HasSubstr("bench_left.png: the 9x6 chessboard (inner corners) was not found"));
  EXPECT_THAT(error_of(left, blank, BenchSpec()),
              HasSubstr("bench_right.png: the 9x6 chessboard (inner corners) was not found"));
  EXPECT_THAT(error_of(left, right, BenchSpec(25.0)),
              HasSubstr("bench_left.png / bench_right.png: the triangulated corners fit a flat "
                        "9x6 board of 25.00 mm squares to"));
  EXPECT_THAT(error_of(cv::Mat(), right, BenchSpec()),
              HasSubstr("bench_left.png: cannot read the image"));
}

}  // namespace
}  // namespace softsight
