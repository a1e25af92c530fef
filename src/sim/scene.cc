#include "softsight/core/format.h"
#include "softsight/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <set>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "sim/actuator.h"
#include "sim/background.h"
#include "sim/camera.h"
#include "sim/distractors.h"
#include "sim/raster.h"
#include "sim/scene_checks.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

// Beyond this the bending band would run into its own base.
constexpr double kMaxBendingDeg = 330.0;

}  // namespace

bool SceneOptions::Check(std::string* error) const {
  if (!sim::CheckVideoShape(size, frame_count, fps, error)) return false;
  if (!(std::isfinite(length_px) && length_px > 0)) {
    return Fail(error, "length_px: must be > 0, got " + ShortNumber(length_px));
  }
  if (!(std::isfinite(width_px) && width_px > 0)) {
    return Fail(error, "width_px: must be > 0, got " + ShortNumber(width_px));
  }
  if (!(std::isfinite(marker_radius_px) && marker_radius_px > 0)) {
    return Fail(error, "marker_radius_px: must be > 0, got " + ShortNumber(marker_radius_px));
  }
  if (oscillate && oscillate_cycles < 1) {
    return Fail(error, "oscillate_cycles: must be at least 1, got " +
                           std::to_string(oscillate_cycles));
  }
  if (kind == SceneKind::kBending) {
    if (!(std::isfinite(max_bend_deg) && max_bend_deg > 0 && max_bend_deg <= kMaxBendingDeg)) {
      return Fail(error, "max_bend_deg: must be in (0, " + ShortNumber(kMaxBendingDeg) + "], got " +
                             ShortNumber(max_bend_deg));
    }
    // The inner edge must keep a positive radius at the strongest bend.
    const double min_radius_px = length_px / (max_bend_deg * std::numbers::pi / 180.0);
    if (width_px / 2 >= min_radius_px) {
      return Fail(error, "width_px: " + ShortNumber(width_px) + " is too wide for a bend of " +
                             ShortNumber(max_bend_deg) + " degrees over length_px " + ShortNumber(length_px) +
                             " (at most " + ShortNumber(2 * min_radius_px) + ")");
    }
  } else if (sim::PlateLengthPx(*this) < 2 * marker_radius_px) {
    return Fail(error, "length_px: " + ShortNumber(length_px) + " is too short for the " +
                           SceneKindName(kind) + " plates to carry markers of radius " +
                           ShortNumber(marker_radius_px));
  }
  if (const std::string bad = sim::CheckDistractors(distractors); !bad.empty()) {
    return Fail(error, bad);
  }
  if (background != BackgroundKind::kDefault && background != BackgroundKind::kBench) {
    return Fail(error, "background: unknown kind " + std::to_string(static_cast<int>(background)));
  }
  std::set<std::string> names;
  for (const SceneMarker& marker : markers) {
    if (marker.name.empty()) return Fail(error, "markers: a marker has an empty name");
    if (!names.insert(marker.name).second) {
      return Fail(error, "markers: the name '" + marker.name + "' is used twice");
    }
    if (!(marker.body_fraction >= 0 && marker.body_fraction <= 1)) {
      return Fail(error, "markers: '" + marker.name + "' body_fraction must be in [0, 1], got " +
                             ShortNumber(marker.body_fraction));
    }
  }
  return true;
}

bool NoiseOptions::Check(std::string* error) const {
  if (!(std::isfinite(sigma) && sigma >= 0 && sigma <= 128)) {
    return Fail(error, "noise sigma: must be in [0, 128] grey levels, got " + ShortNumber(sigma));
  }
  if (!(std::isfinite(blur_sigma_px) && blur_sigma_px >= 0 && blur_sigma_px <= 50)) {
    return Fail(error, "blur_sigma_px: must be in [0, 50], got " + ShortNumber(blur_sigma_px));
  }
  if (!(std::isfinite(gain_start) && gain_start > 0)) {
    return Fail(error, "gain_start: must be > 0, got " + ShortNumber(gain_start));
  }
  if (!(std::isfinite(gain_end) && gain_end > 0)) {
    return Fail(error, "gain_end: must be > 0, got " + ShortNumber(gain_end));
  }
  return true;
}

