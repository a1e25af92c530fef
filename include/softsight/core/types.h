// Value types that flow through the pipeline:
//   FrameSource -> Tracker -> Observation -> Measurement -> Sinks.
//
// Conventions (see docs/conventions in README):
// - Pixel (row i, column j) has its centre at x = j, y = i (OpenCV's moments convention).
// - Lengths carry their unit in the name (_px, _mm); time is in seconds (time_s), durations in _ms.
// - A value that cannot be computed is absent (std::optional), never 0 and never the last good value.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

// One decoded image with its position in the stream.
struct Frame {
  cv::Mat image;        // 8-bit BGR (CV_8UC3); sources convert gray input only when asked to.
  int64_t index = 0;    // 0-based position in the source.
  double time_s = 0.0;  // Timestamp given by the source (video PTS, file rate, or wall clock).
};

// What one tracker says about its marker in one frame. A marker that was not found has no
// position: trackers never report a stale or predicted position as an observation.
struct Observation {
  std::optional<cv::Point2d> position_px;  // Sub-pixel, pixel-centre convention.
  std::optional<double> score;             // Tracker-specific quality (see each tracker's header).

  bool found() const { return position_px.has_value(); }
};

// A named observation, as the pipeline hands it to measurement and sinks.
struct MarkerObservation {
  std::string name;
  Observation observation;
};

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

// Everything the pipeline learned from one frame, as sinks (CSV, overlay, controller) see it.
struct FrameResult {
  int64_t frame_index = 0;
  double time_s = 0.0;
  std::vector<MarkerObservation> markers;  // In config order.
  Measurement measurement;
  double proc_ms = 0.0;                    // Tracking + measurement time for this frame.
};

}  // namespace softsight
