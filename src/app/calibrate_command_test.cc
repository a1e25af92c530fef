// End to end: chessboard views rendered with a known camera, written as files, calibrated by
// the command's typed function; the files it writes are read back and checked against truth.
#include "app/calibrate_command.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "app/calibrate_test_util.h"
#include "calib/calibration_test_views.h"
#include "core/test_util.h"
#include "sim/opencv_samples.h"
#include "softsight/calib/camera_calibration.h"
#include "softsight/core/error.h"
#include "softsight/sim/chessboard.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

class CalibrateCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    suite_dir_ = new testing::TempDir("calibrate_command");
    dir_ = &suite_dir_->path();
    fs::create_directories(*dir_ / "views");
    const ChessboardRenderer renderer(testviews::Camera(), testviews::Pattern());
    for (const testviews::View& view : testviews::RenderViews(renderer, 10)) {
      cv::imwrite((*dir_ / "views" / view.name).string(), view.image);
    }
    // A view without the board, which must be listed, not fatal.
    cv::imwrite((*dir_ / "views" / "blank.png").string(),
                cv::Mat(testviews::Camera().image_size, CV_8UC1, cv::Scalar(128)));
    cv::Mat plane;
    renderer.render(LookAtBoard(testviews::Pattern(), kPlaneDistanceMm, 0, 0, 0), plane);
    cv::imwrite((*dir_ / "plane.png").string(), plane);
  }
  static void TearDownTestSuite() {
    delete suite_dir_;
    suite_dir_ = nullptr;
    dir_ = nullptr;
  }

  static CalibrateOptions CameraOptions() {
    CalibrateOptions options;
    options.input = (*dir_ / "views").string();
    options.chessboard = "9x6";
    options.square_mm = 25.0;
    options.out_file = (*dir_ / "camera.yaml").string();
    return options;
  }

  static constexpr double kPlaneDistanceMm = 560.0;
  static testing::TempDir* suite_dir_;  // Made in SetUpTestSuite, removed in TearDownTestSuite.
  static const fs::path* dir_;
};
testing::TempDir* CalibrateCommandTest::suite_dir_ = nullptr;
const fs::path* CalibrateCommandTest::dir_ = nullptr;

TEST_F(CalibrateCommandTest, FolderOfViewsGivesTheCameraWithinOnePercent) {
  std::ostringstream report;
  const CalibrateSummary summary = RunCalibrate(CameraOptions(), report);
  EXPECT_EQ(summary.images, 11);
  EXPECT_THAT(summary.not_found, ElementsAre("blank.png"));
  EXPECT_THAT(report.str(), HasSubstr("found in 10 of 11 images"));
  EXPECT_THAT(report.str(), HasSubstr("board not found in 1: blank.png"));
  EXPECT_THAT(report.str(), HasSubstr("reprojection RMS"));
  EXPECT_LT(summary.rms_px, 0.15);

  const CameraIntrinsics camera = LoadCameraIntrinsics(CameraOptions().out_file);
  const cv::Matx33d truth = testviews::Camera().camera_matrix;
  EXPECT_EQ(camera.image_size, testviews::Camera().image_size);
  EXPECT_NEAR(camera.camera_matrix(0, 0), truth(0, 0), 0.01 * truth(0, 0));
  EXPECT_NEAR(camera.camera_matrix(1, 1), truth(1, 1), 0.01 * truth(1, 1));
  EXPECT_DOUBLE_EQ(camera.camera_matrix(0, 0), summary.fx_px);

  // Then the plane, undistorted with that file: a fronto-parallel board at distance Z has
  // Z / f millimetres per pixel.
  CalibrateOptions plane;
  plane.plane_image = (*dir_ / "plane.png").string();
  plane.camera_file = CameraOptions().out_file;
  plane.chessboard = "9x6";
  plane.square_mm = 25.0;
  plane.out_file = (*dir_ / "plane.yaml").string();
  std::ostringstream plane_report;
  const CalibrateSummary plane_summary = RunCalibrate(plane, plane_report);
  const double expected = kPlaneDistanceMm / std::sqrt(truth(0, 0) * truth(1, 1));
  EXPECT_NEAR(plane_summary.mm_per_px, expected, 0.005 * expected);
  EXPECT_NEAR(LoadPlaneCalibration(plane.out_file).mm_per_px, plane_summary.mm_per_px, 1e-9);
  EXPECT_THAT(plane_report.str(), HasSubstr("mm/px"));
  std::cout << report.str() << plane_report.str();
}

TEST_F(CalibrateCommandTest, PrintfPatternAndVideoInputs) {
  CalibrateOptions options = CameraOptions();
  options.input = (*dir_ / "views" / "view%d.png").string();
  std::ostringstream report;
  EXPECT_EQ(RunCalibrate(options, report).images, 10);

  // A lossless video of the views, every second frame used.
  const std::string video_file = (*dir_ / "views.avi").string();
  {
    cv::VideoWriter writer(video_file, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 10.0,
                           testviews::Camera().image_size, /*isColor=*/false);
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 10; ++i) {
      const cv::Mat image =
          cv::imread((*dir_ / "views" / ("view" + std::to_string(i) + ".png")).string(),
                     cv::IMREAD_GRAYSCALE);
      writer.write(image);
      writer.write(image);  // Each view twice, as a slow-moving video would show it.
    }
  }
  options.input = video_file;
  options.step = 2;
  const CalibrateSummary summary = RunCalibrate(options, report);
  EXPECT_EQ(summary.images, 10);
  EXPECT_TRUE(summary.not_found.empty());
  const double fx = testviews::Camera().camera_matrix(0, 0);
  EXPECT_NEAR(summary.fx_px, fx, 0.01 * fx);
}

