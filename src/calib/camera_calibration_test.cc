#include "softsight/calib/camera_calibration.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "calib/calibration_test_views.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/sim/chessboard.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;
using ::testing::DoubleNear;
using ::testing::HasSubstr;
using ::testing::Optional;

// Detection may start at either end of the board; align to the truth's order.
std::vector<cv::Point2f> Aligned(std::vector<cv::Point2f> found,
                                 const std::vector<cv::Point2f>& truth) {
  if (cv::norm(found.front() - truth.front()) > cv::norm(found.back() - truth.front())) {
    std::reverse(found.begin(), found.end());
  }
  return found;
}

struct Errors {
  double rms = 0.0, max = 0.0;
};
Errors CompareCorners(const std::vector<cv::Point2f>& found, const std::vector<cv::Point2f>& truth) {
  Errors e;
  for (size_t i = 0; i < truth.size(); ++i) {
    const double d = cv::norm(found[i] - truth[i]);
    e.rms += d * d;
    e.max = std::max(e.max, d);
  }
  e.rms = std::sqrt(e.rms / static_cast<double>(truth.size()));
  return e;
}

// A file in one folder for the whole suite, removed when the test program ends.
// Rendering and calibrating is the slow part: done once for the whole suite.
class CalibrationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    renderer_ = new ChessboardRenderer(testviews::Camera(), testviews::Pattern());
    views_ = new std::vector<testviews::View>(testviews::RenderViews(*renderer_));
    CalibrationOptions options;
    options.board = testviews::Spec();
    ChessboardCalibrator calibrator(options);
    for (const testviews::View& view : *views_) calibrator.add(view.name, view.image);
    result_ = new CalibrationResult(calibrator.calibrate());
  }
  static void TearDownTestSuite() {
    delete result_;
    delete views_;
    delete renderer_;
  }
  static ChessboardRenderer* renderer_;
  static std::vector<testviews::View>* views_;
  static CalibrationResult* result_;
};
ChessboardRenderer* CalibrationTest::renderer_ = nullptr;
std::vector<testviews::View>* CalibrationTest::views_ = nullptr;
CalibrationResult* CalibrationTest::result_ = nullptr;

TEST_F(CalibrationTest, RenderedCornersAreFoundWhereTheLensModelProjectsThem) {
  // Validates renderer and detector together: sub-pixel corners on supersampled images of a
  // distorted lens land on the exact projections.
  for (const testviews::View& view : *views_) {
    ASSERT_TRUE(view.truth.all_corners_inside) << view.name;
    const std::optional<std::vector<cv::Point2f>> found =
        FindChessboard(view.image, testviews::Spec().inner_corners);
    ASSERT_TRUE(found.has_value()) << view.name;
    const Errors e = CompareCorners(Aligned(*found, view.truth.corners_px), view.truth.corners_px);
    // cornerSubPix itself is good to about 0.1 px on these images (its fixed point does not
    // move with the start or with more supersampling); calibration averages that out.
    EXPECT_LT(e.rms, 0.12) << view.name;
    EXPECT_LT(e.max, 0.3) << view.name;
  }
}

TEST(ChessboardRendererTest, EdgeCoverageIsExactArea) {
  // Fronto-parallel board, no distortion: along one image row the paper's left edge (white
  // margin on the background) is a vertical edge. Summing each pixel's white fraction from the
  // image border to a pixel inside the margin gives the edge position by area, which must
  // match the projection to within the sub-sample quantisation (1/16 px at supersample 4).
  CameraModel camera = testviews::Camera();
  camera.distortion.clear();
  ChessboardLook look;
  look.supersample = 4;
  const ChessboardPattern pattern = testviews::Pattern();
  const ChessboardRenderer renderer(camera, pattern, look);
  for (const double shift_mm : {0.0, 0.37, 1.11}) {
    const BoardPose pose = LookAtBoard(pattern, 600.0, 0, 0, 0, shift_mm, 0);
    cv::Mat image;
    renderer.render(pose, image);
    const double v_mm = 2.5 * pattern.square_mm;
    const cv::Point2d edge = renderer.project(pose, {-pattern.square_mm - pattern.margin_mm, v_mm});
    const cv::Point2d inside = renderer.project(pose, {-pattern.square_mm - 0.3 * pattern.margin_mm,
                                                       v_mm});
    const int row = static_cast<int>(std::lround(edge.y));
    const int last = static_cast<int>(std::floor(inside.x));
    double white_fraction_sum = 0.0;
    for (int j = 0; j <= last; ++j) {
      white_fraction_sum += (image.at<uchar>(row, j) - look.background) /
                            static_cast<double>(look.white - look.background);
    }
    EXPECT_NEAR(last + 0.5 - white_fraction_sum, edge.x, 0.04) << shift_mm;
  }
}

