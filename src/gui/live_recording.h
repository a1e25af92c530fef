// The files the live window writes: a recording, and the saved config. Internal to gui.
//
// One recording of the live window: its files are the pipeline's sinks (the CSV, the raw
// lossless video, the annotated video) plus the config that reproduces it, so `softsight track
// --config <prefix>.yaml --input <prefix>.raw.avi` gives the same rows. Internal to gui.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "softsight/config/config.h"
#include "softsight/pipeline/sink.h"
#include "softsight/pipeline/sinks.h"

namespace softsight {

class LiveRecording : public FrameSink {
 public:
  // Opens <base>-NNN.csv, .raw.avi, .avi and writes .yaml, with the first NNN whose CSV does not
  // exist (nothing is overwritten); begin() (with `info`'s frame size) starts the files. It
  // joins the live run (PipelineRun::join) for the frames that follow its first.
  // `config` is what the session runs from this frame on;
  // `origin` the source frame and time of the recording's first frame, saved with the config
  // (its `recording:` key) so that re-tracking the raw video names the source's frames.
  // `draw` draws the overlay of the annotated video. Throws InputError (unwritable folder, no
  // free number, no codec) with nothing left open.
  // The videos keep every frame: an encoder a whole queue behind holds up the window (counted;
  // `info.live`, a camera: a deeper queue, see VideoSink). `before_encode` (tests): both videos'
  // encoder hook (AsyncFrameWriter).
  // `extra_columns`: the CSV's columns after the tracking ones (a hook's: LiveOptions).
  LiveRecording(const std::string& base, const TrackingConfig& config, const RunInfo& info,
                const RecordingOrigin& origin, FrameDrawer draw,
                std::function<void(int64_t index)> before_encode = {},
                const std::vector<CsvColumn>& extra_columns = {});
  ~LiveRecording() override;  // Closes every file, if end() has not.

  // Starts the files for frames of the size given at construction (`info` is the run's: the
  // recording keeps its own, from its config).
  void begin(const RunInfo& info) override;
  // Every processed frame, in order. Throws InputError (a full disk).
  void consume(const Frame& frame, const FrameResult& result) override;
  // Closes every file (end() of each sink).
  void end(const RunSummary& summary) override;
  // A live edit of the session made after the last frame consumed (at least one frame has
  // been): kept in the recording's config, which is written again at once (the .yaml on disk is
  // always whole), so re-tracking the raw video makes the same edit after the same frame. A
  // respecified template's pixels go beside it as <prefix>.<n>.<marker>.png. Throws InputError
  // (an unwritable file).
  void log(ConfigChange change);

  const std::string& prefix() const { return prefix_; }
  int64_t frames() const { return frames_; }
  // For the run's summary: capture -> CSV row per recorded frame (CsvSink::row_latencies_ms),
  // and the frames at which the window waited for a video's encoder (its queue was full).
  const std::vector<double>& row_latencies_ms() const { return csv_->row_latencies_ms(); }
  int64_t encoder_waits() const { return raw_->waited_frames() + annotated_->waited_frames(); }

 private:
  std::string prefix_;
  RunInfo info_;  // The recording's own: its markers, metric, frame size and rate.
  bool begun_ = false, ended_ = false;
  TrackingConfig saved_;  // The .yaml: the starting config, origin and the edits so far.
  std::vector<std::unique_ptr<FrameSink>> sinks_;
  CsvSink* csv_;         // In sinks_.
  VideoSink* raw_;       // In sinks_.
  VideoSink* annotated_; // In sinks_.
  int64_t frames_ = 0;
};

// What the session runs from a recording's first frame on, so that `track` on the raw video
// builds every tracker as the window does: each marker found on the frame on screen starts from
// `boxes[i]` around it (the colour tracker's search box; a template cut there on frame 0), the
// others as configured. `boxes` in config order (absent: the marker is not found now).
TrackingConfig RecordingStartConfig(const TrackingConfig& config,
                                    const std::vector<std::optional<cv::Rect>>& boxes);

// Writes `config` (what the window runs) to `path` for `softsight track`: templates held as pixels
// (selected live, or read from a file) go beside it as `<path stem>.<marker>.png`, named by the
// config with the rect and frame they were selected on. Throws InputError naming the file.
void SaveLiveConfig(const TrackingConfig& config, const std::string& path);

}  // namespace softsight
