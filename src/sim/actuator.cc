#include "sim/actuator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

#include "softsight/core/error.h"

namespace softsight::sim {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Looks: pale translucent silicone; grey rigid parts. All low-saturation, so only the markers
// carry colour an HSV threshold could pick.
const cv::Vec3b kClampBgr{74, 72, 70};
const cv::Vec3b kSiliconeBgr{206, 210, 214};
const cv::Vec3b kChamberBgr{226, 229, 231};
const cv::Vec3b kHighlightBgr{250, 250, 250};
const cv::Vec3b kRibBgr{140, 146, 150};
constexpr double kBodyAlpha = 0.6;
constexpr double kPlateAlpha = 0.78;
constexpr double kChamberAlpha = 0.45;
constexpr double kHighlightAlpha = 0.3;
constexpr double kRibAlpha = 0.4;

// Outline vertices are placed so the polygon departs from the true arc by at most this much.
constexpr double kArcTolerancePx = 0.01;
// Margin kept free between the actuator and the image border over the whole motion.
constexpr double kBorderMarginPx = 3.0;

// Where the clamp holding the base sits, as fractions of the body's length and width.
constexpr double kClampLengthFraction = 0.12;
constexpr double kClampHalfWidthFraction = 0.8;

// Appends shapes to a pose, reusing the polygons (and their vertex buffers) of the previous
// pose: the shape count of a scene does not change from frame to frame.
class ShapeWriter {
 public:
  explicit ShapeWriter(std::vector<ShapePolygon>* shapes) : shapes_(shapes) {}
  std::vector<cv::Point2d>& add(const cv::Vec3b& bgr, double alpha) {
    if (used_ == shapes_->size()) shapes_->emplace_back();
    ShapePolygon& shape = (*shapes_)[used_++];
    shape.outline.clear();
    shape.bgr = bgr;
    shape.alpha = alpha;
    return shape.outline;
  }
  void add(std::initializer_list<cv::Point2d> outline, const cv::Vec3b& bgr, double alpha) {
    add(bgr, alpha).assign(outline);
  }
  // A thin quad from a to b, `thickness_px` wide.
  void stroke(const cv::Point2d& a, const cv::Point2d& b, double thickness_px,
              const cv::Vec3b& bgr, double alpha) {
    const cv::Point2d d = b - a;
    const double len = std::hypot(d.x, d.y);
    const cv::Point2d n = len > 0 ? cv::Point2d(-d.y / len, d.x / len) * (thickness_px / 2) : d;
    add({a + n, b + n, b - n, a - n}, bgr, alpha);
  }
  void finish() { shapes_->resize(used_); }

 private:
  std::vector<ShapePolygon>* shapes_;
  size_t used_ = 0;
};

void AddBounds(const cv::Point2d& p, double r, double* x0, double* y0, double* x1, double* y1) {
  *x0 = std::min(*x0, p.x - r);
  *y0 = std::min(*y0, p.y - r);
  *x1 = std::max(*x1, p.x + r);
  *y1 = std::max(*y1, p.y + r);
}

// The clamp that holds the base: a rigid block behind the base end (s < 0).
void AddClamp(const SceneOptions& o, const cv::Point2d& base, const cv::Point2d& u,
              const cv::Point2d& n, ShapeWriter* shapes) {
  const double depth = kClampLengthFraction * o.length_px;
  const double half = kClampHalfWidthFraction * o.width_px;
  shapes->add({base + half * n, base - half * n, base - half * n - depth * u,
               base + half * n - depth * u},
              kClampBgr, 1.0);
}

}  // namespace

double WedgeOpeningDeg(SceneKind kind) {
  switch (kind) {
    case SceneKind::kWedge1: return 20.0;
    case SceneKind::kWedge4: return 80.0;
    case SceneKind::kBending: return 0.0;
  }
  return 0.0;
}

