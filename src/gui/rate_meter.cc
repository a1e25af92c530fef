#include "gui/rate_meter.h"

namespace softsight {

void RateMeter::result_at(Clock::time_point now) {
  if (times_.size() < kFpsWindow) {
    times_.push_back(now);
  } else {
    times_[next_] = now;
  }
  next_ = (next_ + 1) % kFpsWindow;
  if (times_.size() < 2) return;
  // The oldest time in the ring: its start until it is full, then the slot written next.
  const Clock::time_point oldest = times_.size() < kFpsWindow ? times_.front() : times_[next_];
  const double span_s = std::chrono::duration<double>(now - oldest).count();
  if (span_s > 0) fps_ = (times_.size() - 1) / span_s;
}

void RateMeter::latency(double ms) {
  latency_ms_ = latency_ms_ ? *latency_ms_ + kLatencySmoothing * (ms - *latency_ms_) : ms;
}

}  // namespace softsight
