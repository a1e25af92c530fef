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

}  // namespace softsight
