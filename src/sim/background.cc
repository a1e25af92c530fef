#include "sim/background.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace softsight::sim {
namespace {

// Brightness stays in this range and the per-channel tint within +-kTint, which keeps the HSV
// saturation below about 50 (markers have 150 and more).
constexpr float kMinLevel = 85.f, kMaxLevel = 225.f;
constexpr float kTint = 8.f;

// Smooth random field: Gaussian values on a coarse grid, interpolated up to `size`.
cv::Mat1f SmoothField(cv::Size size, int cells_across, double sigma, cv::RNG& rng) {
  const int cols = std::max(2, cells_across);
  const int rows = std::max(2, cells_across * size.height / std::max(1, size.width));
  cv::Mat1f coarse(rows, cols);
  rng.fill(coarse, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat1f field;
  cv::resize(coarse, field, size, 0, 0, cv::INTER_CUBIC);
  return field;
}

cv::Point2d Bezier(const cv::Point2d p[4], double t) {
  const double a = 1 - t;
  return a * a * a * p[0] + 3 * a * a * t * p[1] + 3 * a * t * t * p[2] + t * t * t * p[3];
}

}  // namespace

void RenderBackground(cv::Size size, int supersample, uint64_t seed, cv::Mat* background_ss,
                      cv::Mat* background) {
  cv::RNG rng(seed * 0x9E3779B97F4A7C15ull + 0x5851F42D4C957F2Dull);
  const int s = supersample;

  // Brightness: a lighting gradient across the bench, soft blobs at two scales, fine grain.
  const double angle = rng.uniform(0.0, 2 * CV_PI);
  const double level = rng.uniform(140.0, 175.0);
  const double slope = rng.uniform(20.0, 45.0) / std::max(size.width, size.height);
  cv::Mat1f brightness(size);
  const double cx = (size.width - 1) / 2.0, cy = (size.height - 1) / 2.0;
  for (int y = 0; y < size.height; ++y) {
    float* row = brightness.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      row[x] = static_cast<float>(level + slope * ((x - cx) * std::cos(angle) +
                                                   (y - cy) * std::sin(angle)));
    }
  }
  brightness += SmoothField(size, 5, 14.0, rng);
  brightness += SmoothField(size, 24, 7.0, rng);
  cv::Mat1f grain(size);
  rng.fill(grain, cv::RNG::NORMAL, 0.0, 6.0);
  cv::GaussianBlur(grain, grain, cv::Size(0, 0), 0.7);
  brightness += grain;

  // A faint colour cast that drifts across the bench (a warm lamp on one side).
  std::vector<cv::Mat1f> tint(3);
  for (cv::Mat1f& t : tint) {
    t = SmoothField(size, 3, kTint / 2, rng);
    t = cv::max(cv::min(t, kTint), -kTint);
  }
  cv::Mat3b low(size);
  for (int y = 0; y < size.height; ++y) {
    const float* b = brightness.ptr<float>(y);
    cv::Vec3b* out = low.ptr<cv::Vec3b>(y);
    for (int x = 0; x < size.width; ++x) {
      const float v = std::clamp(b[x], kMinLevel, kMaxLevel);
      for (int c = 0; c < 3; ++c) out[x][c] = cv::saturate_cast<uchar>(v + tint[c](y, x));
    }
  }
  cv::resize(low, *background_ss, cv::Size(size.width * s, size.height * s), 0, 0,
             cv::INTER_LINEAR);
  cv::Mat& ss = *background_ss;

  // Drawn at the supersampled resolution, so they come out anti-aliased.
  auto to_ss = [s](const cv::Point2d& p) {
    return cv::Point(cvRound((p.x + 0.5) * s - 0.5), cvRound((p.y + 0.5) * s - 0.5));
  };
  const double w = size.width, h = size.height;
  // A cable sagging across the lower part of the image.
  const cv::Point2d ctrl[4] = {{-10, rng.uniform(0.55, 0.95) * h},
                               {rng.uniform(0.2, 0.4) * w, rng.uniform(0.7, 1.1) * h},
                               {rng.uniform(0.6, 0.8) * w, rng.uniform(0.4, 0.8) * h},
                               {w + 10, rng.uniform(0.5, 0.9) * h}};
  std::vector<cv::Point> cable;
  for (int i = 0; i <= 64; ++i) cable.push_back(to_ss(Bezier(ctrl, i / 64.0)));
  const double cable_px = std::max(3.0, 0.012 * std::min(w, h) * 1.5);
  cv::polylines(ss, cable, false, cv::Scalar(38, 40, 42), cvRound(cable_px * s), cv::LINE_8);
  std::vector<cv::Point> shine(cable);
  for (cv::Point& p : shine) p.y -= cvRound(0.2 * cable_px * s);
  cv::polylines(ss, shine, false, cv::Scalar(78, 80, 82), std::max(1, cvRound(0.2 * cable_px * s)),
                cv::LINE_8);

  // Screws: grey heads with a dark rim and a slot.
  const int screws = 3 + rng.uniform(0, 3);
  const double screw_scale = std::min(w, h) / 480.0;
  for (int i = 0; i < screws; ++i) {
    const cv::Point2d c(rng.uniform(0.05, 0.95) * w, rng.uniform(0.05, 0.95) * h);
    const double r = rng.uniform(5.0, 9.0) * screw_scale + 1.0;
    const int grey = rng.uniform(120, 175);
    cv::circle(ss, to_ss(c), cvRound(r * s), cv::Scalar(60, 60, 62), cv::FILLED, cv::LINE_8);
    cv::circle(ss, to_ss(c), cvRound((r - 1.2) * s), cv::Scalar(grey, grey, grey + 3), cv::FILLED,
               cv::LINE_8);
    const double a = rng.uniform(0.0, CV_PI);
    const cv::Point2d d(std::cos(a) * 0.75 * r, std::sin(a) * 0.75 * r);
    cv::line(ss, to_ss(c - d), to_ss(c + d), cv::Scalar(55, 55, 57),
             std::max(1, cvRound(0.3 * r * s)), cv::LINE_8);
  }
  cv::resize(ss, *background, size, 0, 0, cv::INTER_AREA);
}

}  // namespace softsight::sim
