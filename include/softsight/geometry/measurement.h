// The paper's measurements (section 3) from named marker positions.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"

namespace softsight {

// One frame's measurements. Absent where undefined (a marker missing, a straight actuator has
// no radius), never 0. The _mm twins are present only when a metric model is configured.
struct Measurement {
  std::optional<double> angle_deg;        // Eq. 7 at the middle marker; 180 when straight.
  std::optional<double> chord_px;         // c = |base - tip|.
  std::optional<double> sagitta_px;       // d = distance of the middle marker from the chord.
  std::optional<double> radius_px;        // Eq. 8, or the circle fit with more than 3 markers.
  std::optional<double> arc_length_px;    // Eq. 9 (major arc when d > R); = c when straight.
  std::optional<double> circumradius_px;  // Circle through the three points: a cross-check.
  std::optional<double> tip_disp_px;      // Bending distance: tip displacement from reference.

  std::optional<double> chord_mm;
  std::optional<double> sagitta_mm;
  std::optional<double> radius_mm;
  std::optional<double> arc_length_mm;
  std::optional<double> tip_disp_mm;
};

// How pixels become millimetres. Either one scale (camera axis orthogonal to the actuator's
// plane) or a homography from undistorted image pixels to plane millimetres (chessboard in the
// actuator's plane); the latter maps the points first and measures in the plane.
struct MetricModel {
  std::optional<double> scale_mm_per_px;
  std::optional<cv::Matx33d> plane_mm_from_image;
};

struct MeasureOptions {
  std::string base, middle, tip;          // The triple, by marker name.
  // Optional: every marker along the body in order, base to tip. With more than three, radius
  // and arc length come from a least-squares (Taubin) circle fit through all found markers.
  std::vector<std::string> chain;
  // Reference for the bending distance; absent: the tip's position in the first frame where found.
  std::optional<cv::Point2d> tip_reference_px;
  MetricModel metric;
};

// Stateful only in the tip reference; everything else is a pure function of the positions.
class Measurer {
 public:
  explicit Measurer(MeasureOptions options);
  Measurement measure(const std::vector<MarkerObservation>& markers);
  // Next frame where the tip is found becomes the reference (or the configured point again).
  void reset_tip_reference();
  const MeasureOptions& options() const { return options_; }

 private:
  MeasureOptions options_;
  std::optional<cv::Point2d> tip_reference_px_;
};

}  // namespace softsight
