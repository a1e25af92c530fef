// Two cameras, one actuator: each view is tracked by its own TrackingSession, the markers are
// matched across the views by name, every pair is checked against the epipolar constraint and
// triangulated (calib/triangulation.h), and the 3D shape is measured (geometry/shape3d.h).
// A marker is found in 3D only when both views found it and the pair is verified; otherwise its
// status says why (never a point from an unverified pair).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/calib/board_frame.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/calib/triangulation.h"
#include "softsight/config/config.h"
#include "softsight/core/types.h"
#include "softsight/geometry/shape3d.h"
#include "softsight/io/csv_columns.h"
#include "softsight/io/stereo_input.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sink.h"

namespace softsight {

struct StereoOptions {
  TriangulationOptions triangulation{};
  // What the out-of-plane angle is measured against: the first camera's image plane (default:
  // a bend seen face on reads 0), the bending plane of the first frame where it is defined
  // (three found markers not on a line): how far the bend has turned since, or a bench board's
  // plane (`board_normal`): how far the bend leans out of the bench.
  enum class ReferencePlane { kImage, kFirstFrame, kBoard };
  ReferencePlane reference_plane = ReferencePlane::kImage;
  // kBoard: the board's normal in the first camera's frame (BoardFrame::rotation's third column,
  // calib/board_frame.h), any non-zero length; its sign does not matter. Absent by default;
  // required by kBoard, not used otherwise.
  std::optional<cv::Vec3d> board_normal{};
  // The frame every result is expressed in: absent (default) the first camera's; a bench board's
  // (calib/board_frame.h, `track-stereo --bench-board`): each result's positions, covariances
  // and bending-plane normal in the board's frame (ExpressInBoardFrame), after the session has
  // measured in the camera's.
  std::optional<BoardFrame> results_in_board{};

  bool Check(std::string* error) const;
};

// "image", "first" or "board"; throws InputError naming `what` and listing the choices.
StereoOptions::ReferencePlane ParseReferencePlane(const std::string& text, const std::string& what);

struct StereoMarkerResult {
  std::string name{};
  Observation left{}, right{};  // Each view's own observation (raw pixels).
  StereoPoint point{};          // The verified 3D point, or why there is none.
  // "found", "epipolar", "behind", "timing" (StereoStatus::kTiming), or the first view that did not find the marker and why
  // ("left_lost", "right_covered", ...).
  std::string status{};
};

struct StereoFrameResult {
  int64_t frame_index = 0;                  // The left view's frame.
  int64_t right_frame_index = 0;            // The right view's frame paired with it.
  double time_s = 0.0;                      // The left view's.
  // Paired by time: the right frame's time minus the left one's (ms), the pairing error.
  std::optional<double> pair_dt_ms{};
  // When the markers' motion over the last pairs says the right view's frames are not of the
  // left one's moment: by how many right frames the right one is later (negative: earlier).
  // Moving markers are then not found in 3D (status "timing"). Absent: no sign of it.
  std::optional<double> lag_frames{};
  std::vector<StereoMarkerResult> markers{};  // In the left config's order.
  // In millimetres, the first camera's frame: the chain's angle, plane, circle and tip.
  Shape3d shape{};
  // A chain of more than 3 markers: the circle through each inner marker and its two
  // neighbours (StereoSession::segment_names), in chain order. Empty otherwise.
  std::vector<Segment3d> segments{};
  // What each camera alone measures (eq. 7 on its image positions), for comparison.
  std::optional<double> left_angle_deg{}, right_angle_deg{};
  double proc_ms = 0.0;
  // Each view's own tracking of this pair (StereoSession::left_result / right_result: its
  // markers in its config's order, raw pixels, and what that camera alone measures), for a sink
  // that draws the views (the stereo window). Owned by the session: valid while the pair's
  // sinks run (until its next pair); a copy kept longer must not use them.
  const FrameResult* left_view = nullptr;
  const FrameResult* right_view = nullptr;
  // The left frame's capture time (Frame::captured) and the time from it to this result, as
  // FrameResult has them.
  std::chrono::steady_clock::time_point captured{};
  double latency_result_ms = 0.0;
};

class StereoSession {
 public:
  // The step a run drives (pipeline/run.h): a pair of frames in, its 3D result out.
  using Input = FramePair;
  using Result = StereoFrameResult;

  // `left` and `right` configure each view's markers (colours may look different through two
  // cameras; rois differ); every marker of `left` must be in `right` by name. The chain measured
  // is left.measure's chain, else its triple. Throws InputError naming what is wrong.
  StereoSession(const TrackingConfig& left, const TrackingConfig& right,
                const StereoCalibration& stereo, const StereoOptions& options = {});
  ~StereoSession();
  StereoSession(StereoSession&&) noexcept;
  StereoSession& operator=(StereoSession&&) noexcept;

