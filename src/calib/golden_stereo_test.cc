// Golden real data for stereo calibration: OpenCV's own stereo sample pairs (left01..14.jpg with
// right01..14.jpg, no pair 10: 13 pairs of 640x480 photographs of a 9x6 board, shipped by
// Debian's opencv-doc), against the answer of cv::stereoCalibrate called directly on them the
// way OpenCV's samples/cpp/stereo_calib.cpp finds the corners (findChessboardCorners,
// cornerSubPix with an 11x11 half-window; each camera calibrated on its own first, then the rig
// with the intrinsics fixed). The board's squares are 25 mm (as left_intrinsics.yml records).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "sim/opencv_samples.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/calib/triangulation.h"

namespace softsight {
namespace {

const char* const kPairNumbers[] = {"01", "02", "03", "04", "05", "06", "07",
                                    "08", "09", "11", "12", "13", "14"};

ChessboardSpec StereoBoard() {
  ChessboardSpec board;
  board.inner_corners = cv::Size(9, 6);
  board.square_mm = 25.0;
  return board;
}

struct SamplePair {
  std::string left_name, right_name;
  cv::Mat left, right;
};

// OpenCV's sample's corners of one view; absent when not found.
std::optional<std::vector<cv::Point2f>> SampleCorners(const cv::Mat& gray) {
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(gray, StereoBoard().inner_corners, corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    return std::nullopt;
  }
  cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 0.01));
  return corners;
}

// Rotation angle of R_a^T R_b, degrees.
double RotationDifferenceDeg(const cv::Matx33d& a, const cv::Matx33d& b) {
  cv::Vec3d rvec;
  cv::Rodrigues(a.t() * b, rvec);
  return cv::norm(rvec) * 180.0 / CV_PI;
}

// Loading the 26 images and calibrating is the slow part (about 1.5 s): once for the suite.
class GoldenStereoPairs : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    pairs_ = new std::vector<SamplePair>();
    for (const char* number : kPairNumbers) {
      SamplePair pair{
          std::string("left") + number + ".jpg", std::string("right") + number + ".jpg", {}, {}};
      for (const std::string* name : {&pair.left_name, &pair.right_name}) {
        if (!samples::OpenCvSample(*name)) {
          missing_ = new std::string(*name);
          return;
        }
      }
      pair.left = cv::imread(*samples::OpenCvSample(pair.left_name), cv::IMREAD_GRAYSCALE);
      pair.right = cv::imread(*samples::OpenCvSample(pair.right_name), cv::IMREAD_GRAYSCALE);
      pairs_->push_back(std::move(pair));
    }
    StereoCalibrationOptions options;
    options.camera.board = StereoBoard();
    StereoCalibrator calibrator(options);
    for (const SamplePair& pair : *pairs_) {
      calibrator.add(pair.left_name, pair.left, pair.right_name, pair.right);
    }
    ours_ = new StereoCalibrationResult(calibrator.calibrate());
  }
  static void TearDownTestSuite() {
    delete pairs_;
    delete ours_;
    delete missing_;
    pairs_ = nullptr;
    ours_ = nullptr;
    missing_ = nullptr;
  }
  void SetUp() override {
    if (missing_) GTEST_SKIP() << samples::MissingSampleMessage(*missing_);
  }

  static std::vector<SamplePair>* pairs_;
  static StereoCalibrationResult* ours_;
  static std::string* missing_;
};
std::vector<SamplePair>* GoldenStereoPairs::pairs_ = nullptr;
StereoCalibrationResult* GoldenStereoPairs::ours_ = nullptr;
std::string* GoldenStereoPairs::missing_ = nullptr;

// cv::calibrateCamera per camera (k3 fixed, as softsight's default) and cv::stereoCalibrate with
// the intrinsics fixed, called directly on `left` and `right` (the pairs' corners).
struct DirectStereo {
  cv::Matx33d R;
  double baseline_mm = 0;
  std::vector<double> pair_error_px;  // The larger of each pair's two views' RMS.
};
DirectStereo CallStereoCalibrate(const std::vector<std::vector<cv::Point2f>>& left,
                                 const std::vector<std::vector<cv::Point2f>>& right) {
  const std::vector<std::vector<cv::Point3f>> object(left.size(),
                                                     ChessboardObjectPoints(StereoBoard()));
  cv::Mat k1, d1, k2, d2, r, t, e, f, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  cv::calibrateCamera(object, left, cv::Size(640, 480), k1, d1, rvecs, tvecs, cv::CALIB_FIX_K3);
  cv::calibrateCamera(object, right, cv::Size(640, 480), k2, d2, rvecs, tvecs, cv::CALIB_FIX_K3);
  cv::stereoCalibrate(object, left, right, k1, d1, k2, d2, cv::Size(640, 480), r, t, e, f, per_view,
                      cv::CALIB_FIX_INTRINSIC);
  DirectStereo direct{cv::Matx33d(r), cv::norm(t), {}};
  for (int i = 0; i < per_view.rows; ++i) {
    direct.pair_error_px.push_back(std::max(per_view.at<double>(i, 0), per_view.at<double>(i, 1)));
  }
  return direct;
}

