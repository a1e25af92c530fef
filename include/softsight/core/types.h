// Value types that flow through the pipeline:
//   FrameSource -> Tracker -> Observation -> Measurement -> Sinks.
//
// Conventions (see docs/conventions in README):
// - Pixel (row i, column j) has its centre at x = j, y = i (OpenCV's moments convention).
// - Lengths carry their unit in the name (_px, _mm); time is in seconds (time_s), durations in _ms.
// - A value that cannot be computed is absent (std::optional), never 0 and never the last good value.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

// One decoded image with its position in the stream.
struct Frame {
  cv::Mat image{};      // 8-bit BGR (CV_8UC3); sources convert gray input only when asked to.
  int64_t index = 0;    // 0-based position in the source.
  double time_s = 0.0;  // Timestamp given by the source (video PTS, file rate, or wall clock).
  // When the frame was read from its source, on this machine's steady clock: where its latency
  // (FrameResult::latency_result_ms, the CSV's latency_*_ms) is counted from. A camera's: when
  // the capture call returned it (the camera's own exposure-to-driver delay comes before); a
  // file's: when it was decoded. Left at the epoch by a source, RunPipeline stamps it when
  // read() returns.
  std::chrono::steady_clock::time_point captured{};
  // Decoded on its own: every frame of a camera, an image sequence or an intra-only codec
  // (HuffYUV, FFV1, MJPG), and the key frames of a codec that predicts frames from earlier ones
  // (MPEG-4, H.264). A predicted frame repeats any damage of the frames it was decoded from,
  // silently, up to the next key frame: the session accepts a lasting change of the whole
  // picture (a bumped camera) only once a key frame shows it too.
  bool key_frame = true;
  // The source delivered the very picture it delivered before (a frozen camera whose driver
  // keeps handing out its last buffer, a frame relay that stalled): not a new measurement. The
  // session reports every marker `stale` in it, so a control loop holds, then vents, as when the
  // markers are lost. Live sources set it; a recording's repeated frames are its own business.
  bool repeated = false;
};

// Why a marker has (or has no) position in a frame: the per-marker `<name>_status` CSV column.
// "found" means verified: a tracker or the session that is unsure reports one of the others.
enum class MarkerStatus : uint8_t {
  kFound,        // Position reported: the candidate fitted the marker's model and the arrangement.
  kLost,         // No candidate fitted the marker's model in the searched region.
  kAmbiguous,    // Several candidates fitted about equally well: none is reported.
  kImplausible,  // A candidate fitted, but its position contradicts the motion so far or the
                 // other markers (a jump, a segment length, the order along the body).
  kCovered,      // The marker is where expected but too little of it is visible to measure.
  kOutOfFrame,   // The marker's expected position lies outside the image.
  kNotStarted,   // The tracker has nothing to look for yet (its template frame is still ahead).
  kStale,        // The live source repeated its last picture (Frame::repeated): no new measurement.
};

// "found", "lost", "ambiguous", "implausible", "covered", "out_of_frame", "not_started",
// "stale".
const char* MarkerStatusName(MarkerStatus status);

// What one tracker says about its marker in one frame. A marker that was not found has no
// position: trackers never report a stale or predicted position as an observation.
struct Observation {
  std::optional<cv::Point2d> position_px{};  // Sub-pixel, pixel-centre convention.
  std::optional<double> score{};             // Tracker-specific quality (see its header).
  // The position's standard uncertainty along each image axis, px (set with position_px): from
  // the marker's size, contrast and noise, a partial view, the match's fit. A found marker lies
  // within 3 sigma of its true centre (docs/measurements.md, "Uncertainty").
  std::optional<double> sigma_px{};
  // Why there is no position (ignored while position_px is set): see status().
  MarkerStatus not_found_reason = MarkerStatus::kLost;
  // With kAmbiguous: how many candidates fitted about equally (for the summary's "2 candidates").
  int candidates = 0;

  bool found() const { return position_px.has_value(); }
  MarkerStatus status() const { return found() ? MarkerStatus::kFound : not_found_reason; }
  // A not-found observation with its reason.
  static Observation NotFound(MarkerStatus reason, int candidates = 0) {
    Observation o;
    o.not_found_reason = reason;
    o.candidates = candidates;
    return o;
  }
};

// Where a marker's track stands after a frame: the per-marker `<name>_track` CSV column. One
// state per marker, kept by the session's association (its motion model: position, velocity and
// their covariance); the status says what this frame's report was, the track what the session
// believes of the marker over time.
enum class TrackState : uint8_t {
  kLost,       // No track: never found yet, forgotten (a seek, a re-selection), or unseen too long.
  kTentative,  // Found in this frame, the first report of its track: its velocity is unknown.
  kConfirmed,  // Found in this frame, continuing a track of two reports or more.
  kCoasting,   // Not found in this frame, but still predicted: a re-acquisition must lie where a
               // plausible motion since it was last found puts it (for up to kCoastFrames).
};
// Frames a track coasts unseen before it is lost (a second at 30 fps).
inline constexpr int kCoastFrames = 30;

// "lost", "tentative", "confirmed", "coasting".
const char* TrackStateName(TrackState state);

// A named observation, as the pipeline hands it to measurement and sinks.
struct MarkerObservation {
  std::string name{};
  Observation observation{};
  TrackState track = TrackState::kLost;  // Set by the session after the frame's association.
};

// One frame's measurements. Absent where undefined (a marker missing, a straight actuator has
// no radius), never 0. The _mm twins are present only when a metric model is configured.
struct Measurement {
  std::optional<double> angle_deg{};        // Eq. 7 at the middle marker; 180 when straight.
  std::optional<double> chord_px{};         // c = |base - tip|.
  std::optional<double> sagitta_px{};       // d = distance of the middle marker from the chord.
  std::optional<double> radius_px{};        // Eq. 8, or the circle fit with more than 3 markers.
  std::optional<double> arc_length_px{};    // Eq. 9 (major arc when d > R); = c when straight.
  std::optional<double> circumradius_px{};  // Circle through the three points: a cross-check.
  std::optional<double> tip_disp_px{};      // Bending distance: tip displacement from reference.
  // With a chain of N >= 3 markers: the angle (eq. 7) at each inner marker chain[1] .. chain[N-2],
  // in chain order, between its two neighbours along the chain (the paper's multi-segment
  // actuators have one per hinge); absent where that marker or a neighbour is not found. Empty
  // without a chain. CSV: angle_<name>_deg.
  std::vector<std::optional<double>> inner_angle_deg{};

  std::optional<double> chord_mm{};
  std::optional<double> sagitta_mm{};
  std::optional<double> radius_mm{};
  std::optional<double> arc_length_mm{};
  std::optional<double> tip_disp_mm{};
};

// Everything the pipeline learned from one frame, as sinks (CSV, overlay, controller) see it.
struct FrameResult {
  int64_t frame_index = 0;
  double time_s = 0.0;
  std::vector<MarkerObservation> markers{};  // In config order.
  Measurement measurement{};
  double proc_ms = 0.0;                    // Tracking + measurement time for this frame.
  // The frame's capture time (Frame::captured) and the time from it to this result (when the
  // session finished the frame: reading, queueing and tracking included).
  std::chrono::steady_clock::time_point captured{};
  double latency_result_ms = 0.0;
};

}  // namespace softsight
