#include "softsight/sim/chessboard.h"

#include <cmath>
#include <string>

#include <opencv2/calib3d.hpp>

#include "softsight/core/error.h"

namespace softsight {
namespace {

cv::Mat DistortionMat(const std::vector<double>& distortion) {
  if (distortion.empty()) return cv::Mat();
  return cv::Mat(distortion, /*copyData=*/true).reshape(1, 1);
}

cv::Matx33d RotationX(double deg) {
  const double a = deg * CV_PI / 180.0, c = std::cos(a), s = std::sin(a);
  return {1, 0, 0, 0, c, -s, 0, s, c};
}
cv::Matx33d RotationY(double deg) {
  const double a = deg * CV_PI / 180.0, c = std::cos(a), s = std::sin(a);
  return {c, 0, s, 0, 1, 0, -s, 0, c};
}
cv::Matx33d RotationZ(double deg) {
  const double a = deg * CV_PI / 180.0, c = std::cos(a), s = std::sin(a);
  return {c, -s, 0, s, c, 0, 0, 0, 1};
}

}  // namespace

ChessboardRenderer::ChessboardRenderer(CameraModel camera, ChessboardPattern pattern,
                                       ChessboardLook look)
    : camera_(std::move(camera)), pattern_(pattern), look_(look) {
  if (camera_.image_size.width <= 0 || camera_.image_size.height <= 0) {
    throw InputError("chessboard renderer: image size must be positive");
  }
  if (look_.supersample < 1 || look_.supersample > 16) {
    throw InputError("chessboard renderer: supersample must be 1..16, got " +
                     std::to_string(look_.supersample));
  }
  if (pattern_.inner_corners.width < 2 || pattern_.inner_corners.height < 2 ||
      !(pattern_.square_mm > 0.0) || pattern_.margin_mm < 0.0) {
    throw InputError("chessboard renderer: the pattern needs >= 2x2 inner corners and squares > 0");
  }
  const size_t coefficients = camera_.distortion.size();
  if (coefficients != 0 && coefficients != 4 && coefficients != 5 && coefficients != 8) {
    throw InputError("chessboard renderer: distortion needs 0, 4, 5 or 8 coefficients, got " +
                     std::to_string(coefficients));
  }

  // Every sub-sample's position in the distorted image (pixel-centre convention: pixel (i, j)
  // covers [j - 0.5, j + 0.5] x [i - 0.5, i + 0.5]), undistorted once to a normalised ray.
  // The n = s * s sub-samples of a pixel form an "n-rooks" pattern (every sub-sample on its own
  // column and row of an n x n grid, one per cell of an s x s grid): a regular s x s grid would
  // quantise the coverage of an axis-aligned edge to 1/s of a pixel, which biases detected
  // chessboard corners by up to 1/(2s) px; n-rooks quantises it to 1/n.
  const int s = look_.supersample;
  const int n = s * s;
  const int rows = camera_.image_size.height;
  const int cols = camera_.image_size.width * n;
  cv::Mat positions(rows * cols, 1, CV_64FC2);
  for (int r = 0; r < rows; ++r) {
    cv::Vec2d* out = positions.ptr<cv::Vec2d>(r * cols);
    for (int c = 0; c < cols; ++c) {
      const int k = c % n, i = k / s, j = k % s;
      out[c] = cv::Vec2d(c / n - 0.5 + (i * s + j + 0.5) / n, r - 0.5 + (j * s + i + 0.5) / n);
    }
  }
  cv::Mat normalised;
  // Many iterations: the default 5 leave visible errors at the corners of a strongly distorted
  // image, and the truth must be exact.
  cv::undistortPoints(positions, normalised, camera_.camera_matrix,
                      DistortionMat(camera_.distortion), cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100,
                                       1e-12));
  normalised.reshape(2, rows).convertTo(rays_, CV_32FC2);
}