TEST_F(GoldenStereoPairs, BaselineAndRotationAgreeWithOpenCvsStereoCalibrate) {
  // 1. cv::stereoCalibrate called directly on the same corners: the pairing, the corner order,
  //    the intrinsics and the outlier rule change nothing on good data.
  std::vector<std::vector<cv::Point2f>> left, right;
  for (const SamplePair& pair : *pairs_) {
    left.push_back(*FindChessboard(pair.left, StereoBoard().inner_corners));
    right.push_back(*FindChessboard(pair.right, StereoBoard().inner_corners));
  }
  const DirectStereo direct = CallStereoCalibrate(left, right);
  const StereoCalibration& stereo = ours_->stereo;
  EXPECT_NEAR(stereo.baseline_mm() / direct.baseline_mm, 1.0, 0.01)
      << "ours " << stereo.baseline_mm() << " mm, cv::stereoCalibrate " << direct.baseline_mm;
  EXPECT_LT(RotationDifferenceDeg(stereo.R, direct.R), 0.1);

  // 2. OpenCV's sample end to end (its own corner detection, 11x11 window), on the pairs that
  //    detection gets right: its window reaches the neighbouring corners of the small boards of
  //    pairs 02 and 13 and pulls corners 3-5 px off (pair errors 1.2 and 0.55 px against a
  //    median of 0.24). Measured: baseline 83.32 vs 83.47 mm (0.2 %), rotation 0.21 deg apart:
  //    the rotation between the cameras trades off against each camera's principal point, which
  //    two detectors' corners put 1-2 px apart; with the two bad pairs kept OpenCV's own answer
  //    moves by 0.21 deg too.
  std::vector<std::vector<cv::Point2f>> sample_left, sample_right;
  for (const SamplePair& pair : *pairs_) {
    const auto l = SampleCorners(pair.left), r = SampleCorners(pair.right);
    ASSERT_TRUE(l && r) << pair.left_name;
    sample_left.push_back(*l);
    sample_right.push_back(*r);
  }
  const DirectStereo sample_all = CallStereoCalibrate(sample_left, sample_right);
  std::vector<double> sorted = sample_all.pair_error_px;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::vector<std::vector<cv::Point2f>> clean_left, clean_right;
  for (size_t i = 0; i < sample_left.size(); ++i) {
    if (sample_all.pair_error_px[i] <= 2.0 * median) {
      clean_left.push_back(sample_left[i]);
      clean_right.push_back(sample_right[i]);
    }
  }
  EXPECT_EQ(clean_left.size(), sample_left.size() - 2);
  const DirectStereo sample = CallStereoCalibrate(clean_left, clean_right);
  EXPECT_NEAR(stereo.baseline_mm() / sample.baseline_mm, 1.0, 0.01);
  EXPECT_LT(RotationDifferenceDeg(stereo.R, sample.R), 0.3);
  std::cout << "[ figures  ] baseline " << stereo.baseline_mm()
            << " mm; cv::stereoCalibrate on the "
            << "same corners " << direct.baseline_mm << " mm, rotation "
            << RotationDifferenceDeg(stereo.R, direct.R) << " deg apart; OpenCV's sample detection "
            << sample.baseline_mm << " mm, " << RotationDifferenceDeg(stereo.R, sample.R)
            << " deg apart\n";
}

TEST_F(GoldenStereoPairs, EveryPairIsUsedAndReportsItsError) {
  ASSERT_EQ(ours_->pairs.size(), std::size(kPairNumbers));
  EXPECT_EQ(ours_->pairs_used(), static_cast<int>(std::size(kPairNumbers)));
  for (const StereoPairReport& pair : ours_->pairs) {
    ASSERT_TRUE(pair.left_rms_px && pair.right_rms_px) << pair.left_name;
    EXPECT_LT(std::max(*pair.left_rms_px, *pair.right_rms_px), 1.0) << pair.left_name;
  }
}

