// Damage an intra-only decoder conceals without a word: its picture is whole but, from the row
// where a flipped bit put it out of step, wrong. HuffYUV predicts each pixel from the ones
// decoded before it, so a wrong residual offsets one colour of every pixel after it (and a
// lost code shifts them sideways as well); Motion JPEG codes each block's DC level as a
// difference from the block before, so a flipped value bit offsets the brightness (or one colour)
// of every block after it. Either way the frame, compared with the frame before it, splits at
// one row: on one side (what was decoded before the damage) it matches; on the other, up to the
// frame's edge, nearly every sample moved the same way at once, sharply at that row. A marker
// in that band, or cut by its edge, is measured at a wrong place (3-4 px off in the hostile
// trial's HuffYUV sweep, issue 44 D10).
//
// What real footage does not do: the light changes the whole frame (the exposure), or changes
// it smoothly along the rows (a rolling shutter under mains light, whose bands have no clean
// rest and no sharp edge), and what moves (the actuator) covers part of a row, not all of it.
//
// The check looks at a sample every 4 px of every other row, each row's share of samples that
// got brighter or darker, per colour, by 2 levels or more; a frame whose first and last rows
// did not change so is done with there (0.07 ms a VGA frame). A frame
// is damaged when such a band runs from the top or the bottom edge, against the frame before
// and, when the frame before was judged damaged, the same band against the last frame not
// judged damaged (the frame after a damaged one differs from it by that one's band, and from an
// earlier frame with damage too small to judge by that frame's band, but not by one band twice).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

class DamagedBand {
 public:
  // Whether `bgr` (CV_8UC3) is damaged by such a band, or `known_damaged` (the decoder said so:
  // the frame is not compared, nor compared with); call once per frame, in order. Any other
  // type, or a frame of another size, starts afresh (not damaged).
  bool damaged(const cv::Mat& bgr, bool known_damaged = false);
  // Forgets the frames seen (after a seek, the next frame has no neighbour to compare with).
  void reset() { has_previous_ = false; }

 private:
  void sample(const cv::Mat& bgr, cv::Mat& out) const;
  // Per colour: (samples brighter - samples darker) / samples, of sampled row `row`.
  cv::Vec3f row_share(const cv::Mat& now, const cv::Mat& before, int row);
  // The median difference of sampled row `row`'s colour `colour` (0 blue, 1 green, 2 red).
  float row_offset(const cv::Mat& now, const cv::Mat& before, int row, int colour);
  // The damaged band `now` shows against `before`: the sampled rows it covers from the top
  // edge (positive) or from the bottom edge (negative); 0 for none.
  int band_against(const cv::Mat& now, const cv::Mat& before);

  cv::Mat now_, previous_, clean_;  // Samples (rows x columns x BGR); reused, swapped.
  bool has_previous_ = false;
  bool previous_damaged_ = false;
  // Per sampled row and colour: (samples brighter - samples darker) / samples.
  std::vector<cv::Vec3f> shares_;
  std::vector<float> scratch_, offsets_;  // For medians.
};

}  // namespace softsight
