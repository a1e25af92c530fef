#include "softsight/core/hsv_range.h"

#include <gtest/gtest.h>

namespace softsight {
namespace {

// Every member against a brute-force walk round the hue circle: the truth is the set of hues a
// range names, counted one by one.
int HuesIn(const HsvRange& r) {
  int n = 0;
  for (int h = 0; h < 180; ++h) n += r.contains_hue(h);
  return n;
}

TEST(HsvRange, HueContainmentSpanAndCentreAgreeWithAWalkRoundTheCircle) {
  for (int lo = 0; lo < 180; lo += 7) {
    for (int hi = 0; hi < 180; hi += 5) {
      const HsvRange r{lo, hi};
      // Walking up from lo, the hues met before passing hi are the range.
      int walked = 0;
      for (int h = lo;; h = (h + 1) % 180) {
        ++walked;
        EXPECT_TRUE(r.contains_hue(h)) << lo << ".." << hi << " at " << h;
        if (h == hi) break;
      }
      EXPECT_EQ(HuesIn(r), walked) << lo << ".." << hi;
      EXPECT_EQ(r.hue_span(), walked - 1);
      EXPECT_EQ(r.wraps(), lo > hi);
      EXPECT_EQ(r.covers_all_hues(), walked == 180);
      EXPECT_EQ(r.hue_centre(), (lo + (walked - 1) / 2) % 180);
    }
  }
}

TEST(HsvRange, RedWrapsThroughZero) {
  const HsvRange red{170, 10};
  EXPECT_TRUE(red.wraps());
  EXPECT_TRUE(red.contains_hue(175) && red.contains_hue(0) && red.contains_hue(10));
  EXPECT_FALSE(red.contains_hue(11) || red.contains_hue(169) || red.contains_hue(90));
  EXPECT_EQ(red.hue_span(), 20);
  EXPECT_EQ(red.hue_centre(), 0);
  EXPECT_EQ(red.hue_offset(5), 15);
}

TEST(HsvRange, AroundAndWidenedWrapAndSaturateAtTheFullCircle) {
  const HsvRange around = HsvRange::HueAround(3, 12);
  EXPECT_EQ(around.lo, 171);
  EXPECT_EQ(around.hi, 15);
  EXPECT_EQ(HuesIn(around), 25);
  const HsvRange widened = HsvRange{170, 10}.hue_widened(4);
  EXPECT_EQ(widened.lo, 166);
  EXPECT_EQ(widened.hi, 14);
  // Closing the circle gives every hue as the plain 0..179, not a range that starts anywhere.
  const HsvRange all = HsvRange{10, 100}.hue_widened(45);
  EXPECT_EQ(all.lo, 0);
  EXPECT_EQ(all.hi, 179);
  EXPECT_EQ(HsvRange::HueAround(50, 90).hue_span(), 179);
  EXPECT_EQ((HsvRange{10, 100}.hue_widened(44).hue_span()), 178);
}

TEST(HsvRange, SaturationAndValueAreALine) {
  const HsvRange s{80, 255};
  EXPECT_TRUE(s.contains(80) && s.contains(255));
  EXPECT_FALSE(s.contains(79));
  EXPECT_EQ(HsvRange::WrapHue(-1), 179);
  EXPECT_EQ(HsvRange::WrapHue(180), 0);
  EXPECT_EQ(HsvRange::WrapHue(-361), 179);
}

}  // namespace
}  // namespace softsight