TEST_F(CalibrationTest, RecoversTheFocalLengthWithinOnePercent) {
  const cv::Matx33d truth = testviews::Camera().camera_matrix;
  const cv::Matx33d& k = result_->camera.camera_matrix;
  EXPECT_EQ(result_->used.size(), views_->size());
  EXPECT_TRUE(result_->not_found.empty());
  EXPECT_EQ(result_->camera.image_size, testviews::Camera().image_size);
  EXPECT_NEAR(k(0, 0), truth(0, 0), 0.01 * truth(0, 0));
  EXPECT_NEAR(k(1, 1), truth(1, 1), 0.01 * truth(1, 1));
  EXPECT_NEAR(k(0, 2), truth(0, 2), 2.0);
  EXPECT_NEAR(k(1, 2), truth(1, 2), 2.0);
  EXPECT_LT(result_->rms_px, 0.1);
  ASSERT_EQ(result_->camera.distortion.size(), 5u);
  EXPECT_NEAR(result_->camera.distortion[0], testviews::Camera().distortion[0], 0.02);
  std::cout << "fx " << k(0, 0) << " (truth " << truth(0, 0) << "), fy " << k(1, 1) << " (truth "
            << truth(1, 1) << "), rms " << result_->rms_px << " px\n";
}

TEST_F(CalibrationTest, UndistortedImageMatchesTheDistortionFreeProjection) {
  // Undistort with the TRUE camera (the estimate is tested above): corners found in the result
  // must sit where an ideal pinhole camera with the same matrix sees them.
  CameraIntrinsics camera;
  camera.image_size = testviews::Camera().image_size;
  camera.camera_matrix = testviews::Camera().camera_matrix;
  camera.distortion = testviews::Camera().distortion;
  const Undistorter undistorter(camera);
  CameraModel ideal = testviews::Camera();
  ideal.distortion.clear();
  cv::Mat undistorted;
  const testviews::View& view = views_->at(5);
  undistorter.apply(view.image, undistorted);
  const uchar* buffer = undistorted.data;
  undistorter.apply(view.image, undistorted);
  EXPECT_EQ(undistorted.data, buffer) << "apply() reallocated its output";

  const std::optional<std::vector<cv::Point2f>> found =
      FindChessboard(undistorted, testviews::Spec().inner_corners);
  ASSERT_TRUE(found.has_value());
  std::vector<cv::Point2f> ideal_corners;
  const ChessboardRenderer ideal_projector(ideal, testviews::Pattern(), ChessboardLook{});
  for (const cv::Point3f& p : ChessboardObjectPoints(testviews::Spec())) {
    ideal_corners.push_back(cv::Point2f(ideal_projector.project(view.pose, {p.x, p.y})));
  }
  // Bilinear remapping softens the image slightly; corners still land within a tenth of a
  // pixel, while distortion moves them by several pixels in this view.
  const Errors e = CompareCorners(Aligned(*found, ideal_corners), ideal_corners);
  EXPECT_LT(e.rms, 0.1);
  EXPECT_LT(e.max, 0.25);
  const Errors raw = CompareCorners(Aligned(view.truth.corners_px, ideal_corners), ideal_corners);
  EXPECT_GT(raw.max, 3.0) << "the test view should show visible distortion";

  // Point undistortion agrees with the image remap.
  std::vector<cv::Point2f> points;
  undistorter.undistort_points(view.truth.corners_px, points);
  EXPECT_LT(CompareCorners(Aligned(points, ideal_corners), ideal_corners).max, 1e-3);
  const cv::Point2d one = undistorter.undistort_point(view.truth.corners_px[0]);
  EXPECT_NEAR(one.x, points[0].x, 1e-3);
  EXPECT_NEAR(one.y, points[0].y, 1e-3);
}

