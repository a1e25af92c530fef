// A file (or image sequence) played at its own frame rate, as a camera would deliver it, for the
// live window: read() waits until the frame's timestamp is due, and never skips a frame (a slow
// consumer makes the file play slower, not jump). pause() stops the clock: after resume() the
// next frame comes one frame period after the last one delivered, so a pause is no gap in the
// frames and no burst after it. Indices and timestamps are the file's.
//
// Single-threaded: call read(), pause() and resume() from the thread that runs the pipeline.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "softsight/io/frame_source.h"

namespace softsight {

// The time source and the wait of a PacedFrameSource, replaceable so tests run without waiting.
struct PacingClock {
  using Clock = std::chrono::steady_clock;
  std::function<Clock::time_point()> now{};             // Empty: steady_clock::now.
  std::function<void(Clock::time_point)> sleep_until{};  // Empty: std::this_thread::sleep_until.
};

class PacedFrameSource : public FrameSource {
 public:
  using Clock = PacingClock::Clock;
  using Timing = PacingClock;

  explicit PacedFrameSource(std::unique_ptr<FrameSource> source, PacingClock timing = {});

  // Waits until the next frame is due, then returns it. While paused it returns the next frame
  // at once (stepping frame by frame) and the clock stays stopped.
  bool read(Frame& frame) override;
  void pause();
  void resume();
  bool paused() const { return paused_; }
  // Plays at `speed` times the file's rate (0.5: half speed; > 0). The change starts from the
  // last frame delivered, so there is no jump or burst.
  void set_speed(double speed);
  double speed() const { return speed_; }

  std::string description() const override { return source_->description(); }
  std::optional<int64_t> frame_count() const override { return source_->frame_count(); }
  std::optional<double> fps() const override { return source_->fps(); }
  bool is_live() const override { return source_->is_live(); }
  int64_t dropped_frames() const override { return source_->dropped_frames(); }

 private:
  std::unique_ptr<FrameSource> source_;
  Timing timing_;
  bool paused_ = false;
  double speed_ = 1.0;
  // The clock: frame time `anchor_time_s_` is due at `anchor_`. Set by the first frame, moved by
  // resume() to the last delivered frame.
  std::optional<Clock::time_point> anchor_;
  double anchor_time_s_ = 0.0;
  std::optional<double> last_time_s_;
};

}  // namespace softsight
