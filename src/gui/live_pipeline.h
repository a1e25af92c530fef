// Internal to gui (and the tests). The live window's data flow, apart from its input and its
// view: a frame -> the tracking session (the only owner of the config) -> the run (PipelineRun:
// the same work per frame and the same summary as every command's RunPipeline) -> its sinks: a
// recording (its CSV, raw and annotated videos, and the config that reproduces it) joins the
// run while it records. The controller maps keys and the mouse to calls here and to edits of
// session(); the session tells a running recording of every edit it makes, so the recording's
// config keeps each one without the controller having to remember to.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "softsight/config/config.h"
#include "gui/live_window.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/run.h"
#include "softsight/core/types.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/tracking_session.h"

namespace softsight {

class LiveRecording;

// Where and how recordings are written.
struct LiveRecordingSettings {
  std::string prefix = "softsight-live";  // Files <prefix>-NNN.{csv,raw.avi,avi,yaml}.
  // Tests: both videos' encoder hook (AsyncFrameWriter), to make an encoder fall behind.
  std::function<void(int64_t index)> before_encode;
  // The recordings' CSV columns after the tracking ones (LiveOptions::extra_columns).
  std::vector<CsvColumn> extra_columns;
};

class LivePipeline {
 public:
  // Builds the tracking session. `sinks` (not owned) see every processed frame from the first
  // (LiveOptions::sinks). Throws InputError on a bad config.
  LivePipeline(const TrackingConfig& config, LiveRecordingSettings settings,
               std::vector<FrameSink*> sinks = {});
  ~LivePipeline();  // Closes a running recording (what it wrote stays).

  // The frames come from `source` (its description, rate and liveness, for the summary and the
  // recordings): before the first frame.
  void describe_source(const FrameSource& source);

  TrackingSession& session() { return *session_; }
  const TrackingSession& session() const { return *session_; }
  const TrackingConfig& config() const { return session_->config(); }

  // A frame of the source (the next one, or one stepped or sought to): tracked and measured,
  // counted in the run's statistics and, while a recording runs, recorded. A recording that
  // cannot take it (a full disk) is stopped (take_recording_failure() says why); what it wrote
  // stays. Throws InputError as TrackingSession::process.
  const FrameResult& process(const Frame& frame);
  // The frame on screen measured again after a change that is no tracker edit (a new metric
  // scale, which cannot change while recording): neither counted nor recorded.
  const FrameResult& measure_again(const Frame& frame);

  // Starts a recording whose frame 0 is `frame`, the frame on screen: every tracker is rebuilt
  // from the recording's start config (RecordingStartConfig with `boxes`, one per marker in
  // config order: where the marker is now), as `track` builds them from the saved config, and
  // the bending-distance reference restarts at this frame. Returns the frame's result, recorded
  // as the recording's first row. `draw` draws the annotated video's overlay. Throws InputError
  // (unwritable folder, no codec) with no recording running and the session unchanged.
  const FrameResult& start_recording(const Frame& frame,
                                     const std::vector<std::optional<cv::Rect>>& boxes, double fps,
                                     FrameDrawer draw);
  // Closes the recording's files; returns how many frames it holds. No recording: 0.
  int64_t stop_recording();
  bool recording() const { return recording_ != nullptr; }
  // The running recording's file prefix (without extension); empty when none runs.
  std::string recording_prefix() const;
  // The last closed recording's prefix; empty if none.
  const std::string& last_recording() const { return last_recording_; }
  // Why the recording stopped by itself since this was last asked (a frame or an edit it could
  // not keep: "recorded N frames to P.*; <the error>"), once.
  std::optional<std::string> take_recording_failure();

  // The run so far, for the end summary (a recording still open counted too): what every command
  // reports, with the recordings' CSV-row latency and a note per recording.
  LiveRunSummary summary(int64_t dropped_by_source) const;

 private:
  // A recording that cannot keep a frame or an edit stops, keeping what it wrote.
  void fail(const std::string& why);

  // What a closed (or still open) recording adds to the summary.
  void count_recording(const LiveRecording& recording, std::vector<double>* row_ms,
                       std::vector<std::string>* notes, int64_t* recorded, int64_t* waits) const;

  LiveRecordingSettings settings_;
  std::unique_ptr<TrackingSession> session_;
  std::unique_ptr<PipelineRun> run_;
  std::unique_ptr<LiveRecording> recording_;
  class RecordingInRun;
  std::unique_ptr<RecordingInRun> in_run_;  // The recording's place among the run's sinks.
  std::optional<std::string> frame_failure_;  // A frame the recording could not take.
  std::string last_recording_;
  std::optional<std::string> failure_;
  // The closed recordings: their CSV rows' latencies, one note each, frames, encoder waits.
  std::vector<double> row_ms_;
  std::vector<std::string> notes_;
  int64_t recorded_ = 0, encoder_waits_ = 0;
};

}  // namespace softsight
