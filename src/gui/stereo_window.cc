#include "gui/stereo_window.h"

#include <algorithm>
#include <iostream>
#include <opencv2/highgui.hpp>

#include "gui/live_layout.h"
#include "gui/live_window.h"  // ScreenSize

namespace softsight {

std::string StereoWindowKeys::press(int key) {
  if (key < 0) return "";
  const int code = key & 0xFFFF;
  if (code == 'q' || code == 'Q' || code == 27) {
    quit = true;
    return "stop";
  }
  if (code == ' ') {
    paused = !paused;
    step = false;
    return paused ? "paused" : "resumed";
  }
  if (code == '.' && paused) {
    step = true;
    return "step";
  }
  return "";
}

StereoWindow::StereoWindow(StereoWindowOptions options, const TrackingConfig& left,
                           const TrackingConfig& right)
    : options_(std::move(options)), view_([&] {
        StereoViewOptions view;
        view.chart = options_.chart;
        const cv::Size screen = options_.screen_px.area() > 0 ? options_.screen_px : ScreenSize();
        if (screen.area() > 0) view.max_canvas = MaxCanvasForScreen(screen);
        return view;
      }()) {
  view_.set_configs(left, right);
}

StereoWindow::~StereoWindow() {
  if (open_) {
    cv::destroyWindow(options_.title);
    cv::waitKey(1);
  }
}

void StereoWindow::show_and_poll(int wait_ms) {
  if (!open_) {
    // GUI_NORMAL: no toolbar or status bar, so image pixels are canvas pixels.
    cv::namedWindow(options_.title, cv::WINDOW_AUTOSIZE | cv::WINDOW_GUI_NORMAL);
    cv::moveWindow(options_.title, 0, 0);
    open_ = true;
  }
  cv::imshow(options_.title, view_.canvas());
  const std::string said = keys_.press(cv::waitKeyEx(std::max(1, wait_ms)));
  // Said on stdout too, with the pair on screen (scripts and the test under Xvfb read it).
  if (!said.empty()) std::cout << "window: " << said << " at frame " << shown_frame_ << std::endl;
  if (!keys_.quit && cv::getWindowProperty(options_.title, cv::WND_PROP_VISIBLE) < 1) {
    keys_.quit = true;  // Closed by the user.
    std::cout << "window: closed" << std::endl;
  }
}

void StereoWindow::consume(const FramePair& pair, const StereoFrameResult& result) {
  const FrameResult& left = *result.left_view;
  const FrameResult& right = *result.right_view;
  view_.add(result);
  shown_frame_ = result.frame_index;
  view_.compose(pair, result, left, right, keys_.paused ? "PAUSED (space: play, .: next pair)" : "");
  int wait_ms = 1;
  if (options_.pace && !keys_.paused) {
    const Clock::time_point now = Clock::now();
    if (!wall_start_ || result.time_s < media_start_s_) {
      wall_start_ = now;
      media_start_s_ = result.time_s;
    }
    const auto due = *wall_start_ + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(result.time_s - media_start_s_));
    wait_ms = static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(due - now).count());
  }
  show_and_poll(wait_ms);
  // Paused: the run waits here, the window answering keys, until resumed, stepped or stopped.
  keys_.step = false;
  bool was_paused = false;
  while (keys_.paused && !keys_.step && !keys_.quit) {
    if (!was_paused) {
      view_.compose(pair, result, left, right, "PAUSED (space: play, .: next pair)");
      was_paused = true;
    }
    show_and_poll(30);
  }
  // The pace starts again from the next pair after a pause.
  if (was_paused) wall_start_.reset();
}

}  // namespace softsight
