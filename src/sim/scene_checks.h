// Inside the sim module: the checks every rendered scene's options share (the video's shape).
#pragma once

#include <cmath>
#include <string>

#include <opencv2/core.hpp>

#include "softsight/core/format.h"
#include "softsight/core/option_table.h"

namespace softsight::sim {

// The frame size, the frame count and the frame rate of a rendered video, with the messages
// `Check(std::string* error)` gives for them.
inline bool CheckVideoShape(const cv::Size& size, int frame_count, double fps, std::string* error) {
  if (size.width < 16 || size.height < 16 || size.width > 8192 || size.height > 8192) {
    return Fail(error, "size: must be between 16x16 and 8192x8192 pixels, got " +
                           std::to_string(size.width) + "x" + std::to_string(size.height));
  }
  if (frame_count < 1) {
    return Fail(error, "frame_count: must be at least 1, got " + std::to_string(frame_count));
  }
  if (!(std::isfinite(fps) && fps > 0)) return Fail(error, "fps: must be > 0, got " + ShortNumber(fps));
  return true;
}

}  // namespace softsight::sim