ActuatorModel::ActuatorModel(const SceneOptions& options) : options_(options) {
  segments_ = options.kind == SceneKind::kWedge1 ? 1 : options.kind == SceneKind::kWedge4 ? 4 : 0;
  max_bend_deg_ = segments_ > 0 ? WedgeOpeningDeg(options.kind) : options.max_bend_deg;

  // The union of the body's extent over its whole range of motion, with the base at the origin.
  // The extent is smooth in the bend, so a fine sampling plus the margin covers it.
  double x0 = std::numeric_limits<double>::max(), y0 = x0;
  double x1 = std::numeric_limits<double>::lowest(), y1 = x1;
  ActuatorPose pose;
  constexpr int kSamples = 240;
  for (int i = 0; i <= kSamples; ++i) {
    pose_at(max_bend_deg_ * i / kSamples, cv::Point2d(0, 0), &pose);
    AddBounds(pose.bounds.tl(), 0, &x0, &y0, &x1, &y1);
    AddBounds(pose.bounds.br(), 0, &x0, &y0, &x1, &y1);
  }
  const double need_w = x1 - x0 + 2 * kBorderMarginPx;
  const double need_h = y1 - y0 + 2 * kBorderMarginPx;
  if (need_w > options.size.width || need_h > options.size.height) {
    auto num = [](double v) {
      std::ostringstream out;
      out << v;
      return out.str();
    };
    throw InputError("scene " + std::string(SceneKindName(options.kind)) + ": the actuator (length_px " +
                     num(options.length_px) + ", width_px " + num(options.width_px) + ") needs " +
                     num(std::ceil(need_w)) + "x" + num(std::ceil(need_h)) +
                     " px over its motion but the image is " + std::to_string(options.size.width) +
                     "x" + std::to_string(options.size.height) +
                     ": shorten the body or enlarge the image");
  }
  // Centre the swept extent in the image (pixel centres run from 0 to size - 1).
  base_ = cv::Point2d((options.size.width - 1) / 2.0 - (x0 + x1) / 2,
                      (options.size.height - 1) / 2.0 - (y0 + y1) / 2);
}

void ActuatorModel::pose(double bend_deg, ActuatorPose* pose) const {
  CV_DbgAssert(bend_deg >= 0 && bend_deg <= max_bend_deg_ + 1e-9);
  pose_at(bend_deg, base_, pose);
}

void ActuatorModel::pose_at(double bend_deg, const cv::Point2d& base, ActuatorPose* pose) const {
  pose->bend_deg = bend_deg;
  pose->marker_centres.clear();
  pose->centreline_radius_px.reset();
  if (segments_ == 0) {
    bending_pose(bend_deg * kDegToRad, base, pose);
  } else {
    wedge_pose(bend_deg * kDegToRad, base, pose);
  }
  double x0 = std::numeric_limits<double>::max(), y0 = x0;
  double x1 = std::numeric_limits<double>::lowest(), y1 = x1;
  for (const ShapePolygon& shape : pose->shapes) {
    for (const cv::Point2d& p : shape.outline) AddBounds(p, 0, &x0, &y0, &x1, &y1);
  }
  for (const cv::Point2d& c : pose->marker_centres) {
    AddBounds(c, options_.marker_radius_px, &x0, &y0, &x1, &y1);
  }
  pose->bounds = cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
}

// The centre line grows up from the base (u) and turns towards n (the image's right) with
// constant curvature k = bend / length: p(s) = base + u sin(ks)/k + n (1 - cos(ks))/k.
void ActuatorModel::bending_pose(double bend_rad, const cv::Point2d& base,
                                 ActuatorPose* pose) const {
  const cv::Point2d u(0, -1), n(1, 0);
  const double length = options_.length_px;
  const double half_width = options_.width_px / 2;
  const double k = bend_rad / length;
  const bool straight = bend_rad < 1e-12;
  if (!straight) pose->centreline_radius_px = 1.0 / k;
  auto point = [&](double s) {
    if (straight) return base + s * u;
    return base + (std::sin(k * s) / k) * u + ((1 - std::cos(k * s)) / k) * n;
  };
  // Unit normal towards the centre of curvature (n when straight).
  auto normal = [&](double s) { return -std::sin(k * s) * u + std::cos(k * s) * n; };

  ShapeWriter shapes(&pose->shapes);
  AddClamp(options_, base, u, n, &shapes);

  // Enough vertices that the chords stay within kArcTolerancePx of the outer arc.
  int steps = 1;
  if (!straight) {
    const double outer_radius = 1.0 / k + half_width;
    const double step_rad = std::sqrt(8 * kArcTolerancePx / outer_radius);
    steps = std::max(1, static_cast<int>(std::ceil(bend_rad / step_rad)));
  }
  // A band between two offsets across the centre line (negative: the outer side).
  auto band = [&](double from, double to, const cv::Vec3b& bgr, double alpha) {
    std::vector<cv::Point2d>& outline = shapes.add(bgr, alpha);
    for (int i = 0; i <= steps; ++i) {
      const double s = length * i / steps;
      outline.push_back(point(s) + from * normal(s));
    }
    for (int i = steps; i >= 0; --i) {
      const double s = length * i / steps;
      outline.push_back(point(s) + to * normal(s));
    }
  };
  band(-half_width, half_width, kSiliconeBgr, kBodyAlpha);
  // A soft highlight off-centre, as on a rounded translucent body.
  band(-0.55 * half_width, -0.15 * half_width, kHighlightBgr, kHighlightAlpha);
  // Chamber walls across the band (the texture a template tracker sees moving with the body).
  constexpr int kRibs = 12;
  for (int i = 0; i < kRibs; ++i) {
    const double s = length * (i + 0.5) / kRibs;
    const cv::Point2d p = point(s), m = normal(s);
    shapes.stroke(p - 0.85 * half_width * m, p + 0.85 * half_width * m, 1.2, kRibBgr, kRibAlpha);
  }
  shapes.finish();
  for (const SceneMarker& marker : options_.markers) {
    pose->marker_centres.push_back(point(marker.body_fraction * length));
  }
}

