// The one run: frames from a source, through the session, to every sink, until the source ends,
// max_frames are done, a stop is requested or an InputError occurs; then one summary.
// `track`, `control`, `demo` and `evaluate` run through RunPipeline; `live` through PipelineRun,
// the same work per frame and the same summary, in the window's own loop.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "softsight/io/frame_source.h"
#include "softsight/pipeline/sink.h"
#include "softsight/pipeline/summary.h"
#include "softsight/pipeline/tracking_session.h"

namespace softsight {

class KeyFrameGroups;      // One view's key-frame check (pipeline/key_frame_groups.h),
class PairKeyFrameGroups;  // and a pair's: each view's groups, a pair on once both are checked.

struct RunOptions {
  // Stop after this many processed frames (absent: until the source ends). Must be >= 0.
  std::optional<int64_t> max_frames{};
  // Polled before each frame is read; true ends the run cleanly with kStopRequested (every sink
  // still gets end()). Empty: never. Called from the running thread: make it cheap (a flag).
  std::function<bool()> stop_requested{};
  // A video that predicts frames (MPEG-4, H.264): each group of frames reaches the sinks only
  // after its next key frame was tracked, so that a marker the decoder's silent damage moved is
  // reported implausible instead of found (the library checks the group inside; frames of cameras,
  // image sequences and intra-only videos are not delayed). Off for a loop that acts on each
  // frame as it comes (`control`): it cannot wait for the next key frame.
  bool check_key_frame_groups = true;
  // Why the run stopped in the words of the command that runs it ("duration reached", "stopped
  // by SIGINT"; empty: StopReasonName's), asked once as it ends and kept in
  // RunSummary::stop_detail before the sinks' end(): the stream's end record and the printed
  // summary then say the same. Empty: none.
  std::function<std::string(StopReason)> describe_stop{};
};

// What RunPipeline tells its sinks in begin() (frame_size left empty: the first frame's). For a
// sink that joins a run late (a recording started in the live window), so it is told the same.
// Two views: pipeline/stereo_session.h.
RunInfo DescribeRun(const FrameSource& source, const TrackingSession& session,
                    const RunOptions& options = {});

// One run, step by step: RunPipeline's work per step and its summary, for a caller whose own
// loop decides when a frame comes (the live window plays, pauses, steps and seeks as the user
// says, and a recording joins and leaves the run). RunPipeline is this class driven by a source.
// `Session` is the step: a TrackingSession (one view: a Frame in, a FrameResult out) or a
// StereoSession (two views: a FramePair in, a StereoFrameResult out; pipeline/stereo_session.h).
// The run, its sinks, its summary and its key-frame check are the same for both; only what a
// result counts in the summary depends on the step.
template <typename Session>
class BasicPipelineRun {
 public:
  using Input = typename Session::Input;
  using Result = typename Session::Result;
  using Sink = BasicFrameSink<Input, Result>;

  // `info` as DescribeRun gives it (frame_size is set from the first frame). `sinks` begin at
  // the first frame and end in finish(). The session must outlive the run.
  BasicPipelineRun(Session& session, RunInfo info, std::vector<Sink*> sinks = {});
  ~BasicPipelineRun();
  BasicPipelineRun(const BasicPipelineRun&) = delete;
  BasicPipelineRun& operator=(const BasicPipelineRun&) = delete;
  // Before the first frame: the source the frames come from (its description, rate, whether it
  // is live, its frame count), for the sinks' begin() and the summary.
  template <typename Source>
  void describe_source(const Source& source) {
    describe(DescribeRun(source, session_, RunOptions{}));
  }

  // The input through the session and to every sink, counted in the summary. Its (first view's)
  // `captured` unset: stamped now. At the first input a session that needs colour refuses a
  // grayscale frame and the sinks begin. Throws InputError (from the session or a sink;
  // RunPipeline ends the run with it).
  const Result& process(Input& input);
  // A sink joining the run after it began (its owner has begun it: a live recording), and
  // leaving it (its owner ends it); leave() of a sink not in the run does nothing.
  void join(Sink& sink);
  void leave(Sink& sink);
  // From now on, hold a predicted video's frames until the next key frame shows whether the
  // decoder damaged them (RunOptions::check_key_frame_groups); process() still returns each
  // frame's result at once, the sinks get it when its group is checked. A pair goes on once
  // both its views' groups are checked (they need not end together), and a marker either
  // view's check did not believe is not found in 3D there.
  void check_key_frame_groups();
  const RunInfo& info() const { return info_; }
  int64_t frames() const { return processed_; }  // Processed so far (the sinks may lag).

