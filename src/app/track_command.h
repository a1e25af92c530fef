// `softsight track`: frames from a file -> trackers -> measurements -> CSV (+ annotated video).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "softsight/core/types.h"
#include "softsight/io/config.h"
#include "softsight/io/frame_source.h"

namespace softsight {

struct TrackOptions {
  std::string config_file;
  FrameSourceSpec source;
  std::string csv_file;
  std::optional<std::string> method;         // Overrides every marker's method.
  // Overrides every template marker's mode: true matches BGR, false gray (--colour / --gray).
  std::optional<bool> template_colour;
  std::optional<std::string> annotated_file; // Annotated video (overlay drawn on each frame).
  std::optional<int64_t> max_frames;
  bool quiet = false;                        // No progress bar, no summary.
};

// What a run did, printed at its end (and returned to tests).
struct TrackSummary {
  int64_t frames = 0;
  std::vector<std::string> marker_names;
  std::vector<int64_t> found;                // Per marker, frames where it was found.
  int64_t measured = 0;                      // Frames with an angle.
  double proc_ms_median = 0.0;
  double proc_ms_p99 = 0.0;
  double wall_s = 0.0;
  std::string stop_reason;                   // "end of input", "--max-frames reached", ...
};

// Runs the whole job. Throws InputError for bad input; every CSV row written before the error
// stays intact. `summary_out` (optional) receives the summary even when an error is thrown.
TrackSummary RunTrack(const TrackOptions& options, TrackSummary* summary_out = nullptr);

// Summary lines for a person.
std::string FormatSummary(const TrackSummary& summary);

// Per-frame statistics: median and 99th percentile of the processing times.
void SummariseTimes(std::vector<double> proc_ms, TrackSummary* summary);

}  // namespace softsight
