// For tests of recordings (test code only): an encoder held in front of one frame until opened,
// through AsyncFrameWriter's before_encode hook, so that a test fills the queue of frames and
// makes the encoder fall behind without any timing; and the frames a video holds.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "softsight/io/frame_source.h"

namespace softsight::testing {

class EncoderGate {
 public:
  // Holds the encoder in front of the frame with this index (the source's index it was
  // committed with).
  explicit EncoderGate(int64_t held_index = 0) : held_index_(held_index) {}
  // The hook: called on the encoding thread before each frame.
  void wait(int64_t index) {
    if (index != held_index_) return;
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return open_; });
  }
  void open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }

 private:
  const int64_t held_index_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool open_ = false;
};

// How many frames the video at `path` holds, read to its end.
inline int64_t FramesInVideo(const std::string& path) {
  std::unique_ptr<FrameSource> source = OpenFrameSource({path, {}, 30.0});
  Frame frame;
  int64_t frames = 0;
  while (source->read(frame)) ++frames;
  return frames;
}

}  // namespace softsight::testing