TEST_F(CalibrationTest, PlaneHomographyGivesTheScaleWithinHalfAPercent) {
  // A board lying in the actuator's plane, seen tilted by the calibrated camera. Distances
  // between arbitrary plane points (not the corners the fit used) come out in millimetres.
  const BoardPose pose = LookAtBoard(testviews::Pattern(), 520.0, 12.0, -8.0, 4.0, 10.0, -5.0);
  cv::Mat image;
  renderer_->render(pose, image);
  const PlaneCalibration plane =
      CalibratePlane(image, "plane.png", testviews::Spec(), result_->camera);
  EXPECT_LT(plane.rms_mm, 0.1);
  const Undistorter undistorter(result_->camera);
  const std::pair<cv::Point2d, cv::Point2d> pairs[] = {
      {{12.5, 37.5}, {187.5, 112.5}}, {{-10.0, 0.0}, {210.0, 0.0}}, {{30.0, -5.0}, {30.0, 130.0}}};
  for (const auto& [a_mm, b_mm] : pairs) {
    const cv::Point2d a_px = undistorter.undistort_point(renderer_->project(pose, a_mm));
    const cv::Point2d b_px = undistorter.undistort_point(renderer_->project(pose, b_mm));
    const std::optional<cv::Point2d> a = MapToPlane(plane.plane_mm_from_image, a_px);
    const std::optional<cv::Point2d> b = MapToPlane(plane.plane_mm_from_image, b_px);
    ASSERT_TRUE(a && b);
    const double truth = cv::norm(a_mm - b_mm);
    EXPECT_NEAR(cv::norm(*a - *b), truth, 0.005 * truth) << a_mm << " " << b_mm;
  }
}

TEST_F(CalibrationTest, FrontoParallelPlaneScaleIsDistanceOverFocalLength) {
  const double distance_mm = 560.0;
  const BoardPose pose = LookAtBoard(testviews::Pattern(), distance_mm, 0, 0, 0);
  cv::Mat image;
  renderer_->render(pose, image);
  const PlaneCalibration plane =
      CalibratePlane(image, "plane.png", testviews::Spec(), result_->camera);
  const cv::Matx33d k = testviews::Camera().camera_matrix;
  const double truth = distance_mm / std::sqrt(k(0, 0) * k(1, 1));
  EXPECT_NEAR(plane.mm_per_px, truth, 0.005 * truth);
}

TEST_F(CalibrationTest, SavedCalibrationLoadsBackExactly) {
  const testing::TempDir dir;
  const std::string file = dir.file("camera.yaml");
  SaveCameraCalibration(*result_, testviews::Spec(), file);
  const CameraIntrinsics loaded = LoadCameraIntrinsics(file);
  EXPECT_EQ(loaded.image_size, result_->camera.image_size);
  for (int i = 0; i < 9; ++i) {
    EXPECT_DOUBLE_EQ(loaded.camera_matrix.val[i], result_->camera.camera_matrix.val[i]);
  }
  ASSERT_EQ(loaded.distortion.size(), result_->camera.distortion.size());
  for (size_t i = 0; i < loaded.distortion.size(); ++i) {
    EXPECT_DOUBLE_EQ(loaded.distortion[i], result_->camera.distortion[i]);
  }
  std::ifstream in(file);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_THAT(text, HasSubstr("avg_reprojection_error"));
  EXPECT_THAT(text, HasSubstr("!!opencv-matrix"));
}

