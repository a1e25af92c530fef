// A FrameWriter that encodes on its own thread, behind a bounded queue of frame buffers, so the
// pipeline does not wait for the encoder (HuffYUV at VGA takes ~2 ms a frame, MJPG more on a
// loaded machine). It never loses a frame: when the encoder falls a whole queue behind, acquire()
// waits for a free buffer, and the frames that waited are counted (waited()).
//
// Single producer: call acquire/commit/close from one thread (the pipeline's).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/io/frame_writer.h"

namespace softsight {

class AsyncFrameWriter {
 public:
  // Checks the path and codec at once, as FrameWriter does (throws InputError). `capacity`:
  // frames queued at most (>= 1), each a buffer kept for the recording and reused.
  // `before_encode` (tests): called on the encoding thread before each frame is encoded, with its
  // index; a test holds the encoder there to fill the queue.
  AsyncFrameWriter(FrameWriterOptions options, size_t capacity = 8,
                   std::function<void(int64_t index)> before_encode = {});
  // Finishes what is queued (close()), errors swallowed; left by an exception, abandons the
  // video instead (FrameWriter::discard), the output left as it was.
  ~AsyncFrameWriter();
  AsyncFrameWriter(const AsyncFrameWriter&) = delete;
  AsyncFrameWriter& operator=(const AsyncFrameWriter&) = delete;

  // Opens the video for frames of `size` now, on this thread (its errors are InputErrors here).
  void open(cv::Size size);
  // A free buffer to fill with the next frame (8-bit BGR of the first frame's size; it may still
  // hold an older frame), once there is one. Rethrows the encoder's error (InputError naming the file and frame) once it met
  // one. Follow every acquire() with commit().
  cv::Mat* acquire();
  // Queues the buffer acquire() returned, as the frame with this index.
  void commit(int64_t index);
  // Encodes everything queued, then closes the file (FrameWriter::close: into place when whole);
  // rethrows the encoder's error, if any (the video then abandoned).
  void close();

  const std::string& path() const { return path_; }
  const std::string& format() const { return format_; }
  // Frames for which acquire() had to wait for the encoder: how often it held up the
  // pipeline. May be read from any thread.
  int64_t waited() const { return waited_.load(); }
  int64_t queued() const { return queued_; }  // Frames committed (written once close() returns).

 private:
  void encode_loop();

  FrameWriter writer_;  // Used by the encoding thread once it runs (after open()).
  std::string path_, format_;
  std::function<void(int64_t)> before_encode_;
  std::mutex mutex_;
  std::condition_variable queued_cv_, freed_cv_;
  struct Slot {
    cv::Mat image{};
    int64_t index = 0;
  };
  std::vector<Slot> ring_;  // Queued: ring_[head_] .. count_ of them; the next free follows.
  size_t head_ = 0, count_ = 0;
  bool closing_ = false, done_ = false;
  bool abandoned_ = false;  // Destroyed by an exception: what is queued is dropped.
  int uncaught_at_start_ = std::uncaught_exceptions();
  std::exception_ptr error_;
  int64_t queued_ = 0;
  std::atomic<int64_t> waited_{0};
  std::thread thread_;
};

}  // namespace softsight
