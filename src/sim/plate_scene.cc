#include "softsight/core/format.h"
#include "softsight/sim/plate_scene.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "sim/background.h"
#include "sim/camera.h"
#include "sim/distractors.h"
#include "sim/raster.h"
#include "sim/scene_checks.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr int kMaxDots = 16;
constexpr double kMaxTiltDeg = 75.0;
constexpr double kMaxScale = 10.0;
// Dot spacing along the zig-zag and the plate's margin around the dots, in dot radii.
constexpr double kSpacingRadii = 5.0;
constexpr double kMarginRadii = 2.5;
// Margin kept between the plate and the image border where the path has room for it.
constexpr double kBorderFraction = 0.03;


cv::Point2d Apply(const cv::Matx33d& h, const cv::Point2d& p) {
  const cv::Vec3d q = h * cv::Vec3d(p.x, p.y, 1.0);
  return cv::Point2d(q[0] / q[2], q[1] / q[2]);
}

// Rotation by `angle` (radians) about the unit `axis` (Rodrigues' formula).
cv::Matx33d AxisRotation(const cv::Vec3d& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const cv::Matx33d cross(0, -axis[2], axis[1], axis[2], 0, -axis[0], -axis[1], axis[0], 0);
  return c * cv::Matx33d::eye() + s * cross + (1 - c) * (axis * axis.t());
}

}  // namespace

bool PlateSceneOptions::Check(std::string* error) const {
  if (!sim::CheckVideoShape(size, frame_count, fps, error)) return false;
  if (dot_count < 1 || dot_count > kMaxDots) {
    return Fail(error, "dot_count: must be in [1, " + std::to_string(kMaxDots) + "], got " +
                           std::to_string(dot_count));
  }
  if (!(std::isfinite(dot_radius_px) && dot_radius_px > 0 && dot_radius_px <= 200)) {
    return Fail(error, "dot_radius_px: must be in (0, 200], got " + ShortNumber(dot_radius_px));
  }
  if (!(std::isfinite(max_tilt_deg) && max_tilt_deg >= 0 && max_tilt_deg <= kMaxTiltDeg)) {
    return Fail(error, "max_tilt_deg: must be in [0, " + ShortNumber(kMaxTiltDeg) + "], got " +
                           ShortNumber(max_tilt_deg));
  }
  if (!(std::isfinite(scale_start) && scale_start > 0 && scale_start <= kMaxScale)) {
    return Fail(error, "scale_start: must be in (0, " + ShortNumber(kMaxScale) + "], got " + ShortNumber(scale_start));
  }
  if (!(std::isfinite(scale_end) && scale_end > 0 && scale_end <= kMaxScale)) {
    return Fail(error, "scale_end: must be in (0, " + ShortNumber(kMaxScale) + "], got " + ShortNumber(scale_end));
  }
  if (const std::string bad = sim::CheckDistractors(distractors); !bad.empty()) {
    return Fail(error, bad);
  }
  return true;
}

struct PlateScene::Impl {
  PlateSceneOptions options;
  NoiseOptions noise;
  RenderOptions render;
  double focal_px = 0;
  cv::Point2d principal;
  std::vector<cv::Point2d> dots;         // Plate coordinates.
  std::vector<cv::Point2d> corners;      // The plate's outline, plate coordinates.
  double roll0_deg = 0, axis0_deg = 0, phase_x = 0, phase_y = 0;

  cv::Mat background_ss, background, canvas_ss, mask_ss, gray, noise_buffer;
  std::vector<cv::Point2d> outline;
  std::vector<cv::Point> polygon_scratch;
  std::vector<sim::Conic> conics;

  // The plate's pose with its centre's image offset from the principal point.
  cv::Matx33d pose(double t, const cv::Point2d& offset) const {
    const PlateSceneOptions& o = options;
    const double scale = o.scale_start + (o.scale_end - o.scale_start) * t;
    const double depth = focal_px / scale;
    // Tilt rises to the maximum at a third, falls back, and rises again at the end, so the
    // largest tilt meets both the smallest and the largest scale; the axis and the in-plane
    // roll turn meanwhile.
    const double tilt = o.max_tilt_deg * (1 - std::cos(3 * CV_PI * t)) / 2 * CV_PI / 180;
    const double axis = (axis0_deg + 120 * t) * CV_PI / 180;
    const double roll = (roll0_deg + 40 * t) * CV_PI / 180;
    cv::Matx33d rz(std::cos(roll), -std::sin(roll), 0, std::sin(roll), std::cos(roll), 0, 0, 0, 1);
    const cv::Matx33d tilt_r = AxisRotation(cv::Vec3d(std::cos(axis), std::sin(axis), 0), tilt);
    // The tilt is against the line of sight to the plate's centre, not the optical axis, so the
    // dots' foreshortening is what max_tilt_deg says wherever the plate is in the image: first
    // turn the plate to face the camera along that line, then tilt it.
    const cv::Vec3d translation(offset.x * depth / focal_px, offset.y * depth / focal_px, depth);
    const cv::Vec3d sight = cv::normalize(translation);
    const cv::Vec3d z(0, 0, 1);
    const cv::Vec3d turn_axis = z.cross(sight);
    const double turn_sin = cv::norm(turn_axis);
    const cv::Matx33d face = turn_sin > 1e-12
                                 ? AxisRotation(turn_axis / turn_sin, std::atan2(turn_sin, sight.dot(z)))
                                 : cv::Matx33d::eye();
    const cv::Matx33d r = face * tilt_r * rz;
    const cv::Matx33d k(focal_px, 0, principal.x, 0, focal_px, principal.y, 0, 0, 1);
    const cv::Matx33d rt(r(0, 0), r(0, 1), translation[0], r(1, 0), r(1, 1), translation[1],
                         r(2, 0), r(2, 1), translation[2]);
    return k * rt;
  }

