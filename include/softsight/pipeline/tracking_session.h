// Wires the per-frame stages: Frame -> one Tracker per marker -> Observations -> Measurement.
// Sinks (CSV, overlay, video, controller) consume the FrameResult; this class owns no I/O.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "softsight/calib/camera_calibration.h"
#include "softsight/core/types.h"
#include "softsight/geometry/measurement.h"
#include "softsight/io/config.h"
#include "softsight/track/tracker.h"

namespace softsight {

// FrameResult (one frame's observations + measurement) is a core value type: core/types.h.

class TrackingSession {
 public:
  // Builds one tracker per configured marker. Throws InputError on a bad spec.
  explicit TrackingSession(const TrackingConfig& config);
  ~TrackingSession();

  // Tracks every marker in `frame` and measures. On the first frame (and on a marker's template
  // frame) trackers are initialised from the config's ROIs and template rectangles. With a camera
  // model, observations stay in recorded-image pixels (where the overlay draws them) and the
  // measurement uses their undistorted positions. Throws InputError when the frame size differs
  // from the calibrated one.
  const FrameResult& process(const Frame& frame);

  // Live recalibration: the marker is inside `rect` on `frame` (re-cuts a template, or restricts
  // the colour tracker's next acquisition). Throws InputError for an unknown marker.
  void reselect(const std::string& marker, const cv::Mat& frame, const cv::Rect& rect);
  // Replace a marker's spec (new HSV ranges or method) and rebuild its tracker.
  void respec(const MarkerSpec& spec);
  void reset_tip_reference();

  const TrackingConfig& config() const { return config_; }

 private:
  TrackingConfig config_;
  std::vector<std::unique_ptr<Tracker>> trackers_;
  std::vector<bool> initialised_;
  Measurer measurer_;
  std::optional<Undistorter> undistorter_;     // Present when the config names a camera file.
  std::vector<MarkerObservation> undistorted_; // Reused: what the measurer sees with a lens model.
  FrameResult result_;
};

}  // namespace softsight
