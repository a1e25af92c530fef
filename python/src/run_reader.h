// What the module's two frame readers share (softsight.frames' FrameStream in track_binding.cc,
// softsight.frames_stereo's StereoFrameStream in stereo_binding.cc): closing, and how far their
// run has come.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>

#include <pybind11/pybind11.h>

namespace softsight::python {

// `Reader` derives from ClosableRunReader<Reader>, holds its run's stream (a BasicRunStream) in
// `stream_`, and lets go of its input in `release_input()`; it makes this class its friend.
template <typename Reader>
class ClosableRunReader {
 public:
  // Releases the input (idempotent), after a next() in progress.
  void close() {
    pybind11::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(mutex_);
    close_locked();
  }
  bool closed() const { return closed_; }
  // The frames the run will have (max_frames when fewer) when its input knows its length (a
  // pair input does not: max_frames, when given).
  std::optional<int64_t> total() const { return reader().stream_->info().frame_count; }
  int64_t done() const { return reader().stream_->returned(); }

 protected:
  // With mutex_ held. The stream is not asked again: its input is gone.
  void close_locked() {
    closed_ = true;
    static_cast<Reader*>(this)->release_input();
  }

  bool closed_ = false;
  std::mutex mutex_;  // One next() at a time.

 private:
  const Reader& reader() const { return static_cast<const Reader&>(*this); }
};

}  // namespace softsight::python
