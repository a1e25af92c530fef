// Stereo calibration against exact truth: chessboard pairs rendered through two cameras with
// known intrinsics, distortion and pose (sim/stereo_scene.h's rig), and the calibration file.
#include "softsight/calib/stereo_calibration.h"

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "calib/stereo_test_util.h"
#include "softsight/core/error.h"
#include "softsight/sim/stereo_scene.h"

namespace softsight {
namespace {

double RotationAngleDeg(const cv::Matx33d& a, const cv::Matx33d& b) {
  cv::Vec3d rvec;
  cv::Rodrigues(a.t() * b, rvec);
  return cv::norm(rvec) * 180.0 / CV_PI;
}

ChessboardPattern RigPattern() {
  ChessboardPattern pattern;
  pattern.inner_corners = cv::Size(9, 6);
  pattern.square_mm = 20.0;
  pattern.margin_mm = 15.0;
  return pattern;
}

// Ten pairs of the board at 260-340 mm, tilted both ways, as a person waves it in front of the
// rig: both cameras see it whole. Rendered once for the suite (about 1 s).
class RenderedStereoPairs : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    rig_ = new StereoRig(MakeStereoRig());
    pairs_ = new std::vector<std::pair<cv::Mat, cv::Mat>>();
    ChessboardLook look;
    look.supersample = 2;
    const ChessboardRenderer left(rig_->left, RigPattern(), look);
    const ChessboardRenderer right(rig_->right, RigPattern(), look);
    const double poses[][6] = {{300, 0, 0, 0, 0, 0},         {280, 25, 0, 5, -15, 10},
                               {280, -25, 0, -5, 15, -10},   {290, 0, 25, 10, 10, 15},
                               {290, 0, -25, -10, -10, -15}, {320, 20, 20, 15, -20, -15},
                               {320, -20, 20, -15, 20, 15},  {320, 20, -20, 3, 20, -15},
                               {260, -20, -20, -3, -5, 10},  {340, 30, 10, 0, 0, 20}};
    for (const auto& p : poses) {
      const BoardPose pose = LookAtBoard(RigPattern(), p[0], p[1], p[2], p[3], p[4], p[5]);
      cv::Mat l, r;
      left.render(pose, l);
      right.render(RightBoardPose(*rig_, pose), r);
      pairs_->emplace_back(l, r);
    }
  }
  static void TearDownTestSuite() {
    delete rig_;
    delete pairs_;
  }
  static StereoCalibrationOptions Options() {
    StereoCalibrationOptions options;
    options.camera.board.inner_corners = RigPattern().inner_corners;
    options.camera.board.square_mm = RigPattern().square_mm;
    return options;
  }
  static StereoCalibrationResult Calibrate() {
    StereoCalibrator calibrator(Options());
    for (size_t i = 0; i < pairs_->size(); ++i) {
      const std::string n = std::to_string(i);
      calibrator.add("l" + n + ".png", (*pairs_)[i].first, "r" + n + ".png", (*pairs_)[i].second);
    }
    return calibrator.calibrate();
  }
  static StereoRig* rig_;
  static std::vector<std::pair<cv::Mat, cv::Mat>>* pairs_;
};
StereoRig* RenderedStereoPairs::rig_ = nullptr;
std::vector<std::pair<cv::Mat, cv::Mat>>* RenderedStereoPairs::pairs_ = nullptr;

TEST_F(RenderedStereoPairs, RecoversTheRigsPoseAndLenses) {
  const StereoCalibrationResult result = Calibrate();
  EXPECT_EQ(result.pairs_used(), static_cast<int>(pairs_->size()));
  const StereoCalibration& s = result.stereo;
  EXPECT_NEAR(s.baseline_mm(), 100.0, 0.3);  // 0.3 %
  EXPECT_LT(RotationAngleDeg(s.R, rig_->R), 0.05);
  EXPECT_LT(cv::norm(s.T - rig_->T), 0.5);
  EXPECT_NEAR(s.left.camera_matrix(0, 0), rig_->left.camera_matrix(0, 0), 3.0);
  EXPECT_NEAR(s.right.camera_matrix(0, 0), rig_->right.camera_matrix(0, 0), 3.0);
  EXPECT_LT(s.rms_px, 0.2);
  // Rectified, the two cameras share their rows: P1 and P2 both take points in the rectified
  // first camera's frame (R1 X), and give one y.
  const cv::Vec3d x = s.R1 * cv::Vec3d(15, -10, 300);
  const cv::Vec4d rectified(x[0], x[1], x[2], 1.0);
  const cv::Vec3d in_left = s.P1 * rectified, in_right = s.P2 * rectified;
  EXPECT_NEAR(in_left[1] / in_left[2], in_right[1] / in_right[2], 1e-6);
}

