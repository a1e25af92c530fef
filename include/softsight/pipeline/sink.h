// Where a step's result goes: the CSV table, an annotated or raw video, a progress bar, the
// controller, the stream, the live or stereo window. A sink only consumes; the data flows one way:
//   source -> session (the step) -> result -> every sink, in the order given.
// One view's run hands each Frame and its FrameResult to FrameSinks; two views' run each
// FramePair and its StereoFrameResult to PairSinks (pipeline/stereo_session.h). Both are one
// BasicFrameSink over what the step consumes and produces, so a sink that needs only the row
// (the CSV, the stream) is written once for both. Sinks are called from the thread that runs
// RunPipeline, one frame (or pair) at a time.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"
#include "softsight/pipeline/summary.h"

namespace softsight {

// What a sink learns before the first frame.
struct RunInfo {
  std::string source{};                  // FrameSource::description().
  cv::Size frame_size{};                 // Of the first frame; empty when the source had none.
  std::optional<double> fps{};           // The source's nominal rate, when known.
  std::optional<int64_t> frame_count{};  // Frames the run will process when known (the source's
                                        // count, capped by RunOptions::max_frames).
  bool live = false;                    // A camera (frames may be dropped, no known end).
  std::vector<std::string> marker_names{};  // In config order, as in FrameResult::markers.
  bool metric = false;                  // The measurement has _mm twins (a metric model is set).
};

// `Input`: what the step consumed (Frame, FramePair); `Result`: what it produced (FrameResult,
// StereoFrameResult).
template <typename Input, typename Result>
class BasicFrameSink {
 public:
  virtual ~BasicFrameSink() = default;

  // Once, after the first frame has been read and before it is consumed (when the source is
  // empty: once, with an empty frame_size, before end()). May throw InputError (a file that
  // cannot be opened): the run then stops with StopReason::kError.
  virtual void begin(const RunInfo& info) { (void)info; }
  // Every processed frame, in source order. `frame` is the image as read (no overlay).
  // May throw InputError (a full disk): the run stops with StopReason::kError.
  virtual void consume(const Input& frame, const Result& result) = 0;
  // Once at the end of every run that called begin(), whatever the reason, with the summary.
  // Must not throw.
  virtual void end(const RunSummary& summary) { (void)summary; }
  // After every sink's end(), in sink order: adds to the run's summary what only this sink knows
  // (the CSV's capture-to-row latency, a video encoder's error or waits), so every caller of
  // RunPipeline (track, control, Python) reports the same figures without patching them in.
  // Must not throw.
  virtual void report(RunSummary& summary) const { (void)summary; }
  // Whether consume() looks at the input's image (a video, a hook, a window do; the CSV, the
  // progress bar and the stream do not). A run that holds frames back (a predicted video's
  // key-frame groups, RunOptions::check_key_frame_groups) keeps their images only when one of its
  // sinks does: a 1080p group of 250 frames is 1.5 GB of pixels and 250 rows of a few kB.
  virtual bool uses_image() const { return true; }
};

// One view's sink: every Frame as read and its FrameResult.
using FrameSink = BasicFrameSink<Frame, FrameResult>;

}  // namespace softsight
