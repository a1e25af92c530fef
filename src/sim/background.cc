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
    const double cy = rng.uniform(0.05, 0.95) * h;  // Before x: see DrawBgr.
    const cv::Point2d c(rng.uniform(0.05, 0.95) * w, cy);
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

namespace softsight::sim {
namespace {

float Smoothstep(float edge0, float edge1, float x) {
  const float t = std::clamp((x - edge0) / (edge1 - edge0), 0.f, 1.f);
  return t * t * (3 - 2 * t);
}

// A patch's colour class, so that every seed has some of each.
enum class PatchTint { kDark, kReddish, kGreenish, kBluish };

// A colour drawn channel by channel from [lo, hi) ranges, red first, then green, then blue.
// Every random draw of the renderer is its own statement (or an element of a braced list, which
// C++ evaluates in order): the order of a call's arguments is left open by C++, GCC evaluated
// them last to first and clang first to last, so the pictures depended on the compiler. The
// order kept is GCC's, which drew the pictures the README's figures were measured on
// (SceneGoldenTest pins them).
cv::Vec3f DrawBgr(cv::RNG& rng, cv::Vec2f b, cv::Vec2f g, cv::Vec2f r) {
  const float red = rng.uniform(r[0], r[1]);
  const float green = rng.uniform(g[0], g[1]);
  const float blue = rng.uniform(b[0], b[1]);
  return {blue, green, red};
}

cv::Vec3f PatchColour(PatchTint tint, const cv::Vec3f& wood, cv::RNG& rng) {
  const float v = static_cast<float>(rng.uniform(0.6, 1.1));
  switch (tint) {
    case PatchTint::kDark: return wood * static_cast<float>(rng.uniform(0.3, 0.55));
    // Hues near the marker colours, saturation from dull to marker-like.
    case PatchTint::kReddish:
      return DrawBgr(rng, {35.f, 80.f}, {35.f, 75.f}, {120.f, 175.f}) * v;
    case PatchTint::kGreenish:
      return DrawBgr(rng, {55.f, 95.f}, {110.f, 160.f}, {50.f, 100.f}) * v;
    case PatchTint::kBluish:
      return DrawBgr(rng, {120.f, 175.f}, {80.f, 120.f}, {40.f, 85.f}) * v;
  }
  return wood;
}

// A point of the image to the supersampled image (pixel centres kept).
cv::Point SupersampledPixel(int s, const cv::Point2d& p) {
  return cv::Point(cvRound((p.x + 0.5) * s - 0.5), cvRound((p.y + 0.5) * s - 0.5));
}

// Wood: a base colour (`wood`) between light oak and walnut, grain stripes along a
// near-horizontal direction warped by a smooth field, streaks stretched along the grain.
cv::Mat3f WoodGrain(cv::Size size, double scale, cv::RNG& rng, cv::Vec3f* wood_out) {
  const double mix = rng.uniform(0.0, 1.0);
  const cv::Vec3f oak(112, 160, 200), walnut(62, 96, 138);
  const cv::Vec3f wood = oak * static_cast<float>(1 - mix) + walnut * static_cast<float>(mix);
  *wood_out = wood;
  const double grain_angle = rng.uniform(-0.25, 0.25);
  const double period = rng.uniform(7.0, 13.0) * scale + 2.0;
  const cv::Mat1f warp = SmoothField(size, 4, 1.0, rng);
  const cv::Mat1f rings = SmoothField(size, 9, 1.0, rng);
  cv::Mat1f streaks;
  {
    const int cols = std::max(2, size.width / 60), rows = std::max(2, size.height / 2);
    cv::Mat1f coarse(rows, cols);
    rng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
    cv::resize(coarse, streaks, size, 0, 0, cv::INTER_CUBIC);
  }
  const cv::Mat1f blotch = SmoothField(size, 6, 1.0, rng);
  cv::Mat3f bench(size);
  const float ca = static_cast<float>(std::cos(grain_angle)), sa = static_cast<float>(std::sin(grain_angle));
  for (int y = 0; y < size.height; ++y) {
    cv::Vec3f* out = bench.ptr<cv::Vec3f>(y);
    for (int x = 0; x < size.width; ++x) {
      const float across = -sa * x + ca * y + 30.f * static_cast<float>(scale) * warp(y, x) +
                           8.f * rings(y, x);
      const float g = 0.5f + 0.5f * std::sin(static_cast<float>(2 * CV_PI / period) * across);
      const float m = 1.f - 0.16f * g * g - 0.05f * streaks(y, x) + 0.08f * blotch(y, x);
      out[x] = wood * m;
    }
  }
  return bench;
}

// Patches: ragged blotches (an ellipse eaten by a smooth field), in every colour class.
void AddPatches(const cv::Vec3f& wood, double scale, uint64_t seed, cv::RNG& rng,
                cv::Mat3f& bench) {
  const cv::Size size = bench.size();
  const double w = size.width, h = size.height;
  const cv::Mat1f ragged = SmoothField(size, 16, 1.0, rng);
  const int patches = std::max(8, static_cast<int>(std::lround(14 * w * h / (640.0 * 480.0))));
  for (int i = 0; i < patches; ++i) {
    const PatchTint tint = static_cast<PatchTint>((i + static_cast<int>(seed)) % 4);
    const cv::Vec3f colour = PatchColour(tint, wood, rng);
    const double cy = rng.uniform(-0.05, 1.05) * h;  // Before x: see DrawBgr.
    const cv::Point2d c(rng.uniform(-0.05, 1.05) * w, cy);
    const double ra = rng.uniform(18.0, 75.0) * scale, rb = ra * rng.uniform(0.4, 1.0);
    const double t = rng.uniform(0.0, CV_PI);
    const double opacity = rng.uniform(0.45, 0.9);
    const double ct = std::cos(t), st = std::sin(t);
    const double reach = 1.6 * ra;
    const int x0 = std::max(0, static_cast<int>(c.x - reach)), x1 = std::min(size.width - 1, static_cast<int>(c.x + reach));
    const int y0 = std::max(0, static_cast<int>(c.y - reach)), y1 = std::min(size.height - 1, static_cast<int>(c.y + reach));
    for (int y = y0; y <= y1; ++y) {
      cv::Vec3f* out = bench.ptr<cv::Vec3f>(y);
      for (int x = x0; x <= x1; ++x) {
        const double dx = x - c.x, dy = y - c.y;
        const double u = (ct * dx + st * dy) / ra, v = (-st * dx + ct * dy) / rb;
        const float rho = static_cast<float>(std::sqrt(u * u + v * v));
        const float alpha =
            static_cast<float>(opacity) * Smoothstep(0.f, 0.35f, 1.f - rho + 0.45f * ragged(y, x));
        if (alpha > 0) out[x] = out[x] * (1 - alpha) + colour * alpha;
      }
    }
  }
}

// The sensor's grain over the bench, to 8 bits.
cv::Mat3b WithGrain(const cv::Mat3f& bench, cv::RNG& rng) {
  const cv::Size size = bench.size();
  cv::Mat1f grain(size);
  rng.fill(grain, cv::RNG::NORMAL, 0.0, 4.0);
  cv::Mat3b low(size);
  for (int y = 0; y < size.height; ++y) {
    const cv::Vec3f* in = bench.ptr<cv::Vec3f>(y);
    cv::Vec3b* out = low.ptr<cv::Vec3b>(y);
    for (int x = 0; x < size.width; ++x) {
      for (int k = 0; k < 3; ++k) out[x][k] = cv::saturate_cast<uchar>(in[x][k] + grain(y, x));
    }
  }
  return low;
}

// Tape strips: long rotated rectangles, slightly translucent, with a darker edge line.
void AddTapes(cv::Size size, double scale, int s, cv::RNG& rng, cv::Mat& ss) {
  const double w = size.width, h = size.height;
  const cv::Scalar tapes[] = {{150, 196, 214},   // masking tape
                              {158, 160, 162},   // grey duct tape
                              {228, 230, 232},   // white tape
                              {200, 150, 70}};   // blue painter's tape
  for (int i = 0; i < 2; ++i) {
    const double cy = rng.uniform(0.1, 0.9) * h;  // Before x: see DrawBgr.
    const cv::Point2d c(rng.uniform(0.1, 0.9) * w, cy);
    const double length = rng.uniform(0.3, 0.6) * std::max(w, h);
    const double width = rng.uniform(14.0, 26.0) * scale + 2;
    const double a = rng.uniform(0.0, CV_PI);
    const cv::Point2d d(std::cos(a), std::sin(a)), n(-std::sin(a), std::cos(a));
    const cv::Point corners[4] = {SupersampledPixel(s, c - d * (length / 2) - n * (width / 2)),
                                  SupersampledPixel(s, c + d * (length / 2) - n * (width / 2)),
                                  SupersampledPixel(s, c + d * (length / 2) + n * (width / 2)),
                                  SupersampledPixel(s, c - d * (length / 2) + n * (width / 2))};
    const cv::Scalar colour = tapes[rng.uniform(0, 4)];
    cv::Mat layer = ss.clone();
    cv::fillConvexPoly(layer, corners, 4, colour, cv::LINE_8);
    cv::polylines(layer, std::vector<cv::Point>(corners, corners + 4), true, colour * 0.8,
                  std::max(1, s / 2), cv::LINE_8);
    cv::addWeighted(layer, 0.88, ss, 0.12, 0.0, ss);
  }
}

// A cable: a long thin curve across the bench, dark with a highlight.
void AddCable(cv::Size size, double scale, int s, cv::RNG& rng, cv::Mat& ss) {
  const double w = size.width, h = size.height;
  const cv::Point2d ctrl[4] = {{rng.uniform(-0.1, 0.3) * w, -10},
                               {rng.uniform(-0.2, 1.2) * w, rng.uniform(0.2, 0.5) * h},
                               {rng.uniform(-0.2, 1.2) * w, rng.uniform(0.5, 0.8) * h},
                               {rng.uniform(0.7, 1.1) * w, h + 10}};
  std::vector<cv::Point> cable;
  for (int i = 0; i <= 96; ++i) cable.push_back(SupersampledPixel(s, Bezier(ctrl, i / 96.0)));
  const double cable_px = rng.uniform(3.5, 6.0) * scale + 1;
  const int grey = rng.uniform(22, 48);
  cv::polylines(ss, cable, false, cv::Scalar(grey, grey, grey + 4), cvRound(cable_px * s),
                cv::LINE_8);
  std::vector<cv::Point> shine(cable);
  for (cv::Point& p : shine) p.x -= cvRound(0.2 * cable_px * s);
  cv::polylines(ss, shine, false, cv::Scalar(grey + 45, grey + 45, grey + 48),
                std::max(1, cvRound(0.2 * cable_px * s)), cv::LINE_8);
}

}  // namespace

void RenderBenchBackground(cv::Size size, int supersample, uint64_t seed, cv::Mat* background_ss,
                           cv::Mat* background) {
  cv::RNG rng(seed * 0xD1B54A32D192ED03ull + 0x8CB92BA72F3D8DD7ull);
  const int s = supersample;
  const double scale = std::min(size.width, size.height) / 480.0;
  // One generator through every step, in this order: a seed gives the same bench.
  cv::Vec3f wood;
  cv::Mat3f bench = WoodGrain(size, scale, rng, &wood);
  AddPatches(wood, scale, seed, rng, bench);
  const cv::Mat3b low = WithGrain(bench, rng);
  cv::resize(low, *background_ss, cv::Size(size.width * s, size.height * s), 0, 0,
             cv::INTER_LINEAR);
  cv::Mat& ss = *background_ss;
  AddTapes(size, scale, s, rng, ss);
  AddCable(size, scale, s, rng, ss);
  cv::resize(ss, *background, size, 0, 0, cv::INTER_AREA);
}

}  // namespace softsight::sim
