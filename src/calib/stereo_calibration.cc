#include "softsight/calib/stereo_calibration.h"

#include <algorithm>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/calibration_internals.h"
#include "softsight/core/error.h"

namespace softsight {

using calib_internal::CalibrateFromCorners;
using calib_internal::DistortionMat;
using calib_internal::OpenForReading;
using calib_internal::FinishWriting;
using calib_internal::OpenForWriting;
using calib_internal::ReadMatrix;
using calib_internal::ReadPositiveInt;
using calib_internal::SizeText;

namespace {

cv::Matx33d Skew(const cv::Vec3d& t) {
  return cv::Matx33d(0, -t[2], t[1], t[2], 0, -t[0], -t[1], t[0], 0);
}

bool Finite(const cv::Mat& m) { return cv::checkRange(m); }

// The larger of a pair's two views' errors: a pair fits when both of its views do.
double PairError(const StereoPairReport& pair) {
  return std::max(pair.left_rms_px.value_or(0.0), pair.right_rms_px.value_or(0.0));
}

double Median(std::vector<double> values) {
  CV_Assert(!values.empty());
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  return values[mid];
}

}  // namespace

const char* StereoPairStatusName(StereoPairStatus status) {
  switch (status) {
    case StereoPairStatus::kUsed: return "used";
    case StereoPairStatus::kLeftOnly: return "left_only";
    case StereoPairStatus::kRightOnly: return "right_only";
    case StereoPairStatus::kNeither: return "neither";
    case StereoPairStatus::kOutlier: return "outlier";
  }
  return "?";
}

bool StereoCalibration::Check(std::string* error) const {
  if (left.image_size.empty() || left.image_size != right.image_size) {
    *error = "image size: both cameras need one resolution, got " + SizeText(left.image_size) +
             " and " + SizeText(right.image_size);
    return false;
  }
  const std::pair<const char*, cv::Mat> matrices[] = {
      {"camera_matrix_left", cv::Mat(left.camera_matrix)},
      {"camera_matrix_right", cv::Mat(right.camera_matrix)},
      {"R", cv::Mat(R)},
      {"T", cv::Mat(T)},
      {"F", cv::Mat(F)},
      {"P1", cv::Mat(P1)},
      {"P2", cv::Mat(P2)}};
  for (const auto& [name, m] : matrices) {
    if (!Finite(m)) {
      *error = std::string(name) + ": has a non-finite entry";
      return false;
    }
  }
  // R must be a rotation: R R^T = I and det R = +1 (a reflection would mirror the scene).
  if (cv::norm(R * R.t() - cv::Matx33d::eye()) > 1e-6 || cv::determinant(R) < 0) {
    *error = "R: not a rotation matrix";
    return false;
  }
  if (!(cv::norm(T) > 0)) {
    *error = "T: the cameras are at the same place (baseline 0): no depth from two views";
    return false;
  }
  // A baseline no bench has (beyond 100 m) is a corrupt file: its depths overflow to inf/nan.
  constexpr double kMaxBaselineMm = 1e5;
  if (!(cv::norm(T) <= kMaxBaselineMm)) {
    *error = "T: a baseline of " + std::to_string(cv::norm(T)) +
             " mm (more than 100 m between the cameras): not a calibration of a bench";
    return false;
  }
  for (const auto& [name, d] : {std::pair{"distortion_left", &left.distortion},
                                std::pair{"distortion_right", &right.distortion}}) {
    for (const double k : *d) {
      // Lens distortion coefficients beyond 1e3 map every point outside the image.
      if (!(std::isfinite(k) && std::abs(k) <= 1e3)) {
        *error = std::string(name) + ": a coefficient of " + std::to_string(k) +
                 " (no lens distorts beyond 1e3): a corrupt file";
        return false;
      }
    }
  }
  return true;
}

void CompleteStereoCalibration(StereoCalibration& stereo) {
  stereo.E = Skew(stereo.T) * stereo.R;
  stereo.F = stereo.right.camera_matrix.inv().t() * stereo.E * stereo.left.camera_matrix.inv();
  stereo.F *= 1.0 / cv::norm(stereo.F);
  cv::Mat r1, r2, p1, p2, q;
  cv::stereoRectify(stereo.left.camera_matrix, DistortionMat(stereo.left.distortion),
                    stereo.right.camera_matrix, DistortionMat(stereo.right.distortion),
                    stereo.left.image_size, stereo.R, stereo.T, r1, r2, p1, p2, q,
                    cv::CALIB_ZERO_DISPARITY, 0.0);
  stereo.R1 = cv::Matx33d(r1);
  stereo.R2 = cv::Matx33d(r2);
  stereo.P1 = cv::Matx34d(p1);
  stereo.P2 = cv::Matx34d(p2);
  stereo.Q = cv::Matx44d(q);
}

bool StereoCalibrationOptions::Check(std::string* error) const {
  if (!camera.Check(error)) return false;
  if (!(std::isfinite(outlier_factor) && outlier_factor >= 1.0)) {
    *error = "outlier_factor: must be >= 1 (times the median pair's error), got " +
             std::to_string(outlier_factor);
    return false;
  }
  if (!(std::isfinite(outlier_floor_px) && outlier_floor_px > 0.0)) {
    *error = "outlier_floor_px: must be > 0, got " + std::to_string(outlier_floor_px);
    return false;
  }
  return true;
}

int StereoCalibrationResult::pairs_used() const {
  return static_cast<int>(std::count_if(pairs.begin(), pairs.end(), [](const StereoPairReport& p) {
    return p.status == StereoPairStatus::kUsed;
  }));
}

StereoCalibrator::StereoCalibrator(StereoCalibrationOptions options)
    : options_(std::move(options)) {
  std::string error;
  if (!options_.Check(&error)) throw InputError("stereo calibration: " + error);
}

StereoPairStatus StereoCalibrator::add(const std::string& left_name, const cv::Mat& left_image,
                                       const std::string& right_name, const cv::Mat& right_image) {
  if (left_image.empty()) throw InputError(left_name + ": empty image");
  if (right_image.empty()) throw InputError(right_name + ": empty image");
  if (left_image.size() != right_image.size()) {
    throw InputError(right_name + ": image is " + SizeText(right_image.size()) + " but " +
                     left_name + " is " + SizeText(left_image.size()) +
                     "; set both cameras to one resolution");
  }
  const cv::Size& board = options_.camera.board.inner_corners;
  return add_corners(left_name, FindChessboard(left_image, board), right_name,
                     FindChessboard(right_image, board), left_image.size());
}

StereoPairStatus StereoCalibrator::add_corners(
    const std::string& left_name, std::optional<std::vector<cv::Point2f>> left_corners,
    const std::string& right_name, std::optional<std::vector<cv::Point2f>> right_corners,
    const cv::Size& image_size) {
  if (image_size_.empty()) {
    image_size_ = image_size;
  } else if (image_size != image_size_) {
    throw InputError(left_name + ": image is " + SizeText(image_size) +
                     " but the first pair's are " + SizeText(image_size_) +
                     "; calibrate one resolution at a time");
  }
  if (left_corners && right_corners) {
    // findChessboardCorners may start a board at either end (a 180 degree turn of the grid),
    // and the two cameras need not agree. Both see the board from nearly the same side, so
    // the first-to-last corner direction agrees in both views when the orders do; reversing
    // the list turns the grid by 180 degrees.
    const cv::Point2f left_span = left_corners->back() - left_corners->front();
    const cv::Point2f right_span = right_corners->back() - right_corners->front();
    if (left_span.dot(right_span) < 0) std::reverse(right_corners->begin(), right_corners->end());
  }
  Pair pair;
  pair.report.left_name = left_name;
  pair.report.right_name = right_name;
  pair.report.status = left_corners && right_corners ? StereoPairStatus::kUsed
                       : left_corners                ? StereoPairStatus::kLeftOnly
                       : right_corners               ? StereoPairStatus::kRightOnly
                                                     : StereoPairStatus::kNeither;
  pair.left = std::move(left_corners);
  pair.right = std::move(right_corners);
  pairs_.push_back(std::move(pair));
  return pairs_.back().report.status;
}

StereoCalibrationResult StereoCalibrator::calibrate() const {
  const std::string board_text = SizeText(options_.camera.board.inner_corners);
  std::vector<std::vector<cv::Point2f>> left_views, right_views;
  std::vector<size_t> both;  // Pairs with the board in both views.
  for (size_t i = 0; i < pairs_.size(); ++i) {
    if (pairs_[i].left) left_views.push_back(*pairs_[i].left);
    if (pairs_[i].right) right_views.push_back(*pairs_[i].right);
    if (pairs_[i].left && pairs_[i].right) both.push_back(i);
  }
  const int min_views = options_.camera.min_views;
  if (static_cast<int>(both.size()) < min_views) {
    throw InputError("the " + board_text + " chessboard was found in both views of " +
                     std::to_string(both.size()) + " of " + std::to_string(pairs_.size()) +
                     " pairs, need at least " + std::to_string(min_views) +
                     " (--chessboard counts INNER corners; the whole board must be in both views)");
  }

  StereoCalibrationResult result;
  StereoCalibration& stereo = result.stereo;
  result.left_rms_px = CalibrateFromCorners(options_.camera, image_size_, left_views, stereo.left);
  result.right_rms_px =
      CalibrateFromCorners(options_.camera, image_size_, right_views, stereo.right);
  for (const Pair& pair : pairs_) result.pairs.push_back(pair.report);

  // stereoCalibrate with each camera's intrinsics fixed (each from all of its own views: more
  // views than pairs, and a joint fit of 2 x 9 intrinsics from a dozen pairs mostly trades
  // focal length against distance), then leave out the pairs that do not fit and fit again.
  const std::vector<cv::Point3f> board_points = ChessboardObjectPoints(options_.camera.board);
  std::vector<size_t> used = both;
  for (int round = 0; round < 4; ++round) {
    std::vector<std::vector<cv::Point2f>> left_points, right_points;
    for (const size_t i : used) {
      left_points.push_back(*pairs_[i].left);
      right_points.push_back(*pairs_[i].right);
    }
    const std::vector<std::vector<cv::Point3f>> object_points(used.size(), board_points);
    cv::Mat k1(stereo.left.camera_matrix), k2(stereo.right.camera_matrix);
    cv::Mat d1 = DistortionMat(stereo.left.distortion), d2 = DistortionMat(stereo.right.distortion);
    cv::Mat r, t, e, f, per_view;
    stereo.rms_px = cv::stereoCalibrate(object_points, left_points, right_points, k1, d1, k2, d2,
                                        image_size_, r, t, e, f, per_view, cv::CALIB_FIX_INTRINSIC);
    stereo.R = cv::Matx33d(r);
    stereo.T = cv::Vec3d(t.reshape(1, 3));
    std::vector<double> errors;
    for (size_t k = 0; k < used.size(); ++k) {
      StereoPairReport& report = result.pairs[used[k]];
      report.left_rms_px = per_view.at<double>(static_cast<int>(k), 0);
      report.right_rms_px = per_view.at<double>(static_cast<int>(k), 1);
      errors.push_back(PairError(report));
    }
    const double limit =
        std::max(options_.outlier_factor * Median(errors), options_.outlier_floor_px);
    std::vector<size_t> kept;
    for (const size_t i : used) {
      if (PairError(result.pairs[i]) > limit) {
        result.pairs[i].status = StereoPairStatus::kOutlier;
      } else {
        kept.push_back(i);
      }
    }
    if (kept.size() == used.size()) break;
    if (static_cast<int>(kept.size()) < min_views) {
      throw InputError("only " + std::to_string(kept.size()) + " of " +
                       std::to_string(both.size()) +
                       " pairs with the board in both views fit together (reprojection error "
                       "below " +
                       std::to_string(limit) + " px), need at least " + std::to_string(min_views) +
                       ": were the pairs taken at the same moment, and do left and right match?");
    }
    used = std::move(kept);
  }
  CompleteStereoCalibration(stereo);
  return result;
}

void SaveStereoCalibration(const StereoCalibrationResult& result, const ChessboardSpec& board,
                           const std::string& file) {
  const StereoCalibration& s = result.stereo;
  cv::FileStorage fs = OpenForWriting(file);
  calib_internal::WriteCalibrationHeader(fs, s.left.image_size, board);
  fs << "camera_matrix_left" << cv::Mat(s.left.camera_matrix);
  fs << "distortion_left" << DistortionMat(s.left.distortion);
  fs << "camera_matrix_right" << cv::Mat(s.right.camera_matrix);
  fs << "distortion_right" << DistortionMat(s.right.distortion);
  fs << "left_rms_px" << result.left_rms_px;
  fs << "right_rms_px" << result.right_rms_px;
  fs << "R" << cv::Mat(s.R);
  fs << "T" << cv::Mat(s.T);
  fs << "E" << cv::Mat(s.E);
  fs << "F" << cv::Mat(s.F);
  fs << "R1" << cv::Mat(s.R1);
  fs << "R2" << cv::Mat(s.R2);
  fs << "P1" << cv::Mat(s.P1);
  fs << "P2" << cv::Mat(s.P2);
  fs << "Q" << cv::Mat(s.Q);
  fs << "rms_px" << s.rms_px;
  fs << "baseline_mm" << s.baseline_mm();
  fs << "pairs_used" << result.pairs_used();
  fs << "pairs"
     << "[";
  for (const StereoPairReport& pair : result.pairs) {
    fs << "{"
       << "left" << pair.left_name << "right" << pair.right_name << "status"
       << StereoPairStatusName(pair.status);
    if (pair.left_rms_px) fs << "left_rms_px" << *pair.left_rms_px;
    if (pair.right_rms_px) fs << "right_rms_px" << *pair.right_rms_px;
    fs << "}";
  }
  fs << "]";
  FinishWriting(fs, file);
}

StereoCalibration LoadStereoCalibration(const std::string& file) {
  cv::FileStorage fs = OpenForReading(file);
  StereoCalibration s;
  const cv::Size size(ReadPositiveInt(fs, file, "image_width"),
                      ReadPositiveInt(fs, file, "image_height"));
  s.left.image_size = s.right.image_size = size;
  s.left.camera_matrix = cv::Matx33d(ReadMatrix(fs, file, "camera_matrix_left", 3, 3));
  s.right.camera_matrix = cv::Matx33d(ReadMatrix(fs, file, "camera_matrix_right", 3, 3));
  for (const char* key : {"distortion_left", "distortion_right"}) {
    const cv::Mat d = ReadMatrix(fs, file, key, 0, 0).reshape(1, 1);
    if (d.cols != 4 && d.cols != 5 && d.cols != 8 && d.cols != 12 && d.cols != 14) {
      throw InputError(file + ": " + key + ": expected 4, 5, 8, 12 or 14 values, got " +
                       std::to_string(d.cols));
    }
    d.copyTo(std::string(key) == "distortion_left" ? s.left.distortion : s.right.distortion);
  }
  s.R = cv::Matx33d(ReadMatrix(fs, file, "R", 3, 3));
  s.T = cv::Vec3d(ReadMatrix(fs, file, "T", 3, 1));
  if (!fs["rms_px"].empty()) s.rms_px = static_cast<double>(fs["rms_px"]);
  std::string error;
  if (!s.Check(&error)) throw InputError(file + ": " + error);
  // E, F and the rectification follow from the rest: recomputed, so a hand-edited R or T
  // cannot leave them disagreeing.
  CompleteStereoCalibration(s);
  return s;
}

std::optional<ChessboardSpec> LoadStereoCalibrationBoard(const std::string& file) {
  cv::FileStorage fs = OpenForReading(file);
  if (fs["board_width"].empty() || fs["board_height"].empty() || fs["square_size_mm"].empty()) {
    return std::nullopt;
  }
  ChessboardSpec board;
  board.inner_corners = cv::Size(ReadPositiveInt(fs, file, "board_width"),
                                 ReadPositiveInt(fs, file, "board_height"));
  board.square_mm = static_cast<double>(fs["square_size_mm"]);
  std::string error;
  if (!board.Check(&error)) throw InputError(file + ": the board: " + error);
  return board;
}

cv::Mat DrawRectifiedPair(const StereoCalibration& stereo, const cv::Mat& left_image,
                          const cv::Mat& right_image, int spacing_px) {
  CV_Assert(spacing_px > 0);
  const cv::Size size = stereo.left.image_size;
  if (left_image.size() != size || right_image.size() != size) {
    throw InputError("rectified pair: the images are " + SizeText(left_image.size()) + " and " +
                     SizeText(right_image.size()) + " but the calibration is for " +
                     SizeText(size));
  }
  cv::Mat canvas(size.height, 2 * size.width, CV_8UC3);
  const struct {
    const CameraIntrinsics& camera;
    const cv::Matx33d& rotation;
    const cv::Matx34d& projection;
    const cv::Mat& image;
    int x;
  } halves[] = {{stereo.left, stereo.R1, stereo.P1, left_image, 0},
                {stereo.right, stereo.R2, stereo.P2, right_image, size.width}};
  for (const auto& half : halves) {
    cv::Mat map1, map2, rectified, bgr;
    cv::initUndistortRectifyMap(half.camera.camera_matrix, DistortionMat(half.camera.distortion),
                                half.rotation, cv::Mat(half.projection).colRange(0, 3), size,
                                CV_16SC2, map1, map2);
    cv::remap(half.image, rectified, map1, map2, cv::INTER_LINEAR);
    if (rectified.channels() == 1) {
      cv::cvtColor(rectified, bgr, cv::COLOR_GRAY2BGR);
    } else {
      bgr = rectified;
    }
    bgr.copyTo(canvas(cv::Rect(half.x, 0, size.width, size.height)));
  }
  for (int y = spacing_px / 2; y < size.height; y += spacing_px) {
    const cv::Scalar colour((y * 67) % 256, (y * 151 + 90) % 256, (y * 29 + 180) % 256);
    cv::line(canvas, {0, y}, {canvas.cols - 1, y}, colour, 1, cv::LINE_AA);
  }
  return canvas;
}

}  // namespace softsight