// A chain of rigid plates joined by wedge-shaped chambers. Each chamber's far face turns about
// its inner corner (the hinge, on the image's right) by bend / segments, so the chamber opens
// into a triangle on the outer side and everything after it turns with it.
void ActuatorModel::wedge_pose(double bend_rad, const cv::Point2d& base,
                               ActuatorPose* pose) const {
  const cv::Point2d u(0, -1), n(1, 0);
  const double width = options_.width_px;
  const double half_width = width / 2;
  const double gap = ChamberGapPx(options_);
  const double plate = PlateLengthPx(options_);
  const double opening = bend_rad / segments_;
  const double ca = std::cos(opening), sa = std::sin(opening);

  ShapeWriter shapes(&pose->shapes);
  AddClamp(options_, base, u, n, &shapes);

  // Material positions along the closed body: plates of length `plate`, chambers of `gap`.
  // A marker at body fraction f sits at closed length f * length on the centre line.
  std::vector<double> marker_s;
  for (const SceneMarker& marker : options_.markers) {
    marker_s.push_back(marker.body_fraction * options_.length_px);
  }
  pose->marker_centres.assign(marker_s.size(), base);

  cv::Point2d p = base, d = u, m = n;
  double s0 = 0.0;  // Closed length at the start of the current part.
  auto place = [&](double part_length, auto position_at) {
    for (size_t i = 0; i < marker_s.size(); ++i) {
      const double t = marker_s[i] - s0;
      if (t >= 0 && t <= part_length + 1e-9) pose->marker_centres[i] = position_at(t);
    }
    s0 += part_length;
  };
  for (int i = 0; i <= segments_; ++i) {
    // Plate.
    shapes.add({p - half_width * m, p + plate * d - half_width * m,
                p + plate * d + half_width * m, p + half_width * m},
               kSiliconeBgr, kPlateAlpha);
    place(plate, [&](double t) { return p + t * d; });
    p += plate * d;
    if (i == segments_) break;
    // Chamber.
    const cv::Point2d hinge = p + gap * d + half_width * m;
    const cv::Point2d d2 = ca * d + sa * m, m2 = ca * m - sa * d;
    const cv::Point2d far_centre = hinge - half_width * m2;
    const cv::Point2d near_outer = p - half_width * m, near_inner = p + half_width * m;
    const cv::Point2d far_outer = hinge - width * m2;
    shapes.add({near_outer, far_outer, hinge, near_inner}, kChamberBgr, kChamberAlpha);
    // Bellows folds.
    for (double f : {1.0 / 3, 2.0 / 3}) {
      shapes.stroke(near_outer + f * (far_outer - near_outer),
                    near_inner + f * (hinge - near_inner), 1.0, kRibBgr, kRibAlpha);
    }
    const cv::Point2d near_centre = p;
    place(gap, [&](double t) { return near_centre + (t / gap) * (far_centre - near_centre); });
    p = far_centre;
    d = d2;
    m = m2;
  }
  shapes.finish();
}

double ChamberGapPx(const SceneOptions& options) { return std::max(2.0, 0.5 * options.width_px); }

double PlateLengthPx(const SceneOptions& options) {
  const int segments = options.kind == SceneKind::kWedge1 ? 1 : 4;
  return (options.length_px - segments * ChamberGapPx(options)) / (segments + 1);
}

}  // namespace softsight::sim
