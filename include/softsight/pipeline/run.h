// The one run loop: frames from a source, through the session, to every sink, until the source
// ends, max_frames are done, a stop is requested or an InputError occurs; then one summary.
// `track`, `control`, `demo`, `evaluate` and `live` all run through it.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "softsight/io/frame_source.h"
#include "softsight/pipeline/sink.h"
#include "softsight/pipeline/summary.h"
#include "softsight/pipeline/tracking_session.h"

namespace softsight {

struct RunOptions {
  // Stop after this many processed frames (absent: until the source ends). Must be >= 0.
  std::optional<int64_t> max_frames;
  // Polled before each frame is read; true ends the run cleanly with kStopRequested (every sink
  // still gets end()). Empty: never. Called from the running thread: make it cheap (a flag).
  std::function<bool()> stop_requested;
};

// Runs the pipeline. Pacing is the source's business (a camera decorator drops stale frames, a
// file never does); every frame read is processed and reaches every sink in order.
// An InputError from the source, the session or a sink does not escape: it ends the run with
// StopReason::kError and its message in RunSummary::error (the caller decides how to report it,
// typically by throwing it again after printing the summary). Any other exception reaches the
// caller after every begun sink's end(). Before the first frame is
// processed it checks that a session needing colour is not fed a grayscale video.
RunSummary RunPipeline(FrameSource& source, TrackingSession& session,
                       const std::vector<FrameSink*>& sinks, const RunOptions& options = {});

// What RunPipeline tells its sinks in begin() (frame_size left empty: the first frame's). For a
// sink that joins a run late (a recording started in the live window), so it is told the same.
RunInfo DescribeRun(const FrameSource& source, const TrackingSession& session,
                    const RunOptions& options = {});

}  // namespace softsight