  // Tracks both frames and measures in 3D. Throws InputError when a frame's size is not the
  // calibrated one (naming the view).
  const StereoFrameResult& process(const Frame& left, const Frame& right);
  // The same for a pair from a StereoInput (its pairing error goes into the result).
  const StereoFrameResult& process(const FramePair& pair);

  std::vector<std::string> marker_names() const;
  // The chain's inner markers, whose segments StereoFrameResult::segments holds (a chain of
  // more than 3 markers; else none).
  std::vector<std::string> segment_names() const;
  const Triangulator& triangulator() const;
  // Each view's config, as given.
  const TrackingConfig& left_config() const;
  const TrackingConfig& right_config() const;
  // Each view's own tracking of the last pair: its markers (in its config's order, raw pixels)
  // and what that camera alone measures; what the stereo window draws on each view. Empty
  // before the first pair; valid until the next process().
  const FrameResult& left_result() const;
  const FrameResult& right_result() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Two views' sink: every pair as read and its 3D result (with each view's own tracking:
// StereoFrameResult::left_view / right_view, for the stereo window).
using PairSink = BasicFrameSink<FramePair, StereoFrameResult>;
// Two views' run: RunPipeline's loop, summary and sinks over pairs (pipeline/run.h). Its summary
// counts a marker found where it is found in 3D, and a frame measured where the 3D angle is.
using StereoPipelineRun = BasicPipelineRun<StereoSession>;
// A pair run pulled one pair at a time (pipeline/run.h BasicRunStream; Python's frames_stereo).
using StereoRunStream = BasicRunStream<StereoInput, StereoSession>;

// What a pair run tells its sinks in begin(): the input (its description, the left view's rate,
// live or not; frame_count only from `options.max_frames`) and the markers' names.
RunInfo DescribeRun(const StereoInput& input, const StereoSession& session,
                    const RunOptions& options = {});
// The one run (pipeline/run.h RunPipeline) on pairs: each pair through the session and to every
// sink, until the input ends, max_frames pairs are done, a stop is requested or an InputError
// ends it (kError, its message in the summary). A session that needs colour refuses a gray
// pair. With RunOptions::check_key_frame_groups (the default), a pair of predicted videos is
// checked view by view as one view's video is (pipeline/run.h), and a pair goes on once both
// its views' groups are checked: a marker either view's decoder silently moved is not found in
// 3D there (status "left_implausible" / "right_implausible"), and the 3D shape made with it is
// absent.
RunSummary RunPipeline(StereoInput& input, StereoSession& session,
                       const std::vector<PairSink*>& sinks, const RunOptions& options = {});

// What a pair run's report says beyond its RunSummary (whose markers count the pairs each was
// found in 3D): per marker the pairs refused by the epipolar check and by the pairing check
// (timing), the 3D uncertainty of each found point and the epipolar distance of each pair both
// views found, the lag the markers' motion showed, and the pairing error (pairing by time).
struct StereoRunFigures {
  std::vector<int64_t> epipolar{}, timing{};  // Per marker, in the session's order.
  std::vector<double> sigma_mm{}, epipolar_px{}, lag_frames{};
  bool paired_by_time = false;  // A pair had a pairing error (pair_dt_ms).
  std::optional<double> max_abs_pair_dt_ms{};
};

// Collects StereoRunFigures over a pair run (track-stereo's report, Python's summary).
class StereoFiguresSink : public PairSink {
 public:
  void begin(const RunInfo& info) override;
  void consume(const FramePair& pair, const StereoFrameResult& result) override;
  const StereoRunFigures& figures() const { return figures_; }

 private:
  StereoRunFigures figures_;
};

// Expresses a frame's 3D results in a board's frame (calib/board_frame.h) instead of the first
// camera's: each found marker's position and covariance, and the bending plane's normal. The
// angles, radii, arc lengths, the tip displacement and the out-of-plane angle do not depend on
// the frame and are left as they are.
void ExpressInBoardFrame(const BoardFrame& frame, StereoFrameResult& result);

// The stereo CSV's columns: frame, right_frame, time_s, pair_dt_ms; per marker <m>_X, <m>_Y,
// <m>_Z (mm, first camera's frame), <m>_sigma_mm, <m>_epipolar_px, <m>_status; then angle_deg
// (3D), out_of_plane_deg, plane_nx, plane_ny, plane_nz, radius_mm, arc_length_mm, tip_disp_mm;
// per segment (inner marker <s> of a chain of more than 3) angle_<s>_deg, radius_<s>_mm,
// arc_length_<s>_mm; then angle_left_deg, angle_right_deg, proc_ms. Absent values are empty
// fields.
BasicCsvColumnTable<StereoFrameResult> StereoColumns(
    const std::vector<std::string>& marker_names,
    const std::vector<std::string>& segment_names = {});
// The suffixes of a marker's columns in StereoColumns (_X ... _status): its marker/<name> topic
// on the stream.
std::vector<std::string> StereoMarkerSuffixes();

}  // namespace softsight