// A numbered pattern with a gap (a view deleted as blurred) is not cut short at it: every file
// is a view, and the report says which numbers were missing.
TEST_F(CalibrateCommandTest, APatternWithAGapUsesEveryFileAndSaysSo) {
  fs::create_directories(*dir_ / "gappy");
  for (int i = 0; i < 10; ++i) {
    if (i == 4) continue;
    const std::string name = "view" + std::to_string(i) + ".png";
    fs::copy_file(*dir_ / "views" / name, *dir_ / "gappy" / name,
                  fs::copy_options::overwrite_existing);
  }
  CalibrateOptions options = CameraOptions();
  options.input = (*dir_ / "gappy" / "view%d.png").string();
  options.out_file = (*dir_ / "gappy.yaml").string();
  std::ostringstream report;
  const CalibrateSummary summary = RunCalibrate(options, report);
  EXPECT_EQ(summary.images, 9) << report.str();
  EXPECT_THAT(report.str(), HasSubstr("the numbering has gaps: 1 file number missing (first: 4)"));
  EXPECT_THAT(report.str(), HasSubstr("found in 9 of 9 images"));
  const double fx = testviews::Camera().camera_matrix(0, 0);
  EXPECT_NEAR(summary.fx_px, fx, 0.01 * fx);
}

// OpenCV's sample chessboards are left01.jpg .. left14.jpg without left10 (opencv-doc).
TEST_F(CalibrateCommandTest, OpenCvsSampleChessboardsThroughAPatternAreAllThirteenViews) {
  if (!samples::OpenCvSample("left11.jpg")) GTEST_SKIP() << samples::MissingSampleMessage("left11.jpg");
  CalibrateOptions options = CameraOptions();
  options.input = samples::OpenCvSamplesDir() + "/left%02d.jpg";
  options.out_file = (*dir_ / "left.yaml").string();
  std::ostringstream report;
  const CalibrateSummary summary = RunCalibrate(options, report);
  EXPECT_EQ(summary.images, 13) << report.str();
  EXPECT_THAT(report.str(), HasSubstr("1 file number missing (first: 10)"));
  EXPECT_THAT(report.str(), HasSubstr("found in 13 of 13 images"));
}

using testing::CalibrateErrorOf;

TEST_F(CalibrateCommandTest, BadInputIsOneLineNamingTheCulprit) {
  CalibrateOptions options = CameraOptions();
  options.input = (*dir_ / "no_such_folder").string();
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("no_such_folder: no such file or folder"));

  options = CameraOptions();
  options.chessboard = "9*6";
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("--chessboard: expected inner corners"));

  options = CameraOptions();
  options.chessboard = "7x5";  // Wrong count: the board is found nowhere.
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("found in 0 of 11 images"));

  options = CameraOptions();
  options.square_mm = 0;
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("--square-mm"));

  options = CameraOptions();
  options.plane_image = (*dir_ / "plane.png").string();
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("give one of --input"));

  fs::create_directories(*dir_ / "empty");
  options = CameraOptions();
  options.input = (*dir_ / "empty").string();
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("holds no image files"));

  const std::string corrupt = (*dir_ / "corrupt" / "a.png").string();
  fs::create_directories(*dir_ / "corrupt");
  std::ofstream(corrupt) << "not a png";
  options.input = (*dir_ / "corrupt").string();
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("a.png: cannot read"));

  options = CameraOptions();
  options.input.reset();
  options.plane_image = (*dir_ / "views" / "blank.png").string();
  options.out_file = (*dir_ / "plane_blank.yaml").string();
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("blank.png: the 9x6 chessboard was not found"));

  options.plane_image = (*dir_ / "plane.png").string();
  options.camera_file = (*dir_ / "missing_camera.yaml").string();
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("missing_camera.yaml: cannot open"));
}

std::string FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST_F(CalibrateCommandTest, NoInputIsOverwrittenAndAFailedWriteIsAnErrorThatKeepsTheOldFile) {
  // --out naming one of the views: refused before any work, the picture as it was.
  const fs::path view = *fs::directory_iterator(*dir_ / "views");
  const std::string before = FileBytes(view);
  CalibrateOptions options = CameraOptions();
  options.out_file = view.string();
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("refusing to overwrite an input"));
  EXPECT_EQ(FileBytes(view), before);
  // ... or a link to it.
  const fs::path link = *dir_ / "link_to_view.png";
  fs::remove(link);
  fs::create_symlink(view, link);
  options.out_file = link.string();
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("refusing to overwrite an input"));
  EXPECT_EQ(FileBytes(view), before);

  // The plane's scale written over the camera's intrinsics it reads: refused, intrinsics kept.
  std::ostringstream report;
  RunCalibrate(CameraOptions(), report);
  const fs::path camera = *dir_ / "camera.yaml";
  const std::string intrinsics = FileBytes(camera);
  options = CameraOptions();
  options.input.reset();
  options.plane_image = (*dir_ / "plane.png").string();
  options.camera_file = camera.string();
  options.out_file = camera.string();
  EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("refusing to overwrite an input"));
  EXPECT_EQ(FileBytes(camera), intrinsics);

  // A write that fails (a full disk) is an error naming the file, never "wrote".
  if (fs::exists("/dev/full")) {
    options = CameraOptions();
    options.out_file = "/dev/full";
    EXPECT_THAT(CalibrateErrorOf(options), HasSubstr("/dev/full: cannot write it"));
  }
  // The calibration lands whole or not at all: written beside it, then renamed over it.
  EXPECT_FALSE(fs::exists(camera.string() + ".part"));
  EXPECT_THAT(FileBytes(camera), HasSubstr("camera_matrix"));
}

}  // namespace
}  // namespace softsight
