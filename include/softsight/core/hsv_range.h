// An inclusive range of one channel of OpenCV's 8-bit HSV, with the channel's rules: saturation
// and value (0..255) are a line; hue (0..179, half degrees) is a circle, and a hue range with
// lo > hi wraps through 0: {170, 10} is 170..179 and 0..10 (red). Every hue test, width, centre
// and widening goes through these members, so wrap-around is written once.
#pragma once

namespace softsight {

struct HsvRange {
  int lo = 0;
  int hi = 255;

  static constexpr int kHueCycle = 180;  // Hues 0..179.

  // Saturation and value: lo <= x <= hi.
  constexpr bool contains(int x) const { return x >= lo && x <= hi; }

  // ---- Hue --------------------------------------------------------------------------------------
  // Any integer as a hue in 0..179 (-1 is 179, 180 is 0).
  static constexpr int WrapHue(int h) { return (h % kHueCycle + kHueCycle) % kHueCycle; }
  // The hues within `reach` of `centre` each way (a full circle when 2 * reach + 1 >= 180).
  static constexpr HsvRange HueAround(int centre, int reach) {
    if (2 * reach + 1 >= kHueCycle) return {0, kHueCycle - 1};
    return {WrapHue(centre - reach), WrapHue(centre + reach)};
  }
  constexpr bool wraps() const { return lo > hi; }
  constexpr bool contains_hue(int h) const {
    return lo <= hi ? h >= lo && h <= hi : h >= lo || h <= hi;
  }
  // Steps up the circle from lo to `h` (0..179).
  constexpr int hue_offset(int h) const { return WrapHue(h - lo); }
  // Steps up the circle from lo to hi: 0 for one hue, 179 for all of them.
  constexpr int hue_span() const { return hue_offset(hi); }
  constexpr bool covers_all_hues() const { return hue_span() == kHueCycle - 1; }
  // The middle of the range on the circle (rounded down): 0 for {170, 10}.
  constexpr int hue_centre() const { return WrapHue(lo + hue_span() / 2); }
  // `slack` more hues each side; every hue when that closes the circle.
  constexpr HsvRange hue_widened(int slack) const {
    if (hue_span() + 2 * slack >= kHueCycle - 1) return {0, kHueCycle - 1};
    return {WrapHue(lo - slack), WrapHue(hi + slack)};
  }
};

}  // namespace softsight
