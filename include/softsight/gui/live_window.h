// The thin highgui adapter around LiveController: one window, its mouse callback, six trackbars
// and the key loop. Everything it decides is the controller's; this file only moves events in
// and images out.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "softsight/gui/live_controller.h"
#include "softsight/io/frame_source.h"

namespace softsight {

class SeekableSource;  // gui/seekable_source.h: a file the transport keys can seek in.

// True when a window can be opened (an X display answers, or a Wayland socket is named);
// otherwise false with `why` saying what is missing.
bool HaveDisplay(std::string* why);

struct LiveWindowOptions {
  std::string title = "softsight live";
  bool trackbars = true;  // The six HSV trackbars of the active marker, in a window of their own.
  std::string trackbar_title = "HSV ranges (softsight)";
  // The screen the window must fit (the canvas is scaled down to it); empty: the X screen's.
  cv::Size screen_px;
};

// Runs the window until the controller asks to quit or the window is closed. Frames come from
// `source` through a LiveFeed: a PacedFrameSource for a file (every frame, at its rate, paused
// with the window), a NewestFrameSource for a camera (stale frames dropped and counted). On
// stdout: each message the window shows, as "live: <message>" (after the key or click that caused
// it has been handled), and "end of input" once the last frame of a file source is on screen.
// `seekable`: the source under `source`'s pacing when it is a file, image sequence or rendered
// scene (the transport keys step and seek in it); null for a camera.
// Returns the exit code (0).
int RunLiveWindow(LiveController& controller, FrameSource& source,
                  const LiveWindowOptions& options = {}, SeekableSource* seekable = nullptr);

}  // namespace softsight
