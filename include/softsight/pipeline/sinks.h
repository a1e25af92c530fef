// The sinks every command shares: the per-frame CSV and the videos (raw recording, annotated).
// The progress bar and the controller are sinks of the program (src/app); the live window's
// view is a sink of the GUI.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "softsight/config/config.h"
#include "softsight/io/csv_columns.h"
#include "softsight/io/csv_writer.h"
#include "softsight/io/frame_writer.h"
#include "softsight/pipeline/sink.h"

namespace softsight {

// The tracking columns of a run of `config` (io/csv_columns.h): its markers, its chain's inner
// angles, the _mm twins when it has a metric model, then `extra` before proc_ms.
CsvColumnTable TrackingColumns(const TrackingConfig& config,
                               const std::vector<CsvColumn>& extra = {});

// One CSV row per processed frame, with the columns of `columns` (TrackingColumns for the
// session's markers, plus the caller's extra columns by name). The file and its header are
// written in the constructor, so an unwritable path fails before the run; rows are flushed whole
// as they are written.
class CsvSink : public FrameSink {
 public:
  CsvSink(const std::string& path, CsvColumnTable columns);
  void consume(const Frame& frame, const FrameResult& result) override;

  const std::string& path() const { return writer_.path(); }

 private:
  CsvWriter writer_;
};

// Draws the result on a copy of the frame (the overlay lives in gui: the caller passes it).
using FrameDrawer = std::function<void(cv::Mat& canvas, const FrameResult& result)>;

// Every processed frame to a video or image pattern: as read (`draw` empty: the raw recording,
// lossless by default, which `track` reproduces row for row), or with `draw` applied (the
// annotated video). The video's rate is options.fps, or the source's when that is absent.
class VideoSink : public FrameSink {
 public:
  // Checks the path and codec at once (FrameWriter). `fps` absent: the source's, else 30.
  VideoSink(std::string path, std::string codec, std::optional<double> fps, FrameDrawer draw = {});
  void begin(const RunInfo& info) override;
  void consume(const Frame& frame, const FrameResult& result) override;
  void end(const RunSummary& summary) override;

  const FrameWriter& writer() const { return *writer_; }

 private:
  FrameWriterOptions options_;
  std::optional<double> fps_;
  FrameDrawer draw_;
  std::unique_ptr<FrameWriter> writer_;
  cv::Mat canvas_;  // Reused: no allocation per frame.
};

}  // namespace softsight
