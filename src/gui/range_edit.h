// Internal to gui (and the tests). Growing and shrinking a marker's HSV ranges by the colours
// of clicked pixels, for the live window's mask view: a click adds the pixels around it to the
// ranges, a shift-click takes them out. Hue is circular (a range with lo > hi wraps through 0).
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "softsight/track/colour_tracker.h"

namespace softsight {

struct HsvRanges {
  HsvRange h, s, v;
};

// "170..10": a range as the window shows it.
std::string RangeText(const HsvRange& range);

// True when the HSV pixel lies in all three ranges.
bool InRanges(const HsvRanges& ranges, const cv::Vec3b& hsv);

// Widens each range as little as possible to take in every pixel of `hsv_pixels` (CV_8UC3,
// OpenCV's 8-bit HSV, hue 0..179).
HsvRanges GrowRanges(HsvRanges ranges, const cv::Mat& hsv_pixels);

// Narrows one range at one end so that no pixel of `hsv_pixels` is a member any more, choosing
// the end that removes the smallest share of its range (the other pixels the ranges accept
// are kept as far as one cut allows). Returns false, `ranges` unchanged, when none of the pixels
// is a member (nothing to remove) or no single cut can exclude them all without emptying a range;
// `why` says which.
bool ShrinkRanges(HsvRanges& ranges, const cv::Mat& hsv_pixels, std::string* why);

}  // namespace softsight
