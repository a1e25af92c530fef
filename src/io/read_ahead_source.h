// A file, image sequence or rendered scene decoded on its own thread, a few frames ahead of the
// pipeline, so decoding and tracking overlap: a run's wall time approaches max(decode, track)
// instead of their sum. Unlike NewestFrameSource (cameras, newest frame wins) it never drops a
// frame: the decoding thread waits while the queue is full, and every frame reaches read() in
// order with the inner source's index and timestamp. The end of the stream and an InputError the
// inner source throws (a truncated file, a corrupt frame) reach read() exactly where they occur:
// after every frame decoded before them, as an unthreaded read gives them.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "softsight/io/frame_source.h"

namespace softsight {

class ReadAheadSource : public FrameSource {
 public:
  // Starts decoding `source` at once. `capacity`: frames decoded ahead at most (>= 1); each one is
  // a frame buffer kept for the run (4 at VGA: 3.7 MB), reused frame after frame.
  explicit ReadAheadSource(std::unique_ptr<FrameSource> source, size_t capacity = 4);
  // Stops the decoding thread (it finishes the frame it is decoding, at most) and joins it.
  ~ReadAheadSource() override;
  ReadAheadSource(const ReadAheadSource&) = delete;
  ReadAheadSource& operator=(const ReadAheadSource&) = delete;

  // The next frame in order, waiting for the decoder if needed (swaps buffers with `frame`: no
  // copy). Returns false at the end; rethrows the inner source's error once, in its place.
  bool read(Frame& frame) override;

  // Fixed when the source opened (read on this thread, never while the decoder runs).
  std::string description() const override { return description_; }
  std::optional<int64_t> frame_count() const override { return frame_count_; }
  std::optional<double> fps() const override { return fps_; }
  bool is_live() const override { return live_; }
  std::vector<std::string> files() const override { return files_; }
  // The inner source's, as of the last frame handed out (its final value once read() returned
  // false or threw).
  int64_t dropped_frames() const override;
  std::optional<std::string> note() const override;

 private:
  void decode_loop();

  std::unique_ptr<FrameSource> source_;  // Used only by the decoding thread once it started.
  std::string description_;
  std::optional<int64_t> frame_count_;
  std::optional<double> fps_;
  bool live_ = false;
  std::vector<std::string> files_;

  mutable std::mutex mutex_;
  std::condition_variable decoded_;  // A frame was queued, or the stream ended.
  std::condition_variable taken_;    // A slot was freed, or a stop was asked.
  std::vector<Frame> ring_;          // Queued frames: ring_[head_] .. count_ of them.
  size_t head_ = 0;
  size_t count_ = 0;
  bool ended_ = false;                // The decoder is done: end of stream or error_.
  bool stopping_ = false;             // The destructor asks the decoder to stop.
  std::exception_ptr error_;          // Thrown by read() once the queue before it is empty.
  int64_t dropped_ = 0;               // The inner source's counts, refreshed after each frame.
  std::optional<std::string> note_;
  std::thread thread_;
};

}  // namespace softsight
