#include "io/frame_grabber.h"

#include <optional>
#include <string>
#include <utility>

#include "softsight/core/error.h"

namespace softsight {

FrameGrabber::FrameGrabber(std::unique_ptr<FrameSource> source, bool pace)
    : source_(std::move(source)), pace_(pace && !source_->is_live()) {
  thread_ = std::thread([this] { run(); });
}

FrameGrabber::~FrameGrabber() {
  stop_ = true;
  ready_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void FrameGrabber::run() {
  GrabbedFrame next;
  std::optional<double> first_time_s;
  SteadyClock::time_point start;
  try {
    while (!stop_) {
      if (!source_->read(next.frame)) break;
      if (pace_) {
        // Deliver each frame when its timestamp comes, as a camera would.
        if (!first_time_s) {
          first_time_s = next.frame.time_s;
          start = SteadyClock::now();
        }
        const auto due =
            start + std::chrono::duration_cast<SteadyClock::duration>(
                        std::chrono::duration<double>(next.frame.time_s - *first_time_s));
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait_until(lock, due, [this] { return stop_.load(); });
        if (stop_) break;
      }
      next.captured = SteadyClock::now();
      next.frame.captured = next.captured;  // Travels with the frame: where its latency starts.
      ++captured_;
      std::lock_guard<std::mutex> lock(mutex_);
      if (slot_full_) ++dropped_;  // The consumer never saw the previous one: newest wins.
      std::swap(slot_, next);      // Keeps both buffers alive: no allocation per frame.
      slot_full_ = true;
      ready_.notify_all();
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::current_exception();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ended_ = true;
  ready_.notify_all();
}

bool FrameGrabber::take(GrabbedFrame& out) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!slot_full_) {
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    return false;
  }
  std::swap(out, slot_);
  slot_full_ = false;
  return true;
}

bool FrameGrabber::wait_take(GrabbedFrame& out, std::chrono::milliseconds timeout) {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, timeout, [this] { return slot_full_ || ended_; });
  }
  return take(out);
}

bool FrameGrabber::finished() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return ended_ && !slot_full_ && !error_;
}

NewestFrameSource::NewestFrameSource(std::unique_ptr<FrameSource> source,
                                     std::chrono::milliseconds stall_timeout)
    : grabber_(std::move(source), /*pace=*/false), stall_timeout_(stall_timeout) {}

bool NewestFrameSource::read(Frame& frame) {
  const auto deadline = SteadyClock::now() + stall_timeout_;
  while (!grabber_.wait_take(taken_, std::chrono::milliseconds(50))) {
    if (grabber_.finished()) return false;
    if (SteadyClock::now() > deadline) {
      throw InputError(description() + ": no frame for " +
                       std::to_string(stall_timeout_.count()) + " ms (unplugged?)");
    }
  }
  std::swap(frame, taken_.frame);
  return true;
}

}  // namespace softsight
