#include "softsight/calib/board_frame.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/calibration_internals.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"

namespace softsight {

cv::Point3d BoardFrame::to_board(const cv::Point3d& camera_mm) const {
  const cv::Vec3d p =
      rotation.t() * (cv::Vec3d(camera_mm.x, camera_mm.y, camera_mm.z) - origin_mm);
  return {p[0], p[1], p[2]};
}

cv::Vec3d BoardFrame::direction_to_board(const cv::Vec3d& camera) const {
  return rotation.t() * camera;
}

cv::Matx33d BoardFrame::covariance_to_board(const cv::Matx33d& camera) const {
  return rotation.t() * camera * rotation;
}

BoardFrame FitBoardFrame(const std::vector<std::optional<cv::Point3d>>& corners_mm,
                         const ChessboardSpec& board) {
  const int width = board.inner_corners.width, height = board.inner_corners.height;
  if (static_cast<int>(corners_mm.size()) != width * height) {
    throw InputError("board frame: " + std::to_string(corners_mm.size()) + " corners for " +
                     WithArticle(SizeText(board.inner_corners) + " board"));
  }
  std::vector<cv::Vec3d> ideal, measured;
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const std::optional<cv::Point3d>& p = corners_mm[r * width + c];
      if (!p) continue;
      ideal.emplace_back(c * board.square_mm, r * board.square_mm, 0.0);
      measured.emplace_back(p->x, p->y, p->z);
    }
  }
  const auto n = static_cast<double>(ideal.size());
  cv::Vec3d ideal_centre, measured_centre;
  for (size_t i = 0; i < ideal.size(); ++i) {
    ideal_centre += ideal[i] / n;
    measured_centre += measured[i] / n;
  }
  // Kabsch: the rotation maximising sum (measured_i - centre) . R (ideal_i - centre).
  cv::Matx33d h = cv::Matx33d::zeros();
  for (size_t i = 0; i < ideal.size(); ++i) {
    h += (ideal[i] - ideal_centre) * (measured[i] - measured_centre).t();
  }
  // The ideal grid's spread along its rows and columns: corners on one line leave one of them 0.
  cv::Matx22d spread = cv::Matx22d::zeros();
  for (const cv::Vec3d& q : ideal) {
    const cv::Vec2d d(q[0] - ideal_centre[0], q[1] - ideal_centre[1]);
    spread += d * d.t();
  }
  cv::Vec2d spread_eigen;
  cv::eigen(spread, spread_eigen);
  if (ideal.size() < 3 || spread_eigen[1] <= 1e-9 * board.square_mm * board.square_mm) {
    throw InputError("board frame: " + std::to_string(ideal.size()) +
                     " corners, not enough off one line to fit the board's pose");
  }
  cv::Mat w, u, vt;
  cv::SVD::compute(cv::Mat(h), w, u, vt);
  const cv::Matx33d U(u), V(cv::Mat(vt.t()));
  const double d = cv::determinant(V * U.t()) < 0 ? -1.0 : 1.0;
  BoardFrame frame;
  frame.rotation = V * cv::Matx33d::diag({1.0, 1.0, d}) * U.t();
  frame.origin_mm = measured_centre - frame.rotation * ideal_centre;
  double sum_sq = 0.0;
  for (size_t i = 0; i < ideal.size(); ++i) {
    const double e = cv::norm(frame.rotation * ideal[i] + frame.origin_mm - measured[i]);
    sum_sq += e * e;
    frame.max_mm = std::max(frame.max_mm, e);
  }
  frame.rms_mm = std::sqrt(sum_sq / n);
  frame.corners = static_cast<int>(ideal.size());
  return frame;
}

