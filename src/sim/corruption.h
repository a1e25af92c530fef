// Damaged frames, as a broken file or a glitching capture delivers them, injected into rendered
// sequences to test that a tracker does not report confidently wrong positions on them.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

namespace softsight {

enum class CorruptionKind {
  kGarbageBlock,  // A rectangle of random bytes (a lost slice decoded from garbage).
  kOtherVideo,    // The whole frame replaced by a frame of another video.
  kShiftedBand,   // From some row on, rows shifted sideways (a decoder that lost its place).
};

// Corrupts `image` (CV_8UC1 or CV_8UC3) in place; deterministic in `seed`.
// kGarbageBlock: random bytes over `block_px` when it is not empty (e.g. a marker's box),
//   otherwise over a rectangle of half the width and height (a quarter of the frame) at a
//   random place.
// kOtherVideo: `image` becomes `other_frame` (resized and converted to the image's size and
//   type when they differ); throws InputError when `other_frame` is empty.
// kShiftedBand: a band of rows (an eighth to a half of the height, possibly to the bottom)
//   shifted sideways by 5-30 % of the width, wrapping around, and dimmed or brightened a little.
void CorruptFrame(CorruptionKind kind, uint64_t seed, const cv::Mat& other_frame, cv::Mat& image,
                  const cv::Rect& block_px = cv::Rect());

const char* CorruptionKindName(CorruptionKind kind);

}  // namespace softsight