TEST_F(GoldenStereoPairs, TriangulatedCornersAreOneSquareApart) {
  // Every corner of every pair in 3D; neighbours along rows and columns must be 25 mm apart.
  // Two figures: each pair's scale (the mean of its 85 neighbour distances: what the
  // calibration's metric is worth) within 0.5 % RMS over the pairs, and single neighbour
  // distances, which carry each corner's own detection noise through the depth: at these
  // boards' 270-400 mm with f = 535 px and an 83 mm baseline, depth error = Z^2 sigma / (f B)
  // = 2.4 mm per pixel of corner error, so the 0.1-0.2 px of the corners (the calibration's
  // 0.25 px RMS) give about 0.6 % on one 25 mm square (measured 0.65 %).
  const Triangulator triangulator(ours_->stereo);
  const cv::Size grid = StereoBoard().inner_corners;
  double sum_sq = 0.0, scale_sum_sq = 0.0;
  int count = 0;
  std::vector<std::string> rejected;
  for (const SamplePair& pair : *pairs_) {
    const auto l = FindChessboard(pair.left, grid), r = FindChessboard(pair.right, grid);
    ASSERT_TRUE(l && r) << pair.left_name;
    std::vector<cv::Point2f> right = *r;
    if ((l->back() - l->front()).dot(right.back() - right.front()) < 0) {
      std::reverse(right.begin(), right.end());
    }
    std::vector<std::optional<cv::Point3d>> points;
    for (size_t i = 0; i < l->size(); ++i) {
      const StereoPoint p = triangulator.triangulate(cv::Point2d((*l)[i]), cv::Point2d(right[i]));
      if (!p.found()) {
        EXPECT_EQ(p.status, StereoStatus::kEpipolar) << pair.left_name << " corner " << i;
        rejected.push_back(pair.right_name + " corner " + std::to_string(i));
      }
      points.push_back(p.position_mm);
    }
    double pair_sum = 0.0;
    int pair_count = 0;
    const auto add = [&](int a, int b) {
      const auto& pa = points[static_cast<size_t>(a)];
      const auto& pb = points[static_cast<size_t>(b)];
      if (!pa || !pb) return;
      const double e = cv::norm(*pa - *pb) / 25.0 - 1.0;
      sum_sq += e * e;
      pair_sum += e;
      ++pair_count;
    };
    for (int row = 0; row < grid.height; ++row) {
      for (int col = 0; col < grid.width; ++col) {
        if (col + 1 < grid.width) add(row * grid.width + col, row * grid.width + col + 1);
        if (row + 1 < grid.height) add(row * grid.width + col, (row + 1) * grid.width + col);
      }
    }
    ASSERT_GT(pair_count, 70) << pair.left_name;
    count += pair_count;
    const double scale_error = pair_sum / pair_count;
    scale_sum_sq += scale_error * scale_error;
  }
  // Corners on the board's edge that the detector misplaces by 2-4 px in one view (right02
  // corner 0, right05 corners 27 and 45, measured against a 5x5 window's refinement) break the
  // epipolar constraint and are not believed; every other corner of every pair is.
  EXPECT_LE(rejected.size(), 5u);
  for (const std::string& r : rejected) std::cout << "[ rejected ] " << r << "\n";
  const double scale_rms = std::sqrt(scale_sum_sq / static_cast<double>(pairs_->size()));
  const double neighbour_rms = std::sqrt(sum_sq / count);
  EXPECT_LT(scale_rms, 0.005) << "pairs' square size RMS error " << scale_rms * 100 << " %";
  EXPECT_LT(neighbour_rms, 0.008) << "neighbouring corners' distance RMS error "
                                  << neighbour_rms * 100 << " %";
  std::cout << "[ figures  ] square side from triangulated corners: per pair " << scale_rms * 100
            << " % RMS, per neighbour " << neighbour_rms * 100 << " % RMS (" << count
            << " neighbours, " << rejected.size() << " corners not believed)\n";
}

TEST_F(GoldenStereoPairs, APairWithTheBoardInOneViewOnlyAndAMismatchedPairAreLeftOut) {
  StereoCalibrationOptions options;
  options.camera.board = StereoBoard();
  StereoCalibrator calibrator(options);
  const cv::Size grid = StereoBoard().inner_corners;
  for (const SamplePair& pair : *pairs_) {
    calibrator.add_corners(pair.left_name, FindChessboard(pair.left, grid), pair.right_name,
                           FindChessboard(pair.right, grid), pair.left.size());
  }
  // The board in the left view only (the right camera's picture is blank).
  EXPECT_EQ(calibrator.add("left01.jpg", (*pairs_)[0].left, "blank.png",
                           cv::Mat(480, 640, CV_8UC1, cv::Scalar(128))),
            StereoPairStatus::kLeftOnly);
  // Two views of different moments: the board is in both, but they do not fit the rig.
  EXPECT_EQ(
      calibrator.add_corners("left03.jpg", FindChessboard((*pairs_)[2].left, grid), "right09.jpg",
                             FindChessboard((*pairs_)[8].right, grid), cv::Size(640, 480)),
      StereoPairStatus::kUsed);
  const StereoCalibrationResult result = calibrator.calibrate();
  ASSERT_EQ(result.pairs.size(), std::size(kPairNumbers) + 2);
  EXPECT_EQ(result.pairs[std::size(kPairNumbers)].status, StereoPairStatus::kLeftOnly);
  EXPECT_EQ(result.pairs[std::size(kPairNumbers)].right_name, "blank.png");
  const StereoPairReport& mismatched = result.pairs.back();
  EXPECT_EQ(mismatched.status, StereoPairStatus::kOutlier);
  EXPECT_EQ(mismatched.right_name, "right09.jpg");
  EXPECT_EQ(result.pairs_used(), static_cast<int>(std::size(kPairNumbers)));
  // Left out, the rig is the one calibrated without it.
  EXPECT_NEAR(result.stereo.baseline_mm(), ours_->stereo.baseline_mm(),
              0.005 * ours_->stereo.baseline_mm());
}

}  // namespace
}  // namespace softsight
