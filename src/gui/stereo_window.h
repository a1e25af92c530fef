// The stereo window (`softsight track-stereo --window`): a sink of the stereo run that shows
// each pair as it is tracked (gui/stereo_view.h draws it) while the run writes its CSV as
// without it. Keys: space pauses and resumes (the run waits in consume()), `.` shows one more
// pair while paused, q or Escape (or closing the window) asks the run to stop. Recorded inputs
// can be paced to their own frame rate. Internal to gui; only the live plugin links it (the
// GUI's libraries load with that plugin only).
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "gui/stereo_view.h"
#include "softsight/pipeline/stereo_session.h"

namespace softsight {

// What a key does to the run, apart from any window (tests press them).
struct StereoWindowKeys {
  bool paused = false;
  bool quit = false;
  bool step = false;  // Paused: show one more pair, then pause again.
  // A key as cv::waitKeyEx gives it (-1: none). Returns the message it is worth on stdout
  // ("paused", "resumed", "stop"), empty for a key that does nothing.
  std::string press(int key);
};

struct StereoWindowOptions {
  std::string title = "softsight track-stereo";
  StripChartOptions chart;
  // Recorded inputs: show each pair when it is due by its time_s (the video's own pace, from
  // the first pair shown or the end of a pause); false: as soon as it is tracked. Cameras: false
  // (their pairs come at their own rate).
  bool pace = true;
  cv::Size screen_px;  // The screen the window must fit; empty: the X screen's.
};

class StereoWindow : public PairSink {
 public:
  // `left`, `right`: each view's config (the markers each view's triangle joins).
  StereoWindow(StereoWindowOptions options, const TrackingConfig& left,
               const TrackingConfig& right);
  ~StereoWindow() override;  // Closes the window.
  StereoWindow(const StereoWindow&) = delete;
  StereoWindow& operator=(const StereoWindow&) = delete;

  // Draws the pair with each view's own tracking (StereoFrameResult::left_view / right_view).
  void consume(const FramePair& pair, const StereoFrameResult& result) override;
  // q, Escape or the window closed: the run should stop before the next pair.
  bool quit_requested() const { return keys_.quit; }

 private:
  // Shows the canvas and waits up to `wait_ms` for a key (at least 1 ms: the window's events).
  void show_and_poll(int wait_ms);

  using Clock = std::chrono::steady_clock;
  StereoWindowOptions options_;
  StereoView view_;
  StereoWindowKeys keys_;
  bool open_ = false;
  int64_t shown_frame_ = 0;  // The left frame of the pair on screen.
  // Pacing: the wall time at which the pair of time `media_start_s_` was shown.
  std::optional<Clock::time_point> wall_start_;
  double media_start_s_ = 0.0;
};

}  // namespace softsight
