// What one run of the pipeline did, in the style of Ceres' Solver::Summary: counts, per-marker
// found rates, timings, the frames the source dropped and why the run stopped. RunPipeline fills
// it; every command prints BriefReport() (one line) or FullReport() (a few lines) at its end.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "softsight/pipeline/status_summary.h"

namespace softsight {

enum class StopReason {
  kEndOfInput,     // The source had no more frames.
  kMaxFrames,      // RunOptions::max_frames frames were processed.
  kStopRequested,  // RunOptions::stop_requested said so (Ctrl-C, a window closed, a controller).
  kError,          // An InputError ended the run: RunSummary::error holds its message.
};

// "end of input", "max frames reached", "stop requested", "error".
const char* StopReasonName(StopReason reason);

struct MarkerRunSummary {
  std::string name{};
  int64_t found = 0;  // Frames where the marker was reported found.
};

struct RunSummary {
  std::string source{};                // FrameSource::description().
  int64_t frames = 0;                  // Frames processed (each one reached every sink).
  // Frames the source skipped because the pipeline was slower than it (a live camera: newest
  // frame wins). Always 0 for files, image sequences and rendered scenes.
  int64_t dropped = 0;
  std::optional<int64_t> first_index{};  // Source indices of the first and last processed frame.
  std::optional<int64_t> last_index{};
  std::vector<MarkerRunSummary> markers{};  // In config order.
  MarkerStatusSummary statuses{};      // Why and when each marker was not found.
  int64_t measured = 0;                // Frames with an angle.
  double proc_ms_median = 0.0;         // FrameResult::proc_ms over the processed frames.
  double proc_ms_p99 = 0.0;
  // Latency per frame from its capture (Frame::captured): to its result, and to the moment every
  // sink had it (the CSV row written, the controller's command sent, the window drawn).
  double latency_result_ms_median = 0.0;
  double latency_result_ms_p99 = 0.0;
  double latency_done_ms_median = 0.0;
  double latency_done_ms_p99 = 0.0;
  // To the CSV row written (CsvSink::row_latencies_ms), when the command that owns the CSV
  // filled it in; absent: not reported.
  std::optional<double> latency_row_ms_median{};
  std::optional<double> latency_row_ms_p99{};
  double wall_s = 0.0;                 // Whole run, reading and sinks included.
  StopReason stop_reason = StopReason::kEndOfInput;
  // With kStopRequested, who asked, when the caller knows: "stopped by SIGTERM".
  std::string stop_detail{};
  std::string error{};                 // With kError: the InputError's message.
  // What the source says about its input (FrameSource::note), e.g. gaps in a sequence.
  std::vector<std::string> notes{};

  // Fraction of processed frames in which marker `i` was found (0 without frames).
  double found_rate(size_t i) const;
  // Why it stopped, as the summary says it: stop_detail, else StopReasonName(stop_reason).
  std::string stop_text() const;
  // Whether the run ended without an error.
  bool ok() const { return stop_reason != StopReason::kError; }

  // "300 frames (end of input), found: red 100.0 %, blue 99.7 %, green 100.0 %, 0.41 ms/frame"
  std::string BriefReport() const;
  // Source, frames and drops, one line per marker, why and when markers were not found
  // (MarkerStatusSummary::lines), measured frames, timings, why it stopped.
  std::string FullReport() const;
};

// Median and 99th percentile of per-frame times (0 when empty); sorts `times_ms`.
void SummariseTimes(std::vector<double>& times_ms, double* median_ms, double* p99_ms);

}  // namespace softsight
