// Two cameras' frames, paired: by index (two videos, one started `frame_offset` frames before the
// other), by time (each frame's timestamp or capture time: two cameras at slightly different
// rates, two videos with timestamps), or the two halves of one side-by-side video.
//
// Built on FrameSource, so any two sources pair: video files, image sequences, rendered scenes,
// two live cameras (each frame with its capture time).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "softsight/core/types.h"
#include "softsight/io/frame_source.h"

namespace softsight {

struct FramePair {
  Frame left{}, right{};  // Each with its own source's index and time.
  // Pairing by time: the right frame's time minus the left one's (after the time offset), in
  // milliseconds: the pairing error. Absent when paired by index.
  std::optional<double> pair_dt_ms{};
};

class StereoInput {
 public:
  virtual ~StereoInput() = default;
  // The next pair, reusing the buffers of `pair`; false at the end of either view. Throws what
  // the sources throw (InputError naming the source and frame).
  virtual bool read(FramePair& pair) = 0;
  // "video left.avi + video right.avi", for messages.
  virtual std::string description() const = 0;
  // The first (left) view's nominal rate, when known; whether it is a live camera (pairs may be
  // missed, no known end). What a run tells its sinks (RunInfo), as of a FrameSource.
  virtual std::optional<double> fps() const { return std::nullopt; }
  virtual bool is_live() const { return false; }
  // Frames read but left without a partner (pairing by time: none of the other view's frames
  // within the tolerance; pairing by index: the first |frame_offset| frames of the view that
  // started earlier).
  virtual int64_t left_unpaired() const { return 0; }
  virtual int64_t right_unpaired() const { return 0; }
  // After read() returned false: the view that ran out while the other still had frames
  // ("images right/ ended first"); absent when both ended together or that is unknown.
  virtual std::optional<std::string> ended_first() const { return std::nullopt; }
  // The files read (both views), so outputs can be checked against them.
  virtual std::vector<std::string> files() const = 0;
};

// Left frame i with right frame i + frame_offset (the right camera started frame_offset frames
// earlier; negative: later). Reads (and drops) the first |frame_offset| frames of the view that
// started earlier at once; throws InputError "<offset_name> N: <source> has only k frames" when
// it has fewer.
std::unique_ptr<StereoInput> PairByIndex(std::unique_ptr<FrameSource> left,
                                         std::unique_ptr<FrameSource> right, int64_t frame_offset,
                                         const std::string& offset_name = "frame offset");

struct TimePairingOptions {
  // Which time a frame carries: the source's (Frame::time_s: a video's timestamps, an image
  // sequence's index / fps), or when it was captured on this machine's clock (Frame::captured:
  // two live cameras read by one program share it; a source that leaves it unset is stamped
  // when read() returns).
  enum class Clock { kSourceTime, kCaptureTime };
  Clock clock = Clock::kSourceTime;
  // The right view's time of a moment minus the left view's (ms): what the right camera's clock
  // is ahead by. 0 when both count from the same start.
  double time_offset_ms = 0.0;
  // Frames further apart than this are not a pair (ms). Absent (default): half the shorter
  // frame interval of the two views (each from its source's fps(), else its first two frames),
  // so a frame can have at most one partner.
  std::optional<double> max_dt_ms{};

  bool Check(std::string* error) const;
};

// Each pair is two frames that are each other's nearest in time within the tolerance; a frame
// with no such partner is left out and counted. Reads one frame ahead in each view.
// Throws InputError when the tolerance cannot be known (no frame rate and a single frame).
std::unique_ptr<StereoInput> PairByTime(std::unique_ptr<FrameSource> left,
                                        std::unique_ptr<FrameSource> right,
                                        const TimePairingOptions& options = {});

// One video with both views side by side: the left half of each frame is the first camera's,
// the right half the second's. The halves are views into the decoded frame (no copy). Throws
// InputError naming the source and frame when a frame's width is odd.
std::unique_ptr<StereoInput> SplitSideBySide(std::unique_ptr<FrameSource> source);

}  // namespace softsight
