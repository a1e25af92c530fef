#include "io/read_ahead_source.h"

#include <algorithm>
#include <chrono>
#include <utility>

namespace softsight {

ReadAheadSource::ReadAheadSource(std::unique_ptr<FrameSource> source, size_t capacity)
    : source_(std::move(source)),
      description_(source_->description()),
      frame_count_(source_->frame_count()),
      fps_(source_->fps()),
      live_(source_->is_live()),
      files_(source_->files()),
      ring_(std::max<size_t>(capacity, 1)),
      dropped_(source_->dropped_frames()),
      note_(source_->note()) {
  thread_ = std::thread([this] { decode_loop(); });
}

ReadAheadSource::~ReadAheadSource() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  taken_.notify_all();
  thread_.join();
}

void ReadAheadSource::decode_loop() {
  std::exception_ptr error;
  for (;;) {
    Frame* slot = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      taken_.wait(lock, [this] { return stopping_ || count_ < ring_.size(); });
      if (stopping_) break;
      // The slot after the queued ones: read() touches only queued slots, so it is the
      // decoder's alone until it is queued below.
      slot = &ring_[(head_ + count_) % ring_.size()];
    }
    bool got = false;
    try {
      slot->captured = {};
      got = source_->read(*slot);
      // A file's "capture" is its decoding: the latency of its frames counts the queue's wait.
      if (got && slot->captured == std::chrono::steady_clock::time_point{}) {
        slot->captured = std::chrono::steady_clock::now();
      }
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    dropped_ = source_->dropped_frames();
    if (!got) {
      note_ = source_->note();
      error_ = error;
      break;
    }
    ++count_;
    decoded_.notify_one();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ended_ = true;
  decoded_.notify_all();
}

bool ReadAheadSource::read(Frame& frame) {
  std::unique_lock<std::mutex> lock(mutex_);
  decoded_.wait(lock, [this] { return count_ > 0 || ended_; });
  if (count_ == 0) {
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    return false;
  }
  // The caller's old buffer goes back to the decoder, which overwrites it. A buffer somebody still
  // shares (a shallow copy of an earlier frame kept by a sink) is let go instead, so what they
  // hold is never overwritten under them.
  if (frame.image.u != nullptr && frame.image.u->refcount > 1) frame.image.release();
  std::swap(frame, ring_[head_]);
  head_ = (head_ + 1) % ring_.size();
  --count_;
  lock.unlock();
  taken_.notify_one();
  return true;
}

int64_t ReadAheadSource::dropped_frames() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

std::optional<std::string> ReadAheadSource::note() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return note_;
}

}  // namespace softsight
