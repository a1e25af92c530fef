#include "gui/live_feed.h"

namespace softsight {

LiveFeed::LiveFeed(FrameSource& source)
    : source_(source), paced_(dynamic_cast<PacedFrameSource*>(&source)) {}

bool LiveFeed::step(LiveController& controller) {
  if (paced_ && controller.paused() != paced_->paused()) {
    // The clock stops with the picture; resume() restarts it one frame period after the last
    // frame shown, so there is no gap and no burst.
    controller.paused() ? paced_->pause() : paced_->resume();
  }
  if (controller.paused() || ended_) return false;
  if (!source_.read(frame_)) {
    ended_ = true;
    controller.on_end_of_input();
    return false;
  }
  const SteadyClock::time_point captured = SteadyClock::now();
  controller.set_dropped_frames(source_.dropped_frames());
  controller.on_frame(frame_, captured);
  ++fed_;
  return true;
}

}  // namespace softsight