namespace {

cv::Mat Gray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

// Mean grey level of a small patch around `at`; absent outside the image.
std::optional<double> PatchLevel(const cv::Mat& gray, const cv::Point2d& at, int side) {
  const cv::Rect patch(static_cast<int>(std::lround(at.x)) - side / 2,
                       static_cast<int>(std::lround(at.y)) - side / 2, side, side);
  if ((patch & cv::Rect(0, 0, gray.cols, gray.rows)) != patch) return std::nullopt;
  return cv::mean(gray(patch))[0];
}

// True when the grid should start at its other end: the corner square beyond the last corner is
// dark and the one beyond the first is light, or (no clear difference) the last corner is nearer
// the image's top-left.
bool StartsAtTheOtherEnd(const cv::Mat& image, const std::vector<cv::Point2f>& corners,
                         const cv::Size& inner) {
  std::vector<cv::Point2f> grid;
  for (int r = 0; r < inner.height; ++r) {
    for (int c = 0; c < inner.width; ++c) {
      grid.emplace_back(static_cast<float>(c), static_cast<float>(r));
    }
  }
  const cv::Matx33d homography(cv::findHomography(grid, corners, 0));
  const auto image_of = [&](double c, double r) {
    const cv::Vec3d p = homography * cv::Vec3d(c, r, 1.0);
    return cv::Point2d(p[0] / p[2], p[1] / p[2]);
  };
  // The centres of the two corner squares, diagonally outside the first and the last corner.
  const cv::Point2d first_square = image_of(-0.5, -0.5);
  const cv::Point2d last_square = image_of(inner.width - 0.5, inner.height - 0.5);
  const double square_px = cv::norm(corners[1] - corners[0]);
  const int side = std::max(1, static_cast<int>(0.4 * square_px));
  const cv::Mat gray = Gray(image);
  const std::optional<double> first = PatchLevel(gray, first_square, side);
  const std::optional<double> last = PatchLevel(gray, last_square, side);
  if (first && last && std::abs(*first - *last) >= 30.0) return *last < *first;
  const cv::Point2f a = corners.front(), b = corners.back();
  return b.x + b.y < a.x + a.y;
}

std::string Fixed(double value, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << value;
  return s.str();
}

}  // namespace

BoardFrame LocateBenchBoard(const Triangulator& triangulator, const ChessboardSpec& board,
                            const std::string& left_name, const cv::Mat& left_image,
                            const std::string& right_name, const cv::Mat& right_image,
                            const BenchBoardOptions& options) {
  std::string error;
  if (!board.Check(&error)) throw InputError("bench board: " + error);
  const cv::Size calibrated = triangulator.stereo().left.image_size;
  const std::string board_text = SizeText(board.inner_corners);
  std::optional<std::vector<cv::Point2f>> found[2];
  const struct {
    const std::string& name;
    const cv::Mat& image;
  } views[] = {{left_name, left_image}, {right_name, right_image}};
  for (int v = 0; v < 2; ++v) {
    const cv::Mat& image = views[v].image;
    if (image.empty()) throw InputError(views[v].name + ": cannot read the image");
    if (image.size() != calibrated) {
      throw InputError(views[v].name + ": image is " + SizeText(image.size()) +
                       " but the cameras were calibrated at " + SizeText(calibrated));
    }
    if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
      throw InputError(views[v].name + ": expected an 8-bit grey or colour image");
    }
    found[v] = FindChessboard(image, board.inner_corners);
    if (!found[v]) {
      throw InputError(views[v].name + ": the " + board_text +
                       " chessboard (inner corners) was not found; the whole board must be in "
                       "both views");
    }
  }
  std::vector<cv::Point2f>& left = *found[0];
  std::vector<cv::Point2f>& right = *found[1];
  if (StartsAtTheOtherEnd(left_image, left, board.inner_corners)) {
    std::reverse(left.begin(), left.end());
  }
  // Both cameras see the board from nearly the same side: the first-to-last corner direction
  // agrees in both views when the orders do (as the stereo calibration matches them).
  if ((left.back() - left.front()).dot(right.back() - right.front()) < 0) {
    std::reverse(right.begin(), right.end());
  }
  std::vector<std::optional<cv::Point3d>> corners(left.size());
  int triangulated = 0;
  for (size_t i = 0; i < left.size(); ++i) {
    const StereoPoint p = triangulator.triangulate(cv::Point2d(left[i]), cv::Point2d(right[i]));
    if (p.found()) {
      corners[i] = *p.position_mm;
      ++triangulated;
    }
  }
  const std::string pair = left_name + " / " + right_name;
  if (triangulated < 3 ||
      triangulated < options.min_corner_fraction * static_cast<double>(left.size())) {
    throw InputError(pair + ": only " + std::to_string(triangulated) + " of " +
                     std::to_string(left.size()) +
                     " board corners pass the epipolar check: not one moment in both views, or "
                     "a --stereo file of another rig");
  }
  const BoardFrame frame = FitBoardFrame(corners, board);
  if (!(frame.rms_mm <= options.max_rms_mm)) {
    throw InputError(pair + ": the triangulated corners fit a flat " + board_text + " board of " +
                     Fixed(board.square_mm, 2) + " mm squares to " + Fixed(frame.rms_mm, 2) +
                     " mm RMS (limit " + Fixed(options.max_rms_mm, 2) +
                     "): a wrong --square-mm or --chessboard, a bent board, or a --stereo file of "
                     "another rig");
  }
  return frame;
}

}  // namespace softsight
