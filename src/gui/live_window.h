// The live window (`softsight live`) for library users: a camera or a file, tracked and measured
// with the overlay, strip chart, mouse recalibration, HSV picking, recording and config saving.
// Everything the window decides lives in src/gui (the controller, its view and its recording);
// this header is the whole of what a program calls.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "softsight/config/config.h"
#include "gui/live_options.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/summary.h"

namespace softsight {

// True when a window can be opened (an X display answers, or a Wayland socket is named);
// otherwise false with `why` saying what is missing.
bool HaveDisplay(std::string* why);
// The default X screen's size in pixels (XWayland too); empty when no X server answers.
cv::Size ScreenSize();

struct LiveWindowOptions {
  std::string title = "softsight live";
  bool trackbars = true;  // The six HSV trackbars of the active marker, in a window of their own.
  std::string trackbar_title = "HSV ranges (softsight)";
  // The screen the window must fit (the canvas is scaled down to it); empty: the X screen's.
  cv::Size screen_px;
  // A file or image sequence plays at its own frame rate and pauses with the window (default);
  // false: as fast as it decodes (never dropping a frame either way).
  bool pace_files = true;
};

// Opens the same input again from its first frame: how the transport keys (step back, seek,
// loop) reach frames no longer held in memory. Empty for a camera.
using FrameSourceOpener = std::function<std::unique_ptr<FrameSource>()>;

// What a run of the window measured, for its end summary (Report(): `softsight live` prints it).
struct LiveRunSummary {
  // The run as every command reports it (PipelineRun): frames tracked (played, stepped to or
  // sought to), each marker's found rate and why it was not found, the frames the source dropped
  // (a camera: newest frame wins), processing time, the latency from capture to the result and
  // (when something was recorded) to the recordings' CSV rows, and a note per recording.
  RunSummary run;
  // The recordings together: frames recorded (CSV rows; both videos hold each one), and how
  // often the window waited for a video's encoder because its queue was full (a camera's frames
  // skipped meanwhile are the source's drops).
  int64_t recorded_frames = 0;
  int64_t encoder_waits = 0;

  std::string Report() const { return run.FullReport(); }
};

struct LiveRunResult {
  int exit_code = 0;
  // Where the last recording's files went (prefix without extension); empty if none.
  std::string last_recording;
  LiveRunSummary summary;
};

// Runs the window on `source` until `q`, Escape or the window is closed. A camera (is_live())
// keeps only its newest frame (drops are counted and shown); a file plays every frame (paced
// per `window.pace_files`) and, with `reopen`, can be stepped and seeked. On stdout: each message
// the window shows, as "live: <message>", and "end of input" once a file's last frame is on
// screen. `options.record_fps` defaults to the source's rate. Throws InputError for a bad config
// or options, before any window opens.
LiveRunResult RunLiveWindow(const TrackingConfig& config, std::unique_ptr<FrameSource> source,
                            LiveOptions options, const LiveWindowOptions& window = {},
                            FrameSourceOpener reopen = {});

}  // namespace softsight
