// Wires the per-frame stages: Frame -> one Tracker per marker -> Observations -> Measurement.
// Sinks (CSV, overlay, video, controller) consume the FrameResult; this class owns no I/O.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "softsight/calib/camera_calibration.h"
#include "softsight/core/types.h"
#include "softsight/geometry/measurement.h"
#include "softsight/config/config.h"
#include "softsight/track/tracker.h"

namespace softsight {

class FrameChangeDetector;
class ArrangementCheck;
class MarkerTracks;

// FrameResult (one frame's observations + measurement) is a core value type: core/types.h.

class TrackingSession {
 public:
  // The step a run drives (pipeline/run.h): one frame in, its result out.
  using Input = Frame;
  using Result = FrameResult;

  // Builds one tracker per configured marker. Throws InputError on a bad spec.
  explicit TrackingSession(const TrackingConfig& config);
  ~TrackingSession();
  TrackingSession(TrackingSession&&) noexcept;
  TrackingSession& operator=(TrackingSession&&) noexcept;

  // Starts over as a session newly built from `config`: trackers, motion models, the learned
  // arrangement of the body, the frame-change reference and the bending-distance reference, all
  // as a new session has them (a live recording's start, which `track` on the recording must
  // reproduce from its config alone). The edit listener stays. Throws InputError on a bad spec,
  // and then changes nothing.
  void restart(const TrackingConfig& config);

  // Tracks every marker in `frame` and measures. On the first frame (and on a marker's template
  // frame) trackers are initialised from the config's ROIs and template rectangles. A live
  // recording's edits (config.changes) are made after the row of their frame, as live. Only
  // plausible reports are found (the association with each marker's motion, the body's
  // arrangement and the frame-change check, in src/pipeline/): in a
  // frame that changed all at once (another video's frame, a flash) no marker is found and the
  // trackers do not see it; a report next to decoded garbage, that jumps against the marker's
  // motion, or that breaks the markers' arrangement along the body is kImplausible and its
  // tracker searches afresh. With a camera
  // model, observations stay in recorded-image pixels (where the overlay draws them) and the
  // measurement uses their undistorted positions. Throws InputError when the frame size differs
  // from the calibrated one.
  const FrameResult& process(const Frame& frame);

  // Live recalibration: the marker is inside `rect` on `frame`, the frame process() saw last
  // (re-cuts a template, or restricts the colour tracker's acquisition). The new tracker tracks
  // that frame at once; returns the frame's result with it. config() records the selection so a
  // saved config reproduces it: a template's pixels, rect and frame index (tracking starts there
  // and then), a colour marker's search box and its frame (roi_frame: from there on). Throws InputError for an unknown marker or a
  // rectangle the tracker cannot use.
  const FrameResult& reselect(const std::string& marker, const Frame& frame, const cv::Rect& rect);
  // Replace a marker's spec (new HSV ranges or method) and rebuild its tracker.
  void respec(const MarkerSpec& spec);
  void reset_tip_reference();
  // The next frame does not follow the last one (the live window seeked, stepped back or looped):
  // every tracker searches afresh and the motion and whole-frame-change checks start over, so a
  // jump is neither believed as motion nor taken for a foreign frame. The learned arrangement of
  // the body and the bending-distance reference stay.
  void jump();
  // Live calibration: a new metric model (e.g. a scale from two clicked points) for the next
  // measurements and in config(). The bending-distance reference is kept (it is an image point,
  // whatever the model), so tip_disp_px continues and tip_disp_mm is that distance in the new
  // model. Throws InputError and changes nothing when the model is invalid.
  void set_metric(const MetricModel& metric);
  // The pixels measurements use for a point of the recorded image: undistorted with the
  // config's camera model, else the point itself (e.g. clicks to become scale_from_points).
  cv::Point2d measurement_point(const cv::Point2d& image_px) const;

  // The frame on screen again, for marker `marker` alone, after its spec changed (respec) while
  // the window is paused: its new tracker starts and tracks `frame` (the frame process() saw
  // last) at once, so the effect of new ranges shows without a new frame. The config is not
  // changed. Throws InputError for an unknown marker.
  const FrameResult& retrack(const std::string& marker, const Frame& frame);
  // The marker's tracker, for the mask view's diagnostics (candidates, membership, search
  // region). `index` in config order.
  const Tracker& tracker(size_t index) const { return *trackers_.at(index); }

  const TrackingConfig& config() const { return config_; }

  // Who keeps the live edits (a live recording, whose config must reproduce them): told of each
  // respec, reselect, retrack and reset_tip_reference once it is made, as a ConfigChange
  // (`after_frame`: the index of the frame process() saw last). Edits happen only here, so a
  // recording cannot miss one. A config's own `changes:` replayed by process() are edits too.
  // The listener must not call back into the session. Empty: nobody listens.
  using EditListener = std::function<void(const ConfigChange& change)>;
  void set_edit_listener(EditListener listener) { edit_listener_ = std::move(listener); }

 private:
  void edited(ConfigChange change) const;  // Tells the listener, if any.
  EditListener edit_listener_;
  int64_t last_frame_ = -1;  // The index of the frame process() saw last.
  void measure(const Frame& frame);  // result_.measurement from result_.markers.
  // The frame's measurement, timing and latency, then the live edits made after it.
  const FrameResult& finish(const Frame& frame, int64_t start_ticks);
  // The config's recorded live edits (config.changes) due after `frame`, the frame just processed.
  void apply_changes(const Frame& frame);
  size_t next_change_ = 0;  // The first of config_.changes not yet applied.
  TrackingConfig config_;
  std::vector<std::unique_ptr<Tracker>> trackers_;
  std::vector<bool> initialised_;
  std::unique_ptr<FrameChangeDetector> frame_change_;
  std::unique_ptr<ArrangementCheck> arrangement_;
  std::vector<std::optional<double>> motion_support_;  // Per marker, this frame (reused).
  std::unique_ptr<MarkerTracks> tracks_;  // Motion models and the global association.
  std::vector<const std::vector<MarkerCandidate>*> candidate_lists_;  // Reused per frame.
  Measurer measurer_;
  std::optional<Undistorter> undistorter_;     // Present when the config names a camera file.
  std::vector<MarkerObservation> undistorted_; // Reused: what the measurer sees with a lens model.
  FrameResult result_;
};

}  // namespace softsight
