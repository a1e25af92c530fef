#include "softsight/io/async_frame_writer.h"

#include <algorithm>
#include <exception>
#include <utility>

namespace softsight {

AsyncFrameWriter::AsyncFrameWriter(FrameWriterOptions options, size_t capacity,
                                   std::function<void(int64_t)> before_encode)
    : writer_(std::move(options)),
      path_(writer_.path()),
      format_(writer_.format()),
      before_encode_(std::move(before_encode)),
      ring_(std::max<size_t>(capacity, 1)) {
  thread_ = std::thread([this] { encode_loop(); });
}

AsyncFrameWriter::~AsyncFrameWriter() {
  if (std::uncaught_exceptions() > uncaught_at_start_) {
    // Left by an exception: the video is abandoned (FrameWriter::discard), the output left as it
    // was; what is queued is not waited for.
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
      abandoned_ = true;
    }
    queued_cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    writer_.discard();
    return;
  }
  try {
    close();
  } catch (...) {  // Reported by the caller's own close(); the cut video was removed.
  }
}

void AsyncFrameWriter::open(cv::Size size) { writer_.open(size); }

void AsyncFrameWriter::encode_loop() {
  for (;;) {
    Slot* slot = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      queued_cv_.wait(lock, [this] { return count_ > 0 || closing_; });
      if (count_ == 0 || abandoned_) break;  // Closing, and everything queued is written.
      slot = &ring_[head_];    // Stays queued (not reused by acquire()) until written.
    }
    try {
      if (before_encode_) before_encode_(slot->index);
      writer_.write(slot->image, slot->index);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = std::current_exception();
      count_ = 0;  // The file is broken: what is queued is not written.
      break;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    head_ = (head_ + 1) % ring_.size();
    --count_;
    freed_cv_.notify_one();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = true;
  freed_cv_.notify_all();
}

cv::Mat* AsyncFrameWriter::acquire() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (count_ == ring_.size() && !error_) {
    ++waited_;
    freed_cv_.wait(lock, [this] { return count_ < ring_.size() || done_; });
  }
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  return &ring_[(head_ + count_) % ring_.size()].image;
}

void AsyncFrameWriter::commit(int64_t index) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ring_[(head_ + count_) % ring_.size()].index = index;
    ++count_;
    ++queued_;
  }
  queued_cv_.notify_one();
}

void AsyncFrameWriter::close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
  }
  queued_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (error_) {
    writer_.discard();  // A frame could not be written: the video is not put in place.
    std::rethrow_exception(std::exchange(error_, nullptr));
  }
  writer_.close();
}

}  // namespace softsight