  cv::Matx33d image_from_plate(int index) const {
    const double t =
        options.frame_count > 1 ? std::clamp(index / double(options.frame_count - 1), 0.0, 1.0) : 0.0;
    // Where the plate's extent at this pose allows, its centre wanders over the free room.
    const cv::Matx33d centred = pose(t, cv::Point2d(0, 0));
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    for (const cv::Point2d& c : corners) {
      const cv::Point2d p = Apply(centred, c) - principal;
      x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
    }
    const double w = options.size.width, h = options.size.height;
    const double margin = kBorderFraction * std::min(w, h);
    auto wander = [](double lo, double hi, double phase) {
      if (lo >= hi) return (lo + hi) / 2;
      return (lo + hi) / 2 + (hi - lo) / 2 * 0.85 * std::sin(phase);
    };
    const cv::Point2d offset(
        wander(margin - principal.x - x0, w - 1 - margin - principal.x - x1, 2 * CV_PI * t + phase_x),
        wander(margin - principal.y - y0, h - 1 - margin - principal.y - y1,
               3 * CV_PI * t + phase_y));
    return pose(t, offset);
  }

  SceneTruth render_frame(int index, cv::Mat& image);
};

PlateScene::PlateScene(PlateSceneOptions options, NoiseOptions noise, RenderOptions render) {
  std::string error;
  if (!options.Check(&error) || !noise.Check(&error) || !render.Check(&error)) {
    throw InputError("plate scene: " + error);
  }
  impl_ = std::make_unique<Impl>();
  Impl& m = *impl_;
  m.options = options;
  m.noise = noise;
  m.render = render;
  const PlateSceneOptions& o = m.options;
  const int s = render.supersample;
  m.focal_px = std::max(o.size.width, o.size.height);
  m.principal = cv::Point2d((o.size.width - 1) / 2.0, (o.size.height - 1) / 2.0);

  // A zig-zag: every other dot offset across the row, so three or more never lie on one line.
  const double r = o.dot_radius_px, spacing = kSpacingRadii * r;
  for (int i = 0; i < o.dot_count; ++i) {
    const double across = o.dot_count == 1 ? 0.0 : (i % 2 == 0 ? -0.4 : 0.4) * spacing;
    m.dots.emplace_back((i - (o.dot_count - 1) / 2.0) * spacing, across);
  }
  double ux = 0, uy = 0;
  for (const cv::Point2d& d : m.dots) ux = std::max(ux, std::abs(d.x)), uy = std::max(uy, std::abs(d.y));
  ux += kMarginRadii * r;
  uy += kMarginRadii * r;
  m.corners = {{-ux, -uy}, {ux, -uy}, {ux, uy}, {-ux, uy}};

  cv::RNG rng(o.seed * 0xBF58476D1CE4E5B9ull + 0x94D049BB133111EBull);
  m.roll0_deg = rng.uniform(-20.0, 20.0);
  m.axis0_deg = rng.uniform(0.0, 180.0);
  m.phase_x = rng.uniform(0.0, 2 * CV_PI);
  m.phase_y = rng.uniform(0.0, 2 * CV_PI);

  // The whole plate must stay in front of the camera (and not graze it) in every frame.
  for (int i = 0; i < o.frame_count; ++i) {
    const cv::Matx33d h = m.image_from_plate(i);
    for (const cv::Point2d& c : m.corners) {
      const cv::Vec3d q = h * cv::Vec3d(c.x, c.y, 1.0);
      if (!(q[2] > 0.05 * m.focal_px / std::max(o.scale_start, o.scale_end))) {
        throw InputError("plate scene: the plate (" + std::to_string(o.dot_count) +
                         " dots of radius " + ShortNumber(r) + " px) reaches behind the camera at frame " +
                         std::to_string(i) + ": lower max_tilt_deg, the scales or the dot size");
      }
    }
  }

  if (o.cluttered_background) {
    sim::RenderBenchBackground(o.size, s, o.seed, &m.background_ss, &m.background);
  } else {
    // A plain gray card with a gentle lighting gradient.
    cv::Mat1f level(o.size);
    for (int y = 0; y < o.size.height; ++y) {
      for (int x = 0; x < o.size.width; ++x) {
        level(y, x) = static_cast<float>(125 + 20.0 * (x - m.principal.x) / o.size.width +
                                         10.0 * (y - m.principal.y) / o.size.height);
      }
    }
    cv::Mat merged, low;
    cv::merge(std::vector<cv::Mat>{level, level, level}, merged);
    merged.convertTo(low, CV_8U);
    cv::resize(low, m.background_ss, cv::Size(o.size.width * s, o.size.height * s), 0, 0,
               cv::INTER_LINEAR);
    cv::resize(m.background_ss, m.background, o.size, 0, 0, cv::INTER_AREA);
  }
  sim::DrawDistractors(o.distractors, s, m.background_ss, m.background);
  m.canvas_ss.create(m.background_ss.size(), CV_8UC3);
  m.mask_ss.create(m.background_ss.size(), CV_8U);
}

