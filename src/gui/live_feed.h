// Internal to gui (and the tests). Feeds the live controller from a frame source, one frame per
// step, and couples the source's pacing to the window's pause: while the controller is paused no
// frame is read and a paced file (PacedFrameSource) stops its clock, so the video neither runs
// on behind the still frame nor jumps ahead on resume. A file never drops a frame; a camera
// (NewestFrameSource) drops stale ones and the controller shows how many. Window-free, so tests
// drive it with a fake clock.
#pragma once

#include <cstdint>

#include "softsight/core/types.h"
#include "softsight/gui/live_controller.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/paced_source.h"

namespace softsight {

class LiveFeed {
 public:
  // `source` must outlive the feed. A PacedFrameSource is paused and resumed with the controller.
  explicit LiveFeed(FrameSource& source);

  // Reads and feeds the next frame unless the controller is paused or the source has ended.
  // Returns true when a frame was fed. Calls controller.on_end_of_input() once at the end.
  // An InputError from the source (a frame that does not decode) reaches the caller.
  bool step(LiveController& controller);

  bool ended() const { return ended_; }
  int64_t frames_fed() const { return fed_; }

 private:
  FrameSource& source_;
  PacedFrameSource* paced_;  // &source_ when it is paced, else null.
  Frame frame_;              // Reused: no allocation per frame.
  bool ended_ = false;
  int64_t fed_ = 0;
};

}  // namespace softsight