bool RenderOptions::Check(std::string* error) const {
  if (supersample < 1 || supersample > 16) {
    return Fail(error, "supersample: must be in [1, 16], got " + std::to_string(supersample));
  }
  return true;
}

SceneKind ParseSceneKind(const std::string& name) {
  if (name == "bending") return SceneKind::kBending;
  if (name == "wedge1") return SceneKind::kWedge1;
  if (name == "wedge4") return SceneKind::kWedge4;
  throw InputError("unknown scene '" + name + "' (choose bending, wedge1 or wedge4)");
}

const char* SceneKindName(SceneKind kind) {
  switch (kind) {
    case SceneKind::kBending: return "bending";
    case SceneKind::kWedge1: return "wedge1";
    case SceneKind::kWedge4: return "wedge4";
  }
  return "?";
}

struct SyntheticScene::Impl {
  SceneOptions scene;
  NoiseOptions noise;
  RenderOptions render;
  std::vector<Occluder> occluders;
  std::vector<cv::Rect> occluder_ss;  // Each occluder's supersampled pixels.
  sim::ActuatorModel model;
  std::optional<Measurer> measurer;

  // Reused buffers: the cached backdrop at both resolutions and the supersampled canvas.
  cv::Mat background_ss, background, canvas_ss, mask_ss;
  cv::Mat noise_buffer;
  sim::ActuatorPose pose;
  std::vector<cv::Point2d> centres_ss;
  std::vector<int> active;  // Occluders drawn in the current frame.
  std::vector<std::pair<int, int>> covers;  // Truth: covered column intervals of one row.
  std::vector<cv::Point> polygon_scratch;
  std::vector<MarkerObservation> observations;

  Impl(SceneOptions s, NoiseOptions n, RenderOptions r, std::vector<Occluder> o)
      : scene(std::move(s)), noise(n), render(r), occluders(std::move(o)), model(scene) {}

  double gain(int index) const { return sim::GainAt(noise, index, scene.frame_count); }

  void compute_truth(SceneTruth* truth);
  SceneTruth render_pose(double bend_deg, double time_s, int index, cv::Mat& image);
};

SyntheticScene::SyntheticScene(SceneOptions scene, NoiseOptions noise, RenderOptions render,
                               std::vector<Occluder> occluders) {
  std::string error;
  if (!scene.Check(&error) || !noise.Check(&error) || !render.Check(&error)) {
    throw InputError("synthetic scene: " + error);
  }
  for (size_t i = 0; i < occluders.size(); ++i) {
    const Occluder& o = occluders[i];
    if (!(o.rect_px.width > 0 && o.rect_px.height > 0 && std::isfinite(o.rect_px.x) &&
          std::isfinite(o.rect_px.y) && std::isfinite(o.rect_px.width) &&
          std::isfinite(o.rect_px.height))) {
      throw InputError("occluder " + std::to_string(i + 1) +
                       ": the rectangle needs a finite position and a positive size");
    }
    if (o.first_frame < 0 || o.last_frame < o.first_frame) {
      throw InputError("occluder " + std::to_string(i + 1) + ": frames must satisfy 0 <= first <= "
                       "last, got " + std::to_string(o.first_frame) + ".." +
                       std::to_string(o.last_frame));
    }
  }
  impl_ = std::make_unique<Impl>(std::move(scene), noise, render, std::move(occluders));
  Impl& m = *impl_;
  const int s = m.render.supersample;
  const cv::Rect image_ss(0, 0, m.scene.size.width * s, m.scene.size.height * s);
  for (const Occluder& o : m.occluders) {
    m.occluder_ss.push_back(sim::SupersampledRect(o.rect_px, s) & image_ss);
  }
  if (m.scene.background == BackgroundKind::kBench) {
    sim::RenderBenchBackground(m.scene.size, s, m.scene.seed, &m.background_ss, &m.background);
  } else {
    sim::RenderBackground(m.scene.size, s, m.scene.seed, &m.background_ss, &m.background);
  }
  sim::DrawDistractors(m.scene.distractors, s, m.background_ss, m.background);
  m.canvas_ss.create(image_ss.size(), CV_8UC3);
  m.mask_ss.create(image_ss.size(), CV_8U);
  if (m.scene.markers.size() >= 3) {
    MeasureOptions measure = SceneMeasureOptions(m.scene);
    // Bending distance from the rest pose, the first frame of every time profile.
    m.model.pose(0.0, &m.pose);
    for (size_t i = 0; i < m.scene.markers.size(); ++i) {
      if (m.scene.markers[i].name == measure.tip) measure.tip_reference_px = m.pose.marker_centres[i];
    }
    m.measurer.emplace(std::move(measure));
  }
}

