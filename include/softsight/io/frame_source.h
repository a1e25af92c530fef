// Where frames come from: a video file (anything FFmpeg reads), an image sequence (a folder or a
// printf pattern), a camera (V4L2 index), or the synthetic renderer. Timestamps come from the source.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "softsight/core/types.h"

namespace softsight {

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Reads the next frame into `frame`, reusing its buffer when the size allows. Returns false at
  // the end of the stream. Throws InputError naming the source and frame index when a frame
  // fails to decode mid-stream.
  virtual bool read(Frame& frame) = 0;

  // Human-readable name for messages: "video demo.avi", "camera 0", "images shots/%04d.png".
  virtual std::string description() const = 0;

  // Number of frames when known in advance (files, synthetic scenes); absent for cameras.
  virtual std::optional<int64_t> frame_count() const = 0;

  // Nominal frame rate in frames per second when known.
  virtual std::optional<double> fps() const = 0;

  // True for live sources (cameras): no progress bar, frames may be dropped.
  virtual bool is_live() const { return false; }
};

}  // namespace softsight
