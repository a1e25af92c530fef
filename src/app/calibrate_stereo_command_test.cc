// End to end: chessboard pairs rendered through a rig of known pose, written as two folders,
// calibrated by `calibrate --left --right`; the file it writes is read back against the truth.
#include <cmath>
#include <filesystem>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "app/calibrate_command.h"
#include "app/calibrate_test_util.h"
#include "core/test_util.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/core/error.h"
#include "softsight/sim/stereo_scene.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class CalibrateStereoCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir("calibrate_stereo");
    fs::create_directories(dir_->path() / "left");
    fs::create_directories(dir_->path() / "right");
    const StereoRig rig = MakeStereoRig();
    ChessboardPattern pattern;
    pattern.square_mm = 20.0;
    pattern.margin_mm = 15.0;
    ChessboardLook look;
    look.supersample = 2;
    const ChessboardRenderer left(rig.left, pattern, look), right(rig.right, pattern, look);
    const double poses[][6] = {{300, 0, 0, 0, 0, 0},         {280, 25, 0, 5, -15, 10},
                               {280, -25, 0, -5, 15, -10},   {290, 0, 25, 10, 10, 15},
                               {290, 0, -25, -10, -10, -15}, {320, 20, 20, 15, -20, -15},
                               {320, -20, 20, -15, 20, 15},  {340, 30, 10, 0, 0, 20}};
    int index = 0;
    for (const auto& p : poses) {
      const BoardPose pose = LookAtBoard(pattern, p[0], p[1], p[2], p[3], p[4], p[5]);
      cv::Mat l, r;
      left.render(pose, l);
      right.render(RightBoardPose(rig, pose), r);
      char name[32];
      std::snprintf(name, sizeof(name), "%02d.png", index++);
      cv::imwrite(dir_->file(std::string("left/") + name), l);
      cv::imwrite(dir_->file(std::string("right/") + name), r);
    }
    // A pair where the board left the right camera's view: reported, left out.
    cv::Mat l;
    left.render(LookAtBoard(pattern, 300, 0, 0, 0, 0, 0), l);
    cv::imwrite(dir_->file("left/08.png"), l);
    cv::imwrite(dir_->file("right/08.png"), cv::Mat(480, 640, CV_8UC1, cv::Scalar(110)));
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static CalibrateOptions Options() {
    CalibrateOptions options;
    options.left = dir_->file("left");
    options.right = dir_->file("right");
    options.chessboard = "9x6";
    options.square_mm = 20.0;
    options.out_file = dir_->file("stereo.yaml");
    return options;
  }
  static std::string ErrorOf(const CalibrateOptions& options) {
    return testing::CalibrateErrorOf(options);
  }
  static testing::TempDir* dir_;
};
testing::TempDir* CalibrateStereoCommandTest::dir_ = nullptr;

TEST_F(CalibrateStereoCommandTest, TwoFoldersGiveTheRigAndNameThePairLeftOut) {
  CalibrateOptions options = Options();
  options.picture_file = dir_->file("epipolar.png");
  std::ostringstream report;
  const CalibrateSummary summary = RunCalibrate(options, report);
  EXPECT_EQ(summary.pairs, 9);
  EXPECT_EQ(summary.pairs_used, 8);
  EXPECT_THAT(summary.left_out, ::testing::ElementsAre("08.png + 08.png: left_only"));
  EXPECT_THAT(report.str(), HasSubstr("08.png + 08.png: left out, board in the left view only"));
  EXPECT_THAT(report.str(), HasSubstr("in both views of 8 of 9 pairs"));
  EXPECT_NEAR(summary.baseline_mm, 100.0, 0.5);

  const StereoCalibration stereo = LoadStereoCalibration(options.out_file);
  const StereoRig rig = MakeStereoRig();
  cv::Vec3d difference;
  cv::Rodrigues(stereo.R.t() * rig.R, difference);
  EXPECT_LT(cv::norm(difference) * 180.0 / CV_PI, 0.1);
  EXPECT_NEAR(stereo.baseline_mm(), 100.0, 0.5);
  const cv::Mat picture = cv::imread(*options.picture_file);
  EXPECT_EQ(picture.size(), cv::Size(1280, 480));
  std::cout << report.str();
}

TEST_F(CalibrateStereoCommandTest, BadInputIsOneLineNamingTheCulprit) {
  CalibrateOptions options = Options();
  options.right.reset();
  EXPECT_THAT(ErrorOf(options),
              HasSubstr("--right: stereo calibration needs both --left and --right"));

  options = Options();
  options.input = dir_->file("left");
  EXPECT_THAT(ErrorOf(options), HasSubstr("give one of --input"));

  fs::create_directories(dir_->path() / "short");
  fs::copy_file(dir_->path() / "right" / "00.png", dir_->path() / "short" / "00.png",
                fs::copy_options::overwrite_existing);
  options = Options();
  options.right = dir_->file("short");
  EXPECT_THAT(ErrorOf(options), HasSubstr("--left has 9 images but --right 1"));

  // One folder of views given as both cameras': two cameras at one place (baseline 0).
  options = Options();
  options.right = options.left;
  options.out_file = dir_->file("one_place.yaml");
  EXPECT_THAT(ErrorOf(options), HasSubstr("is a view of both cameras"));
  EXPECT_FALSE(fs::exists(options.out_file));

  // The output guard: never write over an input.
  options = Options();
  options.picture_file = dir_->file("right/03.png");
  EXPECT_THAT(ErrorOf(options), HasSubstr("right/03.png"));
  EXPECT_FALSE(cv::imread(dir_->file("right/03.png")).empty());

  options = Options();
  options.picture_file = dir_->file("epipolar.png");
  options.left.reset();
  options.right.reset();
  options.input = dir_->file("left");
  EXPECT_THAT(ErrorOf(options), HasSubstr("--picture is used with --left and --right only"));
}

}  // namespace
}  // namespace softsight