  // The summary so far: frames, found counts, timings, the first and last source index. Why the
  // run stopped and the source's drops are finish()'s.
  RunSummary summary() const;
  // Ends the run (once): the summary with why it stopped, the source's drops and notes, and
  // `error` (kError); every sink begun gets end(summary). A run that stopped before its first
  // frame without an error still begins and ends its sinks.
  RunSummary finish(StopReason reason, int64_t dropped = 0, std::vector<std::string> notes = {},
                    std::string error = {});
  // RunOptions::describe_stop, for finish().
  void describe_stop_with(std::function<std::string(StopReason)> describe) {
    describe_stop_ = std::move(describe);
  }

 private:
  void describe(const RunInfo& described);
  void begin_sinks();
  // A result reaches the summary and the sinks.
  void deliver(const Input& input, const Result& result);

  Session& session_;
  RunInfo info_;
  std::vector<Sink*> sinks_;
  size_t begun_ = 0;  // sinks_[0, begun_) have begun.
  std::vector<Sink*> joined_;  // Begun and ended by their owners.
  bool needs_colour_;
  bool finished_ = false;
  std::function<std::string(StopReason)> describe_stop_;
  std::chrono::steady_clock::time_point start_;
  RunSummary summary_;  // Its frames: those the sinks have had.
  int64_t processed_ = 0;
  std::vector<double> proc_ms_, latency_result_ms_, latency_done_ms_;
  using KeyFrameCheck =
      std::conditional_t<std::is_same_v<Input, Frame>, KeyFrameGroups, PairKeyFrameGroups>;
  std::unique_ptr<KeyFrameCheck> key_frame_groups_;  // Set by check_key_frame_groups().
  std::function<void(const Input&, const Result&)> deliver_;
};

// One view's run (`track`, `control`, `live`, Python).
using PipelineRun = BasicPipelineRun<TrackingSession>;

// Runs the pipeline. Pacing is the source's business (a camera decorator drops stale frames, a
// file never does); every frame read is processed and reaches every sink in order.
// An InputError from the source, the session or a sink does not escape: it ends the run with
// StopReason::kError and its message in RunSummary::error (the caller decides how to report it,
// typically by throwing it again after printing the summary). Any other exception reaches the
// caller after every begun sink's end(). Before the first frame is
// processed it checks that a session needing colour is not fed a grayscale video.
RunSummary RunPipeline(FrameSource& source, TrackingSession& session,
                       const std::vector<FrameSink*>& sinks, const RunOptions& options = {});

// RunPipeline turned inside out, for a caller that pulls one result at a time (Python's
// softsight.frames and frames_stereo): the same reading, max_frames, stop request, grayscale
// check and key-frame check (a predicted video's results come out once their group is checked,
// so next() may read several frames before it returns one), without sinks. The source and the
// session must outlive the stream while it runs; once ended() the source is not read again (it
// may be closed). One view: RunStream; a pair (pipeline/stereo_session.h): StereoRunStream,
// whose results have no left_view / right_view (those are the session's, gone by then).
template <typename Source, typename Session>
class BasicRunStream {
 public:
  using Input = typename Session::Input;
  using Result = typename Session::Result;

  BasicRunStream(Source& source, Session& session, const RunOptions& options = {});
  ~BasicRunStream();
  BasicRunStream(const BasicRunStream&) = delete;
  BasicRunStream& operator=(const BasicRunStream&) = delete;

  // The next frame's result, in source order, or nothing once the run has ended. An InputError
  // (a frame that does not decode, an input without frames, a gray video for colour markers)
  // is thrown after every result before it has been returned; the run has ended then.
  std::optional<Result> next();
  bool ended() const { return ended_; }
  const RunInfo& info() const;
  int64_t returned() const { return returned_; }  // Results next() has returned.
  // The run's summary; complete (why it stopped, notes such as demoted marker-frames) once
  // ended() is true.
  const RunSummary& summary() const { return summary_; }

 private:
  class Queue;
  // Reads and processes until a result is queued or the run ends.
  void fill();
  void end(StopReason reason, std::string error);

  Source& source_;
  RunOptions options_;
  std::unique_ptr<Queue> queue_;
  std::unique_ptr<BasicPipelineRun<Session>> run_;
  Input input_;
  bool ended_ = false;
  int64_t returned_ = 0;
  RunSummary summary_;
};

using RunStream = BasicRunStream<FrameSource, TrackingSession>;

// Whether a run of `config` needs colour frames: a marker whose colour range accepts gray pixels
// (a gray-level range, white or black dots) is tracked on gray video as well; only the others
// make gray frames an error, said with GrayFrameProblem() ("colour tracking needs colour (...)").
bool NeedsColour(const TrackingConfig& config);
std::string GrayFrameProblem();
// The error of a run whose source (`source`: its description) ends before its first frame: a
// CSV of only a header, exit 0, would read as "tracked, nothing found". RunPipeline's, and
// that of a caller reading the source itself (softsight.frames in Python).
std::string NoFramesProblem(const std::string& source);

// What a run of `config` tells its sinks of the markers: their names, and whether measurements
// come in millimetres. DescribeRun adds the source.
RunInfo DescribeMarkers(const TrackingConfig& config);

}  // namespace softsight
