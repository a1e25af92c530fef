#include "gui/range_edit.h"

#include <algorithm>
#include <limits>
#include <tuple>
#include <vector>

namespace softsight {

std::string RangeText(const HsvRange& range) {
  return std::to_string(range.lo) + ".." + std::to_string(range.hi);
}

bool InRanges(const HsvRanges& ranges, const cv::Vec3b& hsv) {
  return ranges.h.contains_hue(hsv[0]) && ranges.s.contains(hsv[1]) && ranges.v.contains(hsv[2]);
}

HsvRanges GrowRanges(HsvRanges ranges, const cv::Mat& hsv_pixels) {
  CV_Assert(hsv_pixels.type() == CV_8UC3);
  for (int y = 0; y < hsv_pixels.rows; ++y) {
    for (int x = 0; x < hsv_pixels.cols; ++x) {
      const cv::Vec3b p = hsv_pixels.at<cv::Vec3b>(y, x);
      if (!ranges.h.contains_hue(p[0])) {
        // Extend whichever end is nearer on the circle.
        const int above = HsvRange{ranges.h.hi, ranges.h.hi}.hue_offset(p[0]);  // hi -> p going up.
        const int below = HsvRange{p[0], p[0]}.hue_offset(ranges.h.lo);         // p -> lo going up.
        (above <= below ? ranges.h.hi : ranges.h.lo) = p[0];
      }
      ranges.s.lo = std::min<int>(ranges.s.lo, p[1]);
      ranges.s.hi = std::max<int>(ranges.s.hi, p[1]);
      ranges.v.lo = std::min<int>(ranges.v.lo, p[2]);
      ranges.v.hi = std::max<int>(ranges.v.hi, p[2]);
    }
  }
  return ranges;
}

bool ShrinkRanges(HsvRanges& ranges, const cv::Mat& hsv_pixels, std::string* why) {
  CV_Assert(hsv_pixels.type() == CV_8UC3);
  // Only pixels the ranges accept need taking out; per channel, their extent inside the range
  // (as offsets from the range's low end).
  int lowest[3], highest[3];
  std::fill(lowest, lowest + 3, std::numeric_limits<int>::max());
  std::fill(highest, highest + 3, -1);
  int members = 0;
  HsvRange* r[3] = {&ranges.h, &ranges.s, &ranges.v};
  for (int y = 0; y < hsv_pixels.rows; ++y) {
    for (int x = 0; x < hsv_pixels.cols; ++x) {
      const cv::Vec3b p = hsv_pixels.at<cv::Vec3b>(y, x);
      if (!InRanges(ranges, p)) continue;
      ++members;
      for (int c = 0; c < 3; ++c) {
        const int offset = c == 0 ? r[0]->hue_offset(p[0]) : p[c] - r[c]->lo;
        lowest[c] = std::min(lowest[c], offset);
        highest[c] = std::max(highest[c], offset);
      }
    }
  }
  if (members == 0) {
    *why = "those pixels are not in the ranges already";
    return false;
  }
  // Cutting channel c from below moves lo past the highest member; from above, hi below the
  // lowest. The cheapest cut (share of that range removed) that leaves the range non-empty.
  double best_cost = 2.0;
  int best_channel = -1;
  bool best_from_below = false;
  for (int c = 0; c < 3; ++c) {
    const int span = c == 0 ? r[0]->hue_span() : r[c]->hi - r[c]->lo;
    const double width = span + 1.0;
    if (highest[c] < span) {  // Something stays above the cut.
      const double cost = (highest[c] + 1) / width;
      if (cost < best_cost) std::tie(best_cost, best_channel, best_from_below) = std::tuple(cost, c, true);
    }
    if (lowest[c] > 0) {
      const double cost = (span - lowest[c] + 1) / width;
      if (cost < best_cost) std::tie(best_cost, best_channel, best_from_below) = std::tuple(cost, c, false);
    }
  }
  if (best_channel < 0) {
    *why = "those pixels span a whole range: no single cut excludes them";
    return false;
  }
  HsvRange& cut = *r[best_channel];
  const int base = cut.lo;
  if (best_from_below) {
    cut.lo = base + highest[best_channel] + 1;
  } else {
    cut.hi = base + lowest[best_channel] - 1;
  }
  if (best_channel == 0) {
    cut.lo = HsvRange::WrapHue(cut.lo);
    cut.hi = HsvRange::WrapHue(cut.hi);
  }
  return true;
}

}  // namespace softsight