TEST(CameraFileTest, BadFilesAreInputErrorsNamingFileAndKey) {
  const testing::TempDir dir;
  EXPECT_THROW(
      {
        try {
          LoadCameraIntrinsics(dir.file("does_not_exist.yaml"));
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("does_not_exist.yaml"));
          throw;
        }
      },
      InputError);
  const std::string file = dir.file("no_matrix.yaml");
  std::ofstream(file) << "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n";
  try {
    LoadCameraIntrinsics(file);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("camera_matrix: missing"));
  }
  const std::string garbage = dir.file("garbage.yaml");
  std::ofstream(garbage) << "%YAML:1.0\n---\nimage_width: [unclosed\n";
  EXPECT_THROW(LoadCameraIntrinsics(garbage), InputError);
}

TEST(PlaneFileTest, SavedPlaneLoadsBack) {
  PlaneCalibration plane;
  plane.plane_mm_from_image = cv::Matx33d(0.2, 0.01, -3, 0.002, 0.21, 4, 1e-5, 2e-5, 1);
  plane.mm_per_px = 0.205;
  plane.rms_mm = 0.01;
  const testing::TempDir dir;
  const std::string file = dir.file("plane.yaml");
  SavePlaneCalibration(plane, file);
  const PlaneCalibration loaded = LoadPlaneCalibration(file);
  for (int i = 0; i < 9; ++i) {
    EXPECT_DOUBLE_EQ(loaded.plane_mm_from_image.val[i], plane.plane_mm_from_image.val[i]);
  }
  EXPECT_DOUBLE_EQ(loaded.mm_per_px, 0.205);

  const std::string singular = dir.file("singular_plane.yaml");
  plane.plane_mm_from_image = cv::Matx33d(1, 2, 3, 2, 4, 6, 0, 0, 1);
  SavePlaneCalibration(plane, singular);
  EXPECT_THROW(LoadPlaneCalibration(singular), InputError);
}

TEST(ChessboardCalibratorTest, NoBoardAnywhereIsAnInputError) {
  ChessboardCalibrator calibrator(CalibrationOptions{});
  const cv::Mat blank(240, 320, CV_8UC1, cv::Scalar(128));
  EXPECT_FALSE(calibrator.add("a.png", blank));
  EXPECT_FALSE(calibrator.add("b.png", blank));
  try {
    calibrator.calibrate();
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("found in 0 of 2 images"));
  }
  EXPECT_THROW(calibrator.add("c.png", cv::Mat(100, 100, CV_8UC1, cv::Scalar(0))), InputError);
}

TEST(ChessboardSpecTest, ParsesInnerCornerCounts) {
  EXPECT_EQ(ParseChessboardSize("9x6", "--chessboard"), cv::Size(9, 6));
  EXPECT_EQ(ParseChessboardSize("7X5", "--chessboard"), cv::Size(7, 5));
  for (const char* bad : {"9*6", "x6", "9x", "1x6", "nine", "", "9x6x2", "-9x6"}) {
    try {
      ParseChessboardSize(bad, "--chessboard");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("--chessboard"));
      EXPECT_THAT(e.what(), HasSubstr(std::string("'") + bad + "'"));
    }
  }
  ChessboardSpec spec;
  std::string error;
  EXPECT_TRUE(spec.Check(&error));
  spec.square_mm = 0;
  EXPECT_FALSE(spec.Check(&error));
  EXPECT_THAT(error, HasSubstr("square_mm"));
}

TEST(ScaleFromTwoPointsTest, KnownDistance) {
  EXPECT_DOUBLE_EQ(ScaleFromTwoPoints({10, 10}, {310, 410}, 100.0), 0.2);
  EXPECT_THROW(ScaleFromTwoPoints({10, 10}, {10.2, 10}, 100.0), InputError);
  EXPECT_THROW(ScaleFromTwoPoints({10, 10}, {300, 10}, 0.0), InputError);
  EXPECT_THROW(ScaleFromTwoPoints({10, 10}, {300, 10}, std::nan("")), InputError);
}

}  // namespace
}  // namespace softsight
