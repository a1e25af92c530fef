#include "gui/rate_meter.h"

namespace softsight {

void RateMeter::result_at(Clock::time_point now, double media_time_s) {
  if (times_.size() < kFpsWindow) {
    times_.push_back(now);
    media_s_.push_back(media_time_s);
  } else {
    times_[next_] = now;
    media_s_[next_] = media_time_s;
  }
  next_ = (next_ + 1) % kFpsWindow;
  if (times_.size() < 2) return;
  // The oldest time in the ring: its start until it is full, then the slot written next.
  const size_t oldest = times_.size() < kFpsWindow ? 0 : next_;
  const double span_s = std::chrono::duration<double>(now - times_[oldest]).count();
  if (span_s > 0) {
    fps_ = (times_.size() - 1) / span_s;
    speed_ = (media_time_s - media_s_[oldest]) / span_s;
  }
}

void RateMeter::restart() {
  times_.clear();
  media_s_.clear();
  next_ = 0;
  fps_.reset();
  speed_.reset();
}

void RateMeter::latency(double ms) {
  latency_ms_ = latency_ms_ ? *latency_ms_ + kLatencySmoothing * (ms - *latency_ms_) : ms;
}

}  // namespace softsight
