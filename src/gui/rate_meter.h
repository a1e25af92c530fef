// Internal to gui (and the tests). The live window's figures of speed: the frame rate over the
// last results of the playing source, how fast the source's own time passes against the clock
// over them (a file played slower than real time), and the latency from capture to the screen,
// smoothed so that the overlay's number can be read. Fed with time points, so tests give it their
// own clock.
#pragma once

#include <chrono>
#include <cstddef>
#include <optional>
#include <vector>

namespace softsight {

class RateMeter {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr size_t kFpsWindow = 30;          // Results averaged for the frame rate.
  static constexpr double kLatencySmoothing = 0.2;  // Weight of the newest latency.

  RateMeter() {
    times_.reserve(kFpsWindow);
    media_s_.reserve(kFpsWindow);
  }

  // A result of the playing source at `now`, of its frame at `media_time_s` (the frame's own
  // time_s); stepped or seeked frames are no rate.
  void result_at(Clock::time_point now, double media_time_s);
  // Starts the window over (the source jumped: its time is no longer continuous).
  void restart();
  // A frame's latency from capture to its result on screen, ms.
  void latency(double ms);

  // Results per second over the window; absent before two results (or if no time passed).
  std::optional<double> fps() const { return fps_; }
  // Seconds of the source's time per second of the clock over the window (1: real time; 0.5: a
  // file played at half its speed); absent like fps().
  std::optional<double> speed() const { return speed_; }
  std::optional<double> latency_ms() const { return latency_ms_; }

 private:
  std::vector<Clock::time_point> times_;  // Ring of the last kFpsWindow result times ...
  std::vector<double> media_s_;           // ... and their frames' times.
  size_t next_ = 0;                       // Where the next time goes once the ring is full.
  std::optional<double> fps_, speed_, latency_ms_;
};

}  // namespace softsight
