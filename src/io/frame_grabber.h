// Capture in its own thread, newest frame wins: the consumer always gets the most recent frame
// and frames it was too slow for are dropped, so latency never builds up behind a slow consumer.
// This is how a camera is paced (NewestFrameSource below wraps it as a FrameSource); files and
// image sequences are never read through it by batch commands, so they never drop a frame.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "softsight/core/types.h"
#include "softsight/io/frame_source.h"

namespace softsight {

using SteadyClock = std::chrono::steady_clock;

struct GrabbedFrame {
  Frame frame{};
  SteadyClock::time_point captured{};  // When the source returned it (start of the latency).
};

class FrameGrabber {
 public:
  // Starts reading `source` at once. `pace`: for sources that are not live (files), wait until
  // each frame's timestamp has come, as a camera would deliver it; false reads as fast as the
  // source decodes.
  FrameGrabber(std::unique_ptr<FrameSource> source, bool pace);
  ~FrameGrabber();  // Stops and joins the capture thread.
  FrameGrabber(const FrameGrabber&) = delete;
  FrameGrabber& operator=(const FrameGrabber&) = delete;

  // Moves the newest frame not yet taken into `out` (swapping buffers, no copy) and returns true;
  // returns false at once when there is none. Rethrows an error the capture thread met.
  bool take(GrabbedFrame& out);
  // Like take() but waits up to `timeout` for a frame.
  bool wait_take(GrabbedFrame& out, std::chrono::milliseconds timeout);

  // True once the source has ended and its last frame has been taken.
  bool finished() const;

  int64_t captured_count() const { return captured_.load(); }
  int64_t dropped_count() const { return dropped_.load(); }
  const FrameSource& source() const { return *source_; }

 private:
  void run();

  std::unique_ptr<FrameSource> source_;
  bool pace_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  GrabbedFrame slot_;  // Newest frame, guarded by mutex_.
  bool slot_full_ = false;
  bool ended_ = false;
  std::exception_ptr error_;
  std::atomic<bool> stop_{false};
  std::atomic<int64_t> captured_{0};
  std::atomic<int64_t> dropped_{0};
  std::thread thread_;
};

// A live source (a camera) read in its own thread, newest frame wins: read() returns the most
// recent frame not yet returned, waiting for one if needed; frames the pipeline was too slow for
// are skipped and counted (dropped_frames()). Frames keep the source's index and timestamp, so
// rows show where frames were skipped.
class NewestFrameSource : public FrameSource {
 public:
  // `stall_timeout`: read() gives up with an InputError naming the source when no frame arrives
  // for this long (an unplugged camera), instead of waiting forever.
  explicit NewestFrameSource(std::unique_ptr<FrameSource> source,
                             std::chrono::milliseconds stall_timeout = std::chrono::seconds(5));

  bool read(Frame& frame) override;
  std::string description() const override { return grabber_.source().description(); }
  std::optional<int64_t> frame_count() const override { return grabber_.source().frame_count(); }
  std::optional<double> fps() const override { return grabber_.source().fps(); }
  bool is_live() const override { return true; }
  int64_t dropped_frames() const override { return grabber_.dropped_count(); }
  // The camera's own (what it accepted of its settings, frames it lost): the run's summary
  // prints it. Sources make note() safe to call while their read() runs in the grabber thread.
  std::optional<std::string> note() const override { return grabber_.source().note(); }

 private:
  FrameGrabber grabber_;
  std::chrono::milliseconds stall_timeout_;
  GrabbedFrame taken_;  // Swapped with the caller's frame: buffers are reused, not copied.
};

}  // namespace softsight
