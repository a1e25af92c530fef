// Distractor placement (look-alikes of every marker colour, kept off the actuator's path) and
// drawing.
#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "sim/distractors.h"

#include "sim/actuator.h"
#include "sim/raster.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

// Bends sampled to build the swept area (the pose is smooth in the bend; the margin covers the
// gaps between samples).
constexpr int kSweepSamples = 180;
constexpr int kTriesPerDistractor = 4000;

// Everything the actuator covers at some bend, as a mask at output resolution.
cv::Mat1b SweptArea(const SceneOptions& scene) {
  const sim::ActuatorModel model(scene);
  cv::Mat1b swept(scene.size, uchar(0));
  sim::ActuatorPose pose;
  std::vector<cv::Point> points;
  for (int i = 0; i <= kSweepSamples; ++i) {
    model.pose(model.max_bend_deg() * i / kSweepSamples, &pose);
    for (const sim::ShapePolygon& shape : pose.shapes) {
      points.clear();
      for (const cv::Point2d& p : shape.outline) points.emplace_back(cvRound(p.x), cvRound(p.y));
      if (points.size() >= 3) cv::fillPoly(swept, std::vector<std::vector<cv::Point>>{points}, 255);
    }
    for (const cv::Point2d& c : pose.marker_centres) {
      cv::circle(swept, cv::Point(cvRound(c.x), cvRound(c.y)),
                 static_cast<int>(std::ceil(scene.marker_radius_px)) + 1, 255, cv::FILLED);
    }
  }
  return swept;
}

cv::Vec3b Darker(const cv::Vec3b& bgr, double factor) {
  return cv::Vec3b(cv::saturate_cast<uchar>(bgr[0] * factor), cv::saturate_cast<uchar>(bgr[1] * factor),
                   cv::saturate_cast<uchar>(bgr[2] * factor));
}

}  // namespace

std::vector<Distractor> MakeMarkerDistractors(const SceneOptions& scene, uint64_t seed) {
  const double r = scene.marker_radius_px;
  const double gap = std::max(6.0, r);

  // Free space: distance from every pixel to the nearest swept pixel or the image border.
  cv::Mat1b free_space = SweptArea(scene) == 0;
  free_space.row(0).setTo(0);
  free_space.row(free_space.rows - 1).setTo(0);
  free_space.col(0).setTo(0);
  free_space.col(free_space.cols - 1).setTo(0);
  cv::Mat1f clearance;
  cv::distanceTransform(free_space, clearance, cv::DIST_L2, cv::DIST_MASK_PRECISE);

  // The set, per marker colour. Angles are drawn with the positions.
  struct Wanted {
    cv::Size2d radii;
    cv::Vec3b bgr;
  };
  std::vector<Wanted> wanted;
  for (const SceneMarker& m : scene.markers) {
    wanted.push_back({{3.0 * r, 2.3 * r}, m.bgr});    // larger
    wanted.push_back({{2.0 * r, 0.75 * r}, m.bgr});   // elongated
    wanted.push_back({{r, r}, Darker(m.bgr, 0.5)});   // darker, same hue and size
    wanted.push_back({{0.5 * r, 0.5 * r}, m.bgr});    // too small
    wanted.push_back({{2.0 * r, 2.0 * r}, m.bgr});    // too large
  }
  // The largest first: they are the hardest to fit.
  std::stable_sort(wanted.begin(), wanted.end(), [](const Wanted& a, const Wanted& b) {
    return a.radii.width > b.radii.width;
  });

  cv::RNG rng(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull);
  std::vector<Distractor> placed;
  const int w = scene.size.width, h = scene.size.height;
  for (const Wanted& want : wanted) {
    const double extent = std::max(want.radii.width, want.radii.height);
    for (int attempt = 0; attempt < kTriesPerDistractor; ++attempt) {
      // y before x, as GCC evaluated the arguments when they were both draws: the scene must
      // not depend on the compiler, which C++ leaves free to order a call's arguments.
      const double cy = rng.uniform(0.0, h - 1.0);
      const cv::Point2d c(rng.uniform(0.0, w - 1.0), cy);
      // Distance to the nearest pixel centre of the swept area or border, from the nearest
      // pixel: +-0.71 px, covered by rounding the need up by one pixel.
      const int px = std::clamp(cvRound(c.x), 0, w - 1), py = std::clamp(cvRound(c.y), 0, h - 1);
      if (clearance(py, px) < extent + gap + 1.0) continue;
      if (c.x - extent < 1 || c.y - extent < 1 || c.x + extent > w - 2 || c.y + extent > h - 2) {
        continue;
      }
      bool clear = true;
      for (const Distractor& other : placed) {
        const double need = extent + std::max(other.radii_px.width, other.radii_px.height) + gap;
        clear = clear && std::hypot(c.x - other.centre_px.x, c.y - other.centre_px.y) >= need;
      }
      if (!clear) continue;
      placed.push_back({c, want.radii, rng.uniform(0.0, 180.0), want.bgr});
      break;
    }
  }
  return placed;
}

}  // namespace softsight

namespace softsight::sim {

std::string CheckDistractors(const std::vector<Distractor>& distractors) {
  for (size_t i = 0; i < distractors.size(); ++i) {
    const Distractor& d = distractors[i];
    if (!(std::isfinite(d.centre_px.x) && std::isfinite(d.centre_px.y) &&
          std::isfinite(d.angle_deg) && std::isfinite(d.radii_px.width) &&
          std::isfinite(d.radii_px.height) && d.radii_px.width > 0 && d.radii_px.height > 0)) {
      return "distractors: distractor " + std::to_string(i + 1) +
             " needs a finite centre and angle and positive radii";
    }
  }
  return "";
}

void DrawDistractors(const std::vector<Distractor>& distractors, int supersample,
                     cv::Mat& background_ss, cv::Mat& background) {
  if (distractors.empty()) return;
  const double s = supersample;
  for (const Distractor& d : distractors) {
    const Conic ellipse = Conic::Ellipse(ToSupersampled(d.centre_px, supersample), d.radii_px * s,
                                         d.angle_deg);
    FillConic(ellipse, cv::Point(0, 0), d.bgr, background_ss);
  }
  cv::resize(background_ss, background, background.size(), 0, 0, cv::INTER_AREA);
}

}  // namespace softsight::sim
