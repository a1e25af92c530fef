#include "softsight/geometry/measurement.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "geometry/measure_options.h"
#include "softsight/core/error.h"
#include "softsight/geometry/circle_fit.h"
#include "softsight/geometry/triangle.h"

namespace softsight {
namespace {

bool Finite(const cv::Point2d& p) { return std::isfinite(p.x) && std::isfinite(p.y); }

const cv::Point2d* Find(const std::vector<MarkerObservation>& markers, const std::string& name) {
  for (const MarkerObservation& m : markers) {
    if (m.name == name) return m.observation.position_px ? &*m.observation.position_px : nullptr;
  }
  return nullptr;
}

std::optional<double> Times(const std::optional<double>& value, double factor) {
  if (!value) return std::nullopt;
  return *value * factor;
}

// Radius and arc length from the chain's circle fit. Collinear markers are a straight actuator:
// no radius and the arc is the straight distance from first to last, as eq. 9 does for d = 0.
void MeasureChain(const std::vector<cv::Point2d>& chain, std::optional<double>* radius,
                  std::optional<double>* arc_length) {
  *radius = std::nullopt;
  *arc_length = std::nullopt;
  if (chain.size() < 3 || PointsAreDegenerate(chain)) return;
  if (PointsAreCollinear(chain)) {
    *arc_length = Chord(chain.front(), chain.back());
    return;
  }
  const std::optional<CircleFit> fit = FitCircleTaubin(chain);
  if (!fit) return;
  *radius = fit->radius;
  *arc_length = ArcLengthThroughPoints(*fit, chain);
}

}  // namespace

std::optional<cv::Point2d> MapToPlane(const cv::Matx33d& plane_from_image,
                                      const cv::Point2d& image_px) {
  const cv::Vec3d h = plane_from_image * cv::Vec3d(image_px.x, image_px.y, 1.0);
  // A point on (or numerically at) the vanishing line has no finite image in the plane.
  const double scale = std::abs(h[0]) + std::abs(h[1]) + std::abs(h[2]);
  if (!(std::abs(h[2]) > 1e-12 * scale)) return std::nullopt;
  const cv::Point2d p(h[0] / h[2], h[1] / h[2]);
  if (!Finite(p)) return std::nullopt;
  return p;
}

bool MetricModel::Check(std::string* error) const {
  std::string unused;
  if (error == nullptr) error = &unused;  // Check(nullptr) asks only whether it passes
  // Ranges are the table's (geometry/measure_options.cc); the rules across fields follow.
  if (const auto problem = CheckOptions(MetricModelOptions(), *this)) return Fail(error, *problem);
  if (scale_mm_per_px && plane_mm_from_image) {
    *error = "scale_mm_per_px and plane: give one metric model, not both";
    return false;
  }
  if (scale_mm_per_px && !(std::isfinite(*scale_mm_per_px) && *scale_mm_per_px > 0.0)) {
    *error = "scale_mm_per_px: must be a finite number > 0, got " +
             std::to_string(*scale_mm_per_px);
    return false;
  }
  if (scale_points && !scale_mm_per_px) {
    *error = "scale_points: given without the scale_mm_per_px they define";
    return false;
  }
  if (plane_mm_from_image) {
    const cv::Matx33d& h = *plane_mm_from_image;
    for (int i = 0; i < 9; ++i) {
      if (!std::isfinite(h.val[i])) {
        *error = "plane: the homography has a non-finite entry";
        return false;
      }
    }
    double norm = 0.0;
    for (int i = 0; i < 9; ++i) norm = std::max(norm, std::abs(h.val[i]));
    if (norm == 0.0 || std::abs(cv::determinant(h * (1.0 / norm))) < 1e-15) {
      *error = "plane: the homography is singular";
      return false;
    }
  }
  return true;
}

MeasureOptions MeasureOptions::AlongBody(const std::vector<std::string>& names_base_to_tip) {
  MeasureOptions measure;
  const size_t n = names_base_to_tip.size();
  if (n < 3) return measure;
  measure.base = names_base_to_tip.front();
  measure.middle = names_base_to_tip[n / 2];
  measure.tip = names_base_to_tip.back();
  if (n > 3) measure.chain = names_base_to_tip;
  return measure;
}

std::vector<std::string> MeasureOptions::inner_markers() const {
  if (chain.size() < 3) return {};
  return std::vector<std::string>(chain.begin() + 1, chain.end() - 1);
}

bool MeasureOptions::Check(std::string* error) const {
  std::string unused;
  if (error == nullptr) error = &unused;  // Check(nullptr) asks only whether it passes
  // Ranges are the table's (geometry/measure_options.cc); the rules across fields follow.
  if (const auto problem = CheckOptions(MeasureOptionsTable(), *this)) return Fail(error, *problem);
  if (has_triple()) {
    const std::pair<const char*, const std::string*> triple[] = {
        {"base", &base}, {"middle", &middle}, {"tip", &tip}};
    for (const auto& [field, name] : triple) {
      if (name->empty()) {
        *error = std::string("triple: the ") + field + " marker is not named";
        return false;
      }
    }
    if (base == middle || middle == tip || base == tip) {
      *error = "triple: base, middle and tip must be three different markers, got [" + base +
               ", " + middle + ", " + tip + "]";
      return false;
    }
  }
  if (!chain.empty()) {
    if (chain.size() < 3) {
      *error = "chain: needs at least 3 markers, got " + std::to_string(chain.size());
      return false;
    }
    std::set<std::string> seen;
    for (const std::string& name : chain) {
      if (name.empty() || !seen.insert(name).second) {
        *error = "chain: marker '" + name + "' is empty or listed twice";
        return false;
      }
    }
  }
  if (tip_reference_px && !Finite(*tip_reference_px)) {
    *error = "tip_reference: must be finite";
    return false;
  }
  return metric.Check(error);
}

Measurer::Measurer(MeasureOptions options) : options_(std::move(options)) {
  std::string error;
  if (!options_.Check(&error)) throw InputError("measurement options: " + error);
  tip_reference_px_ = options_.tip_reference_px;
}

void Measurer::reset_tip_reference() { tip_reference_px_ = options_.tip_reference_px; }

void Measurer::set_metric(const MetricModel& metric) {
  std::string error;
  if (!metric.Check(&error)) throw InputError("metric model: " + error);
  options_.metric = metric;
}

Measurement Measurer::measure(const std::vector<MarkerObservation>& markers) {
  Measurement out;
  measure(markers, out);
  return out;
}

void Measurer::measure(const std::vector<MarkerObservation>& markers, Measurement& out) {
  // Every value starts absent; the inner angles keep their storage.
  std::vector<std::optional<double>> inner = std::move(out.inner_angle_deg);
  out = Measurement();
  out.inner_angle_deg = std::move(inner);
  out.inner_angle_deg.assign(options_.chain.size() < 3 ? 0 : options_.chain.size() - 2,
                             std::nullopt);
  for (size_t k = 0; k < out.inner_angle_deg.size(); ++k) {
    const cv::Point2d* before = Find(markers, options_.chain[k]);
    const cv::Point2d* at = Find(markers, options_.chain[k + 1]);
    const cv::Point2d* after = Find(markers, options_.chain[k + 2]);
    if (before && at && after) out.inner_angle_deg[k] = AngleAtMiddleDeg(*before, *at, *after);
  }
  // Without a triple the names are empty and match no marker: the triple's values stay absent.
  const cv::Point2d* base = options_.has_triple() ? Find(markers, options_.base) : nullptr;
  const cv::Point2d* middle = options_.has_triple() ? Find(markers, options_.middle) : nullptr;
  const cv::Point2d* tip = options_.has_triple() ? Find(markers, options_.tip) : nullptr;
  const MetricModel& metric = options_.metric;
  const std::optional<cv::Matx33d>& plane = metric.plane_mm_from_image;
  const double scale = metric.scale_mm_per_px.value_or(1.0);

  // Plane points of every marker used below; absent when not mapped (or not mappable).
  auto to_plane = [&](const cv::Point2d* p) -> std::optional<cv::Point2d> {
    if (!p || !plane) return std::nullopt;
    return MapToPlane(*plane, *p);
  };

  if (tip) {
    if (!tip_reference_px_) tip_reference_px_ = *tip;
    out.tip_disp_px = Chord(*tip, *tip_reference_px_);
    if (metric.scale_mm_per_px) out.tip_disp_mm = *out.tip_disp_px * scale;
    if (plane) {
      const std::optional<cv::Point2d> t = to_plane(tip);
      const std::optional<cv::Point2d> r = to_plane(&*tip_reference_px_);
      if (t && r) out.tip_disp_mm = Chord(*t, *r);
    }
  }

  if (base && tip) {
    out.chord_px = Chord(*base, *tip);
    if (metric.scale_mm_per_px) out.chord_mm = *out.chord_px * scale;
    if (plane) {
      const std::optional<cv::Point2d> b = to_plane(base);
      const std::optional<cv::Point2d> t = to_plane(tip);
      if (b && t) out.chord_mm = Chord(*b, *t);
    }
  }

  if (base && middle && tip) {
    const TriangleMeasures px = MeasureTriangle(*base, *middle, *tip);
    out.angle_deg = px.angle_deg;
    out.sagitta_px = px.sagitta;
    out.radius_px = px.radius;
    out.arc_length_px = px.arc_length;
    out.circumradius_px = px.circumradius;
    if (metric.scale_mm_per_px) {
      out.sagitta_mm = Times(px.sagitta, scale);
      out.radius_mm = Times(px.radius, scale);
      out.arc_length_mm = Times(px.arc_length, scale);
    }
    if (plane) {
      const std::optional<cv::Point2d> b = to_plane(base);
      const std::optional<cv::Point2d> m = to_plane(middle);
      const std::optional<cv::Point2d> t = to_plane(tip);
      if (b && m && t) {
        const TriangleMeasures mm = MeasureTriangle(*b, *m, *t);
        out.sagitta_mm = mm.sagitta;
        out.radius_mm = mm.radius;
        out.arc_length_mm = mm.arc_length;
      }
    }
  }

  if (options_.chain.size() > 3) {
    std::vector<cv::Point2d> chain_px;
    std::vector<cv::Point2d> chain_mm;
    bool all_mapped = true;
    for (const std::string& name : options_.chain) {
      const cv::Point2d* p = Find(markers, name);
      if (!p) continue;
      chain_px.push_back(*p);
      if (plane) {
        const std::optional<cv::Point2d> q = MapToPlane(*plane, *p);
        if (q) chain_mm.push_back(*q);
        else all_mapped = false;
      }
    }
    MeasureChain(chain_px, &out.radius_px, &out.arc_length_px);
    out.radius_mm = std::nullopt;
    out.arc_length_mm = std::nullopt;
    if (metric.scale_mm_per_px) {
      out.radius_mm = Times(out.radius_px, scale);
      out.arc_length_mm = Times(out.arc_length_px, scale);
    }
    if (plane && all_mapped) MeasureChain(chain_mm, &out.radius_mm, &out.arc_length_mm);
  }
}

}  // namespace softsight