TEST_F(RenderedStereoPairs, FileRoundTripKeepsTheRig) {
  const StereoCalibrationResult result = Calibrate();
  const std::string file = (std::filesystem::temp_directory_path() /
                            ("softsight_stereo_" + std::to_string(::getpid()) + ".yaml"))
                               .string();
  SaveStereoCalibration(result, Options().camera.board, file);
  const StereoCalibration loaded = LoadStereoCalibration(file);
  std::filesystem::remove(file);
  EXPECT_LT(cv::norm(loaded.R - result.stereo.R), 1e-9);
  EXPECT_LT(cv::norm(loaded.T - result.stereo.T), 1e-9);
  EXPECT_LT(cv::norm(loaded.left.camera_matrix - result.stereo.left.camera_matrix), 1e-9);
  EXPECT_EQ(loaded.right.distortion, result.stereo.right.distortion);
  EXPECT_LT(cv::norm(loaded.P2 - result.stereo.P2), 1e-6);
  EXPECT_NEAR(loaded.rms_px, result.stereo.rms_px, 1e-12);
}

TEST_F(RenderedStereoPairs, ABaselineOrADistortionNoBenchHasIsRefusedOnLoading) {
  // A rig file edited or corrupted to a 1e300 mm baseline gave "baseline inf mm" and nan depths.
  const StereoCalibrationResult good = Calibrate();
  const std::string file = (std::filesystem::temp_directory_path() /
                            ("softsight_stereo_far_" + std::to_string(::getpid()) + ".yaml"))
                               .string();
  StereoCalibrationResult far = good;
  far.stereo.T = cv::Vec3d(1e300, 0, 0);
  StereoCalibrationResult warped = good;
  warped.stereo.left.distortion[0] = 1e10;
  for (const auto& [result, named] : {std::pair{&far, ": T: a baseline of"},
                                      std::pair{&warped, ": distortion_left: a coefficient of"}}) {
    SaveStereoCalibration(*result, Options().camera.board, file);
    try {
      LoadStereoCalibration(file);
      ADD_FAILURE() << "loaded a rig with " << named;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr(file + named));
    }
  }
  std::filesystem::remove(file);
}

TEST_F(RenderedStereoPairs, TooFewPairsWithTheBoardInBothViewsIsAnError) {
  StereoCalibrator calibrator(Options());
  const cv::Mat blank(480, 640, CV_8UC1, cv::Scalar(120));
  calibrator.add("l0.png", (*pairs_)[0].first, "r0.png", (*pairs_)[0].second);
  calibrator.add("l1.png", (*pairs_)[1].first, "r1.png", blank);
  try {
    calibrator.calibrate();
    FAIL() << "calibrated from one pair";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("found in both views of 1 of 2 pairs"), std::string::npos)
        << e.what();
  }
}

TEST(StereoCalibrationFileTest, AMissingKeyIsNamed) {
  const std::string file = (std::filesystem::temp_directory_path() /
                            ("softsight_stereo_bad_" + std::to_string(::getpid()) + ".yaml"))
                               .string();
  {
    cv::FileStorage fs(file, cv::FileStorage::WRITE);
    fs << "image_width" << 640 << "image_height" << 480;
    fs << "camera_matrix_left" << cv::Mat(cv::Matx33d::eye());
  }
  try {
    LoadStereoCalibration(file);
    FAIL() << "loaded a file without the right camera";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file + ": camera_matrix_right: missing"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove(file);
}

TEST(StereoCalibrationFileTest, APictureOfTheRectifiedPairHasBothViewsSideBySide) {
  const StereoCalibration stereo = testing::CalibrationOfRig(MakeStereoRig());
  const cv::Mat picture = DrawRectifiedPair(stereo, cv::Mat(480, 640, CV_8UC1, cv::Scalar(50)),
                                            cv::Mat(480, 640, CV_8UC3, cv::Scalar(200, 200, 200)));
  ASSERT_EQ(picture.size(), cv::Size(1280, 480));
  // Mid-image, away from the lines: each half shows its own image.
  EXPECT_EQ(picture.at<cv::Vec3b>(250, 320)[0], 50);
  EXPECT_EQ(picture.at<cv::Vec3b>(250, 960)[0], 200);
  EXPECT_THROW(DrawRectifiedPair(stereo, cv::Mat(10, 10, CV_8UC1), cv::Mat(10, 10, CV_8UC1)),
               InputError);
}

}  // namespace
}  // namespace softsight
