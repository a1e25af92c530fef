// The paper's measurements (section 3) from named marker positions.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"

namespace softsight {

// Measurement (the per-frame values) is a core value type: softsight/core/types.h.

// How pixels become millimetres. Either one scale (camera axis orthogonal to the actuator's
// plane) or a homography from undistorted image pixels to plane millimetres (chessboard in the
// actuator's plane); the latter maps the points first and measures in the plane.
struct MetricModel {
  // Two (undistorted) image points a known distance apart, e.g. the ends of a ruler clicked live.
  struct ScalePoints {
    cv::Point2d a_px{}, b_px{};
    double distance_mm = 0.0;
  };

  std::optional<double> scale_mm_per_px{};
  std::optional<cv::Matx33d> plane_mm_from_image{};
  // Where scale_mm_per_px came from, when it was measured between two points: kept so that a
  // saved config states the points (`scale_from_points`), not only the number they gave.
  std::optional<ScalePoints> scale_points{};

  bool empty() const { return !scale_mm_per_px && !plane_mm_from_image; }
  // At most one of the two; the scale finite and > 0; the homography finite and invertible;
  // scale_points only beside a scale. On failure names the bad field in `error`.
  bool Check(std::string* error) const;
};

// Maps an (undistorted) image point into the plane through a homography. Absent when the point
// maps to infinity (it lies on the plane's vanishing line).
std::optional<cv::Point2d> MapToPlane(const cv::Matx33d& plane_from_image,
                                      const cv::Point2d& image_px);

struct MeasureOptions {
  // The triple, by marker name: all three named (the paper's measurements), or all three empty
  // (no triple: one or two markers, or a chain only; angle, chord, sagitta, ... stay absent).
  std::string base{}, middle{}, tip{};
  // Optional: every marker along the body in order, base to tip. Gives the angle at every inner
  // marker (Measurement::inner_angle_deg); with more than three, radius and arc length come from
  // a least-squares (Taubin) circle fit through all found markers.
  std::vector<std::string> chain{};
  // Reference for the bending distance; absent: the tip's position in the first frame where found.
  std::optional<cv::Point2d> tip_reference_px{};
  MetricModel metric{};

  // Markers named in body order, base to tip: the triple at the ends and the middle, and with
  // more than three the chain of them all (fewer than three: no triple, no chain).
  static MeasureOptions AlongBody(const std::vector<std::string>& names_base_to_tip);

  bool has_triple() const { return !base.empty() || !middle.empty() || !tip.empty(); }
  // The chain's inner markers chain[1] .. chain[N-2], whose angles inner_angle_deg holds.
  std::vector<std::string> inner_markers() const;

  // No triple, or base, middle and tip all named and distinct; chain empty or at least 3
  // distinct names; the tip reference finite; the metric model valid. On failure `error` starts
  // with the config key at fault ("triple: ...", "chain: ..."). Unknown marker names are the
  // config's business.
  bool Check(std::string* error) const;
};

// Stateful only in the tip reference; everything else is a pure function of the positions.
// The angle is measured on the image positions in every case (the paper's eq. 7); lengths get
// _mm twins when options.metric is set: with a scale the pixel lengths are multiplied, with a
// plane homography the points are mapped into the plane and every length is measured there.
class Measurer {
 public:
  // Throws InputError when options.Check fails.
  explicit Measurer(MeasureOptions options);
  Measurement measure(const std::vector<MarkerObservation>& markers);
  // The same into `out`, reusing its storage (no allocation per frame once inner_angle_deg has
  // its size).
  void measure(const std::vector<MarkerObservation>& markers, Measurement& out);
  // Next frame where the tip is found becomes the reference (or the configured point again).
  void reset_tip_reference();
  // A new metric model (e.g. a scale clicked live). The tip reference is kept: it is an image
  // point, independent of the model, so the bending distance does not restart. Throws
  // InputError (and changes nothing) when metric.Check fails.
  void set_metric(const MetricModel& metric);
  const MeasureOptions& options() const { return options_; }

 private:
  MeasureOptions options_;
  std::optional<cv::Point2d> tip_reference_px_;
};

}  // namespace softsight