PlateScene::~PlateScene() = default;
PlateScene::PlateScene(PlateScene&&) noexcept = default;
PlateScene& PlateScene::operator=(PlateScene&&) noexcept = default;

const PlateSceneOptions& PlateScene::options() const { return impl_->options; }
int PlateScene::frame_count() const { return impl_->options.frame_count; }
cv::Matx33d PlateScene::image_from_plate(int index) const { return impl_->image_from_plate(index); }
const std::vector<cv::Point2d>& PlateScene::dot_centres() const { return impl_->dots; }

SceneTruth PlateScene::render(int index, cv::Mat& image) { return impl_->render_frame(index, image); }

SceneTruth PlateScene::Impl::render_frame(int index, cv::Mat& image) {
  const int s = render.supersample;
  const cv::Size size = options.size;
  const cv::Matx33d h = image_from_plate(index);
  // Output pixels to supersampled ones: xs = (x + 0.5) s - 0.5.
  const double o_ss = 0.5 * s - 0.5;
  const cv::Matx33d ss_from_image(s, 0, o_ss, 0, s, o_ss, 0, 0, 1);
  const cv::Matx33d ss_from_plate = ss_from_image * h;

  outline.clear();
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const cv::Point2d& c : corners) {
    const cv::Point2d p = Apply(h, c);
    outline.push_back(p);
    x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
  }
  const cv::Rect image_rect(cv::Point(0, 0), size);
  const cv::Rect dirty =
      cv::Rect(cv::Point(static_cast<int>(std::floor(std::max(-1.0, x0))) - 1,
                         static_cast<int>(std::floor(std::max(-1.0, y0))) - 1),
               cv::Point(static_cast<int>(std::ceil(std::min<double>(size.width, x1))) + 2,
                         static_cast<int>(std::ceil(std::min<double>(size.height, y1))) + 2)) &
      image_rect;

  conics.clear();
  for (const cv::Point2d& d : dots) {
    conics.push_back(sim::Conic::CircleThrough(ss_from_plate, d, options.dot_radius_px));
  }
  image.create(size, CV_8UC3);
  background.copyTo(image);
  if (!dirty.empty()) {
    const cv::Rect dirty_ss(dirty.x * s, dirty.y * s, dirty.width * s, dirty.height * s);
    cv::Mat canvas = canvas_ss(dirty_ss), mask = mask_ss(dirty_ss);
    background_ss(dirty_ss).copyTo(canvas);
    sim::FillPolygon(outline, s, dirty_ss.tl(), options.plate_bgr, 1.0, canvas, mask,
                     &polygon_scratch);
    for (const sim::Conic& conic : conics) sim::FillConic(conic, dirty_ss.tl(), options.dot_bgr, canvas);
    cv::Mat out = image(dirty);
    cv::resize(canvas, out, dirty.size(), 0, 0, cv::INTER_AREA);
  }

  const double gain = sim::GainAt(noise, index, options.frame_count);
  if (options.gray) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
    sim::ApplyCamera(noise, gain, index, gray, noise_buffer);
    cv::cvtColor(gray, image, cv::COLOR_GRAY2BGR);
  } else {
    sim::ApplyCamera(noise, gain, index, image, noise_buffer);
  }

  SceneTruth truth;
  truth.frame_index = index;
  truth.time_s = index / options.fps;
  truth.markers.resize(dots.size());
  const cv::Rect inside_ss(0, 0, size.width * s, size.height * s);
  for (size_t i = 0; i < dots.size(); ++i) {
    const sim::Conic& conic = conics[i];
    const cv::Rect box = conic.bounds();
    double total = 0, visible = 0, sum_x = 0, sum_y = 0;
    for (int y = box.y; y < box.y + box.height; ++y) {
      for (int x = box.x; x < box.x + box.width; ++x) {
        const double c = conic.coverage(x, y);
        if (c <= 0) continue;
        total += c;
        if (!inside_ss.contains(cv::Point(x, y))) continue;
        visible += c;
        sum_x += c * x;
        sum_y += c * y;
      }
    }
    MarkerTruth& m = truth.markers[i];
    m.name = "dot" + std::to_string(i);
    m.visible_fraction = total > 0 ? visible / total : 0.0;
    if (visible > 1e-6) {
      m.centroid_px = cv::Point2d(sim::FromSupersampled(sum_x / visible, s),
                                  sim::FromSupersampled(sum_y / visible, s));
    }
  }
  return truth;
}

}  // namespace softsight
