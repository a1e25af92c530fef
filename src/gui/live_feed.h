// Internal to gui (and the tests). Feeds the live controller from a frame source, one frame per
// step, and couples the source's pacing to the window's pause: while the controller is paused no
// frame is read and a paced file (PacedFrameSource) stops its clock, so the video neither runs
// on behind the still frame nor jumps ahead on resume. A file never drops a frame; a camera
// (NewestFrameSource) drops stale ones and the controller shows how many. Window-free, so tests
// drive it with a fake clock.
//
// With a SeekableSource under the pacing, the feed also carries out the controller's transport
// requests (step, seek, start, end) and its loop; a frame reached by a jump is handed over as
// FrameOrder::kJump, and the paced clock restarts at it (no burst to catch up, no wait).
#pragma once

#include <cstdint>

#include "gui/seekable_source.h"
#include "softsight/core/types.h"
#include "gui/live_controller.h"
#include "softsight/io/frame_source.h"
#include "io/paced_source.h"

namespace softsight {

class LiveFeed {
 public:
  // `source` must outlive the feed. A PacedFrameSource is paused and resumed with the controller.
  // `seekable`: the source under `source`'s pacing (or `source` itself) when it can seek; null
  // for cameras, whose transport keys are answered with a message.
  explicit LiveFeed(FrameSource& source, SeekableSource* seekable = nullptr);

  // Carries out a pending transport request, or reads and feeds the next frame unless the
  // controller is paused or the source has ended (or, looping, feeds the first frame again).
  // Returns true when a frame was fed. Calls controller.on_end_of_input() at each end: reading
  // past the last frame, or showing it by End or a seek beyond it.
  // An InputError from the source (a frame that does not decode) reaches the caller.
  bool step(LiveController& controller);

  bool ended() const { return ended_; }

 private:
  bool carry_out(const PlaybackRequest& request, LiveController& controller);
  // Reads the frame at `position` at once (the paced clock restarts at it) and feeds it.
  bool jump_to(int64_t position, LiveController& controller);
  bool read(LiveController& controller, FrameOrder order);
  void reached_end(LiveController& controller);

  FrameSource& source_;
  PacedFrameSource* paced_;   // &source_ when it is paced, else null.
  SeekableSource* seekable_;  // Null: no transport.
  Frame frame_;               // Reused: no allocation per frame.
  bool ended_ = false;
  int64_t shown_ = -1;  // Position (in seekable_) of the frame on screen.
};

}  // namespace softsight
