// Internal to gui (and the tests). What the live window's run measured, gathered frame by frame
// and from each recording as it closes, for the end summary (LiveRunSummary, live_window.h).
#pragma once

#include <cstdint>
#include <vector>

#include "gui/live_recording.h"
#include "softsight/core/types.h"
#include "softsight/gui/live_window.h"

namespace softsight {

class LiveRunStats {
 public:
  // Every tracked frame's result.
  void add_result(const FrameResult& result);
  // A recording about to close (or still open at the end): its rows' latencies and drops.
  void add_recording(const LiveRecording& recording);

  // The summary so far; `open` (may be null): a recording not closed yet, counted as well.
  LiveRunSummary summary(int64_t dropped_by_source, const LiveRecording* open) const;

 private:
  std::vector<double> result_ms_;  // Grows geometrically: one double per frame.
  std::vector<double> row_ms_;
  int64_t recorded_ = 0, encoder_waits_ = 0;
};

}  // namespace softsight
