#include "gui/live_feed.h"

#include <cmath>

namespace softsight {

LiveFeed::LiveFeed(FrameSource& source, SeekableSource* seekable)
    : source_(source), paced_(dynamic_cast<PacedFrameSource*>(&source)), seekable_(seekable) {}

bool LiveFeed::read(LiveController& controller, FrameOrder order) {
  frame_.captured = {};
  if (!source_.read(frame_)) return false;
  if (seekable_) {
    shown_ = seekable_->position() - 1;
    controller.set_source_position(shown_, seekable_->frame_count());
  }
  ended_ = false;
  // A camera's frame carries its capture time (NewestFrameSource's thread); a played file's
  // capture is the moment it is due and read. The recording's latency_*_ms columns count from it.
  if (frame_.captured == SteadyClock::time_point{}) frame_.captured = SteadyClock::now();
  const SteadyClock::time_point captured = frame_.captured;
  controller.set_dropped_frames(source_.dropped_frames());
  controller.on_frame(frame_, captured, order);
  return true;
}

bool LiveFeed::jump_to(int64_t position, LiveController& controller) {
  // Paused, the paced source returns the frame at once; resuming restarts its clock at that
  // frame, so playing on from here neither waits for the old schedule nor bursts to catch up.
  const bool was_paused = paced_ && paced_->paused();
  if (paced_) paced_->pause();
  seekable_->seek(position);
  bool got = read(controller, FrameOrder::kJump);
  if (!got && seekable_->seek_last()) {  // Past the end: the last frame, and the end.
    got = read(controller, FrameOrder::kJump);
    if (got) reached_end(controller);
  }
  if (paced_ && !was_paused) paced_->resume();
  return got;
}

void LiveFeed::reached_end(LiveController& controller) {
  // The last frame is on screen and nothing follows it: the end, at once (space then plays from
  // the start, as after playing to the end), unless looping wraps to the first frame.
  if (controller.loop()) return;
  ended_ = true;
  controller.on_end_of_input();
}

bool LiveFeed::carry_out(const PlaybackRequest& request, LiveController& controller) {
  using Kind = PlaybackRequest::Kind;
  if (!seekable_) {
    controller.report(source_.description() + " plays as it comes: no stepping or seeking");
    return false;
  }
  if (paced_ && controller.paused() != paced_->paused()) {
    controller.paused() ? paced_->pause() : paced_->resume();
  }
  switch (request.kind) {
    case Kind::kStepForward:
      if (read(controller, FrameOrder::kStep)) return true;
      ended_ = true;
      controller.on_end_of_input();
      return false;
    case Kind::kStepBack:
      if (shown_ <= 0) {
        controller.report("at the first frame");
        return false;
      }
      return jump_to(shown_ - 1, controller);
    case Kind::kSeekSeconds: {
      const double fps = source_.fps().value_or(30.0);
      const int64_t frames = std::llround(request.seconds * (fps > 0 ? fps : 30.0));
      return jump_to(std::max<int64_t>(0, shown_ + frames), controller);
    }
    case Kind::kSeekTo:
      return jump_to(request.position, controller);
    case Kind::kStart:
      return jump_to(0, controller);
    case Kind::kEnd: {
      const bool was_paused = paced_ && paced_->paused();
      if (paced_) paced_->pause();
      const bool got = seekable_->seek_last() && read(controller, FrameOrder::kJump);
      if (got) reached_end(controller);
      if (paced_ && !was_paused) paced_->resume();
      return got;
    }
  }
  return false;
}

bool LiveFeed::step(LiveController& controller) {
  if (paced_) paced_->set_speed(controller.speed());
  if (const std::optional<PlaybackRequest> request = controller.take_playback_request()) {
    return carry_out(*request, controller);
  }
  if (paced_ && controller.paused() != paced_->paused()) {
    // The clock stops with the picture; resume() restarts it one frame period after the last
    // frame shown, so there is no gap and no burst.
    controller.paused() ? paced_->pause() : paced_->resume();
  }
  if (controller.paused() || ended_) return false;
  if (read(controller, FrameOrder::kNext)) return true;
  if (controller.loop() && seekable_ && shown_ > 0 && jump_to(0, controller)) return true;
  ended_ = true;
  controller.on_end_of_input();
  return false;
}

}  // namespace softsight