SyntheticScene::~SyntheticScene() = default;
SyntheticScene::SyntheticScene(SyntheticScene&&) noexcept = default;
SyntheticScene& SyntheticScene::operator=(SyntheticScene&&) noexcept = default;

const SceneOptions& SyntheticScene::options() const { return impl_->scene; }
int SyntheticScene::frame_count() const { return impl_->scene.frame_count; }
double SyntheticScene::max_bend_deg() const { return impl_->model.max_bend_deg(); }

double SyntheticScene::bend_at(int index) const {
  const SceneOptions& o = impl_->scene;
  const double t = o.frame_count > 1 ? std::clamp(index / double(o.frame_count - 1), 0.0, 1.0) : 0.0;
  // A raised cosine: starts and ends at rest velocity, like an actuator filled by a pump.
  const double phase = o.oscillate ? 2 * std::numbers::pi * o.oscillate_cycles * t : std::numbers::pi * t;
  return max_bend_deg() * (1 - std::cos(phase)) / 2;
}

SceneTruth SyntheticScene::render(int index, cv::Mat& image) {
  return impl_->render_pose(bend_at(index), index / impl_->scene.fps, index, image);
}

SceneTruth SyntheticScene::render_at_bend(double bend_deg, double time_s, int index,
                                          cv::Mat& image) {
  const double bend = std::isfinite(bend_deg) ? std::clamp(bend_deg, 0.0, max_bend_deg()) : 0.0;
  return impl_->render_pose(bend, time_s, index, image);
}

SceneTruth SyntheticScene::Impl::render_pose(double bend_deg, double time_s, int index,
                                             cv::Mat& image) {
  const int s = render.supersample;
  model.pose(bend_deg, &pose);
  active.clear();
  for (size_t i = 0; i < occluders.size(); ++i) {
    if (index >= occluders[i].first_frame && index <= occluders[i].last_frame &&
        !occluder_ss[i].empty()) {
      active.push_back(static_cast<int>(i));
    }
  }

  // Only the region that differs from the cached backdrop is drawn at the supersampled
  // resolution: the actuator's bounds and the active occluders, on whole output pixels so that
  // its area-average equals that of the full canvas.
  const cv::Rect image_rect(cv::Point(0, 0), scene.size);
  const cv::Rect2d& b = pose.bounds;
  cv::Rect dirty(cv::Point(static_cast<int>(std::floor(b.x)) - 1,
                           static_cast<int>(std::floor(b.y)) - 1),
                 cv::Point(static_cast<int>(std::ceil(b.x + b.width)) + 2,
                           static_cast<int>(std::ceil(b.y + b.height)) + 2));
  for (int i : active) {
    const cv::Rect& r = occluder_ss[i];
    dirty |= cv::Rect(cv::Point(r.x / s, r.y / s),
                      cv::Point((r.x + r.width + s - 1) / s, (r.y + r.height + s - 1) / s));
  }
  dirty &= image_rect;
  const cv::Rect dirty_ss(dirty.x * s, dirty.y * s, dirty.width * s, dirty.height * s);
  cv::Mat canvas = canvas_ss(dirty_ss);
  cv::Mat mask = mask_ss(dirty_ss);
  background_ss(dirty_ss).copyTo(canvas);
  const cv::Point origin = dirty_ss.tl();
  for (const sim::ShapePolygon& shape : pose.shapes) {
    sim::FillPolygon(shape.outline, s, origin, shape.bgr, shape.alpha, canvas, mask,
                     &polygon_scratch);
  }
  centres_ss.clear();
  for (const cv::Point2d& c : pose.marker_centres) centres_ss.push_back(sim::ToSupersampled(c, s));
  const double radius_ss = scene.marker_radius_px * s;
  for (size_t i = 0; i < centres_ss.size(); ++i) {
    sim::FillDisc(centres_ss[i], radius_ss, origin, scene.markers[i].bgr, canvas);
  }
  for (int i : active) {
    const cv::Rect r = occluder_ss[i] & dirty_ss;
    if (!r.empty()) canvas(r - origin).setTo(cv::Scalar(occluders[i].bgr));
  }

  image.create(scene.size, CV_8UC3);
  background.copyTo(image);
  cv::Mat out = image(dirty);
  cv::resize(canvas, out, dirty.size(), 0, 0, cv::INTER_AREA);

  sim::ApplyCamera(noise, gain(index), index, image, noise_buffer);

  SceneTruth truth;
  truth.frame_index = index;
  truth.time_s = time_s;
  truth.bend_deg = bend_deg;
  truth.centreline_radius_px = pose.centreline_radius_px;
  compute_truth(&truth);
  return truth;
}

