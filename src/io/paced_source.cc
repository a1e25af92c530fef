#include "io/paced_source.h"

#include <thread>
#include <utility>

namespace softsight {

PacedFrameSource::PacedFrameSource(std::unique_ptr<FrameSource> source, Timing timing)
    : source_(std::move(source)), timing_(std::move(timing)) {
  if (!timing_.now) timing_.now = [] { return Clock::now(); };
  if (!timing_.sleep_until) {
    timing_.sleep_until = [](Clock::time_point t) { std::this_thread::sleep_until(t); };
  }
}

bool PacedFrameSource::read(Frame& frame) {
  if (!source_->read(frame)) return false;
  if (!anchor_) {
    anchor_ = timing_.now();
    anchor_time_s_ = frame.time_s;
  } else if (!paused_) {
    const auto due = *anchor_ + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>((frame.time_s - anchor_time_s_) / speed_));
    if (timing_.now() < due) timing_.sleep_until(due);
  }
  last_time_s_ = frame.time_s;
  return true;
}

void PacedFrameSource::pause() { paused_ = true; }

void PacedFrameSource::set_speed(double speed) {
  if (!(speed > 0) || speed == speed_) return;
  speed_ = speed;
  if (!paused_ && last_time_s_) {
    anchor_ = timing_.now();
    anchor_time_s_ = *last_time_s_;
  }
}

void PacedFrameSource::resume() {
  if (!paused_) return;
  paused_ = false;
  if (last_time_s_) {
    // The last frame shown is "now": the next one is due a frame period later.
    anchor_ = timing_.now();
    anchor_time_s_ = *last_time_s_;
  }
}

}  // namespace softsight