ChessboardView ChessboardRenderer::render(const BoardPose& pose, cv::Mat& image) const {
  cv::Matx33d camera_from_board;
  cv::Rodrigues(pose.rvec, camera_from_board);
  const cv::Matx33d board_from_camera = camera_from_board.t();
  // The camera centre in board coordinates, and each ray direction rotated into the board frame.
  const cv::Vec3d origin = -(board_from_camera * pose.tvec);

  const double s = pattern_.square_mm;
  const double x_max = pattern_.inner_corners.width * s;   // Squares span [-s, x_max].
  const double y_max = pattern_.inner_corners.height * s;
  const double m = pattern_.margin_mm;
  const int n = look_.supersample * look_.supersample;
  const cv::Size size = camera_.image_size;

  image.create(size, CV_8UC1);
  cv::Mat sums(size, CV_32FC1, cv::Scalar(0));
  for (int r = 0; r < rays_.rows; ++r) {
    const cv::Vec2f* ray = rays_.ptr<cv::Vec2f>(r);
    float* sum = sums.ptr<float>(r);
    for (int c = 0; c < rays_.cols; ++c) {
      const cv::Vec3d d = board_from_camera * cv::Vec3d(ray[c][0], ray[c][1], 1.0);
      uint8_t level = look_.background;
      const double lambda = d[2] != 0.0 ? -origin[2] / d[2] : -1.0;
      if (lambda > 0.0) {
        const double u = origin[0] + lambda * d[0];
        const double v = origin[1] + lambda * d[1];
        if (u >= -s - m && u <= x_max + m && v >= -s - m && v <= y_max + m) {
          level = look_.white;
          if (u >= -s && u <= x_max && v >= -s && v <= y_max) {
            const long a = static_cast<long>(std::floor(u / s));
            const long b = static_cast<long>(std::floor(v / s));
            if (((a + b) & 1) == 0) level = look_.black;
          }
        }
      }
      sum[c / n] += level;
    }
  }
  cv::Mat noisy = sums * (1.0 / n);
  if (look_.noise_sigma > 0.0) {
    cv::Mat noise(size, CV_32FC1);
    cv::RNG rng(look_.seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, look_.noise_sigma);
    noisy += noise;
  }
  noisy.convertTo(image, CV_8UC1);  // Rounds and saturates.

  ChessboardView view;
  view.all_corners_inside = true;
  for (int row = 0; row < pattern_.inner_corners.height; ++row) {
    for (int col = 0; col < pattern_.inner_corners.width; ++col) {
      const cv::Point2d p = project(pose, {col * s, row * s});
      view.corners_px.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
      if (p.x < 0 || p.y < 0 || p.x > size.width - 1 || p.y > size.height - 1) {
        view.all_corners_inside = false;
      }
    }
  }
  return view;
}

cv::Point2d ChessboardRenderer::project(const BoardPose& pose, const cv::Point2d& board_mm) const {
  const std::vector<cv::Point3d> object = {{board_mm.x, board_mm.y, 0.0}};
  std::vector<cv::Point2d> image;
  cv::projectPoints(object, pose.rvec, pose.tvec, camera_.camera_matrix,
                    DistortionMat(camera_.distortion), image);
  return image.front();
}

BoardPose LookAtBoard(const ChessboardPattern& pattern, double distance_mm, double tilt_x_deg,
                      double tilt_y_deg, double roll_deg, double shift_x_mm, double shift_y_mm) {
  const cv::Vec3d centre((pattern.inner_corners.width - 1) * pattern.square_mm / 2.0,
                         (pattern.inner_corners.height - 1) * pattern.square_mm / 2.0, 0.0);
  const cv::Matx33d camera_from_board =
      RotationZ(roll_deg) * RotationX(tilt_x_deg) * RotationY(tilt_y_deg);
  BoardPose pose;
  cv::Rodrigues(camera_from_board, pose.rvec);
  pose.tvec = cv::Vec3d(shift_x_mm, shift_y_mm, distance_mm) - camera_from_board * centre;
  return pose;
}

}  // namespace softsight
