// The sinks every command shares: the per-frame CSV and the videos (raw recording, annotated).
// The progress bar and the controller are sinks of the `softsight` program; the live window's
// view is a sink of the GUI.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "softsight/config/config.h"
#include "softsight/io/csv_columns.h"
#include "softsight/io/async_frame_writer.h"
#include "softsight/io/csv_writer.h"
#include "softsight/io/frame_writer.h"
#include "softsight/pipeline/sink.h"

namespace softsight {

// The tracking columns of a run of `config` (io/csv_columns.h): its markers, its chain's inner
// angles, the _mm twins when it has a metric model, then `extra` before proc_ms.
CsvColumnTable TrackingColumns(const TrackingConfig& config,
                               const std::vector<CsvColumn>& extra = {});

// One CSV row per processed frame (or pair), with the columns of `columns` (one view:
// TrackingColumns for the session's markers, plus the caller's extra columns by name; a pair:
// StereoColumns). The file and its header are written in the constructor, so an unwritable path
// fails before the run; rows are flushed whole as they are written. `Row` is the step's result
// (FrameResult, StereoFrameResult); it carries its capture time (`captured`).
template <typename Input, typename Row>
class BasicCsvSink : public BasicFrameSink<Input, Row> {
 public:
  BasicCsvSink(const std::string& path, BasicCsvColumnTable<Row> columns);
  void begin(const RunInfo& info) override;
  void consume(const Input& input, const Row& row) override;

  const std::string& path() const { return writer_.path(); }
  // The latency from each frame's capture to its row written (the write returned), ms, in row
  // order: for the summary (SummariseTimes). The CSV's latency_row_ms column is taken just
  // before the write.
  const std::vector<double>& row_latencies_ms() const { return row_latency_ms_; }
  // The summary's latency_row_ms_median / _p99 (when any row carried a capture time).
  void report(RunSummary& summary) const override;
  bool uses_image() const override { return false; }

 private:
  BasicCsvWriter<Row> writer_;
  std::vector<double> row_latency_ms_;  // Reserved in begin() for a file's frame count.
};

// One view's CSV (a pair's: BasicCsvSink<FramePair, StereoFrameResult>).
using CsvSink = BasicCsvSink<Frame, FrameResult>;

// Draws the result on a copy of the frame (the overlay lives in gui: the caller passes it).
using FrameDrawer = std::function<void(cv::Mat& canvas, const FrameResult& result)>;

// Every processed frame to a video or image pattern: as read (`draw` empty: the raw recording,
// lossless by default, which `track` reproduces row for row), or with `draw` applied (the
// annotated video). The video's rate is options.fps, or the source's when that is absent.
// Encoding runs on its own thread (AsyncFrameWriter), behind a queue of frames, so the pipeline
// does not wait for it. The video keeps every frame it is given, so a recording and its CSV hold
// the same frames: an encoder that falls behind by a full queue holds up the pipeline (counted:
// waited_frames()), and a camera meanwhile drops its stale frames as the source does, counted in
// the run's summary. For a camera (RunInfo::live) the queue holds about two seconds of frames
// (at most 256 MB), so only an encoder that stays slower than the camera holds it up.
class VideoSink : public FrameSink {
 public:
  // Checks the path and codec at once (FrameWriter). `fps` absent: the source's, else 30.
  // `before_encode` (tests): AsyncFrameWriter's hook on the encoding thread.
  // A video is written beside its output and renamed into place when whole (FrameWriter), its
  // temporary file locked (flock) meanwhile: a second writer of it is refused with InputError
  // before it truncates anything.
  VideoSink(std::string path, std::string codec, std::optional<double> fps, FrameDrawer draw = {},
            std::function<void(int64_t index)> before_encode = {});
  ~VideoSink() override;
  VideoSink(const VideoSink&) = delete;
  VideoSink& operator=(const VideoSink&) = delete;
  void begin(const RunInfo& info) override;
  void consume(const Frame& frame, const FrameResult& result) override;
  // Finishes the video. An encoder error met while finishing cannot be thrown from here: see
  // error().
  void end(const RunSummary& summary) override;

  const std::string& path() const { return options_.path; }
  int64_t written_frames() const { return writer_->queued(); }  // Once end() has run.
  // Frames for which the pipeline had to wait for the encoder (its queue was full).
  int64_t waited_frames() const { return writer_->waited(); }
  // The encoder's error ends an ok run as an error; a note says that every frame was recorded
  // and whether the encoder held up the run (always for a camera's run, else when it did).
  void report(RunSummary& summary) const override;
  // The encoder's error that end() met (a full disk while the last frames were written).
  const std::optional<std::string>& error() const { return error_; }

 private:
  FrameWriterOptions options_;
  std::optional<double> fps_;
  FrameDrawer draw_;
  std::function<void(int64_t)> before_encode_;
  size_t capacity_;
  std::unique_ptr<AsyncFrameWriter> writer_;
  std::optional<std::string> error_;
  bool live_ = false;  // RunInfo::live: a camera's run.
};

}  // namespace softsight