// Each marker's visible area, sub-pixel by sub-pixel: its coverage, times the part not covered
// by the markers drawn after it, zero under an active occluder or outside the image. These are
// exactly the weights with which the marker's colour enters the rendered canvas.
void SyntheticScene::Impl::compute_truth(SceneTruth* truth) {
  const int s = render.supersample;
  const int width_ss = scene.size.width * s, height_ss = scene.size.height * s;
  const double radius_ss = scene.marker_radius_px * s;
  truth->markers.resize(scene.markers.size());
  observations.resize(scene.markers.size());
  for (size_t i = 0; i < scene.markers.size(); ++i) {
    const cv::Point2d& c = centres_ss[i];
    double total = 0, visible = 0, sum_x = 0, sum_y = 0;
    const int first = sim::DiscFirstRow(c, radius_ss), last = sim::DiscLastRow(c, radius_ss);
    for (int y = first; y <= last; ++y) {
      int x0, x1;
      if (!sim::DiscSpan(c, radius_ss, y, &x0, &x1)) continue;
      covers.clear();  // Occluded column intervals of this row.
      for (int k : active) {
        const cv::Rect& r = occluder_ss[k];
        if (y >= r.y && y < r.y + r.height) covers.emplace_back(r.x, r.x + r.width - 1);
      }
      const bool row_inside = y >= 0 && y < height_ss;
      for (int x = x0; x <= x1; ++x) {
        const double coverage = sim::DiscCoverage(c, radius_ss, x, y);
        total += coverage;
        if (!row_inside || x < 0 || x >= width_ss || coverage <= 0) continue;
        bool hidden = false;
        for (const auto& [c0, c1] : covers) hidden = hidden || (x >= c0 && x <= c1);
        if (hidden) continue;
        double w = coverage;
        for (size_t j = i + 1; j < centres_ss.size(); ++j) {
          w *= 1.0 - sim::DiscCoverage(centres_ss[j], radius_ss, x, y);
        }
        visible += w;
        sum_x += w * x;
        sum_y += w * y;
      }
    }
    MarkerTruth& m = truth->markers[i];
    m.name = scene.markers[i].name;
    m.visible_fraction = total > 0 ? visible / total : 0.0;
    m.centroid_px.reset();
    // Below a millionth of a sub-pixel nothing of the marker is left to see.
    if (visible > 1e-6) {
      m.centroid_px = cv::Point2d(sim::FromSupersampled(sum_x / visible, s),
                                  sim::FromSupersampled(sum_y / visible, s));
    }
    observations[i].name = m.name;
    observations[i].observation = Observation{m.centroid_px, std::nullopt};
  }
  if (measurer) truth->measurement = measurer->measure(observations);
}

MeasureOptions SceneMeasureOptions(const SceneOptions& scene) {
  std::vector<size_t> order(scene.markers.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return scene.markers[a].body_fraction < scene.markers[b].body_fraction;
  });
  std::vector<std::string> names;
  for (size_t i : order) names.push_back(scene.markers[i].name);
  return MeasureOptions::AlongBody(names);
}

}  // namespace softsight
