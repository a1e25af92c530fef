// Footage that repeats frames to fill its rate (a 30 fps file from a webcam that delivered 15 or
// 10 in dim light, a converter's constant frame rate) shows a moving marker exactly still for a
// frame or two, then moved by all those frames' worth at once. The template tracker (its velocity)
// and the session's tracks (pipeline/marker_tracks.h) both keep what they knew of the motion over
// such frames, by this one rule, so the step after them is expected.
#pragma once

#include <opencv2/core.hpp>

namespace softsight {

// A report within this of the last position is the marker standing exactly still (sensor noise
// moves a still marker's centroid by hundredths of a pixel, so a real stop soon reads as one).
inline constexpr double kRepeatStillPx = 0.05;
// ... which is a repeated frame only for a marker moving at least this fast (px per frame) ...
inline constexpr double kRepeatMovingPxPerFrame = 1.0;
// ... and for at most this many frames in a row: still for longer, the marker has stopped.
inline constexpr int kMaxRepeatedFrames = 2;

// True when a report `step` px from the marker's last position, for a marker moving at
// `velocity` px per frame with `repeats` repeated frames in a row so far, is one more.
inline bool IsRepeatedFrame(const cv::Point2d& step, const cv::Point2d& velocity, int repeats) {
  return cv::norm(step) <= kRepeatStillPx && cv::norm(velocity) >= kRepeatMovingPxPerFrame &&
         repeats < kMaxRepeatedFrames;
}

}  // namespace softsight
