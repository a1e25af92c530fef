// `softsight track-stereo`: two videos of one actuator from a calibrated pair of cameras ->
// each view tracked by its own TrackingSession -> markers matched by name, epipolar-checked and
// triangulated -> 3D positions and measurements, one CSV row per pair of frames.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/commands.h"
#include "softsight/io/camera_settings.h"
#include "softsight/pipeline/stereo_session.h"
#include "stream/publish_sink.h"

namespace softsight {

struct TrackingConfig;

// One view's marker config (LoadTrackingConfig), every marker ready for a run without the mouse
// (a template marker with its template); throws InputError naming the file and marker.
TrackingConfig LoadStereoViewConfig(const std::string& file);

struct TrackStereoOptions {
  std::string config_file;                       // Markers (and the triple or chain).
  std::optional<std::string> right_config_file;  // The right view's, when its rois differ.
  std::string left_input, right_input;           // Videos, image folders or patterns.
  // Instead of left_input and right_input: one video, the first camera in the left half of each
  // frame, the second in the right half.
  std::optional<std::string> side_by_side;
  // Instead of left_input and right_input: two live cameras (V4L2 indices), paired by the time
  // each frame was captured.
  std::optional<CameraId> left_camera, right_camera;
  std::string stereo_file;                       // From `calibrate --left --right`.
  std::string csv_file;
  // Pairing by index: the right view's frame paired with left frame i is i + frame_offset (the
  // right camera started recording frame_offset frames earlier; negative: later). Absent: found
  // from a flash or the motion (io/frame_offset.h) within +-max_offset_frames, or refused.
  std::optional<int64_t> frame_offset;
  int64_t max_offset_frames = 60;
  // "index" (frame i with frame i + frame_offset) or "time" (each frame with the other view's
  // nearest in time, within half a frame interval; io/stereo_input.h).
  std::string pair_by = "index";
  // Pairing by time: the right view's clock minus the left one's (ms).
  double time_offset_ms = 0.0;
  double max_epipolar_px = 2.0;           // See TriangulationOptions.
  // "image", "first" or "board" (StereoOptions; board needs bench_board).
  std::string reference_plane = "image";
  std::optional<int64_t> max_frames;
  double sequence_fps = 30.0;  // Image sequences' frame rate.
  std::optional<double> right_sequence_fps;  // The right image sequence's, when it differs.
  // Empty, or one pair of images (left, right) of the chessboard lying on the bench: the 3D
  // coordinates are then in the board's frame (calib/board_frame.h) instead of the first
  // camera's. The board: `chessboard` ("9x6", inner corners) and `square_mm`, each taken from
  // the stereo file when not given.
  std::vector<std::string> bench_board;
  std::string chessboard;
  std::optional<double> square_mm;
  // --publish: every pair's row (the CSV's columns) to subscribers as it happens
  // (stream/publish_sink.h; topics frame, measure, marker/<name> with <name>_X ... _status).
  std::optional<PublishOptions> publish;
  // `--window`: both views side by side with their overlay and a strip chart of the 3D angle,
  // each camera's and the out-of-plane angle, while the CSV is written as without it (the
  // window runs in the live plugin, app/track_stereo_window.cc). `pace`: recorded inputs play
  // at their frame rate in it (cameras come at theirs); false: as fast as they are tracked.
  bool window = false;
  bool pace = true;
  double chart_seconds = 10.0;  // The strip chart's time span.
};

// What a run feeds besides the CSV, and what may end it early: the stereo window.
struct StereoRunHooks {
  // Not owned; each sees every pair after its CSV row and its record on the stream.
  std::vector<PairSink*> sinks;
  // Polled before each pair is read: true ends the run there, as the end of the input would
  // (the window's q, Escape or close; Ctrl-C). Empty: never.
  std::function<bool()> stop_requested;
  // What stopped it, for the summary line ("stopped by Ctrl-C (SIGINT)"). Empty: "stopped from
  // the window".
  std::function<std::string()> stop_reason;
};

struct TrackStereoSummary {
  int64_t pairs = 0;  // Pairs of frames tracked (CSV rows).
  // Per marker: pairs found in 3D, pairs refused by the epipolar check, and pairs refused by the
  // pairing check (status timing: the views' frames not of one moment).
  std::vector<std::pair<std::string, int64_t>> found, epipolar, timing;
  // The pairs whose markers' motion said the views' frames are not of one moment, and the
  // median lag they showed (right frames; positive: the right frame is later).
  int64_t lagging_pairs = 0;
  std::optional<double> median_lag_frames;
  // The lag was one amount all along (at least 4 lagging pairs, their quartiles within half a
  // frame): a wrong frame offset, not two rates or a dropped frame.
  bool steady_lag = false;
  std::optional<double> median_sigma_mm;     // Over the found points.
  std::optional<double> median_epipolar_px;  // Over the pairs both views found.
  // Pairing: the offset used (by index), and frames of each view left without a partner (by
  // time: none within the tolerance; by index: the earlier view's first frames).
  std::optional<int64_t> frame_offset;
  int64_t left_unpaired = 0, right_unpaired = 0;
  std::optional<double> max_abs_pair_dt_ms;  // By time: the worst pairing error.
  // With a bench board: its fit's RMS residual (mm), the coordinates in its frame.
  std::optional<double> bench_board_rms_mm;
  bool stopped = false;  // Ended by StereoRunHooks::stop_requested before the input did.
};

// Runs the whole job and prints its report. Throws InputError for bad input (config, stereo
// file, videos, offset, outputs that are inputs), a frame of the wrong size, or an offset that
// cannot be found (one line: pass --frame-offset).
TrackStereoSummary RunTrackStereo(const TrackStereoOptions& options, std::ostream& report,
                                  const StereoRunHooks& hooks = {});
// The same on pairs from `input` (any two sources: cameras, stand-ins in tests); the options'
// inputs, offset and pairing are not used.
TrackStereoSummary RunTrackStereo(const TrackStereoOptions& options, StereoInput& input,
                                  std::ostream& report, const StereoRunHooks& hooks = {});

// The stereo window for a run with --window, and how the run learns that it was closed. Made
// by the live plugin (the only one that loads the GUI's libraries): `track-stereo --window` runs
// there (app/command_table.h). Throws InputError when there is no display.
struct StereoWindowRun {
  std::unique_ptr<PairSink> sink;
  std::function<bool()> stop_requested;
};
// `left` and `right`: each view's config (the markers each view's triangle joins).
using StereoWindowOpener = StereoWindowRun (*)(const TrackStereoOptions& options,
                                               const TrackingConfig& left,
                                               const TrackingConfig& right);

// The command line of `track-stereo`; `open_window` makes the window for --window (null: none,
// the commands plugin).
CommandRunner SetupTrackStereoCommand(CLI::App& sub, StereoWindowOpener open_window);

}  // namespace softsight
