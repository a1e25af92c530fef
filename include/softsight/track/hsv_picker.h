// HSV ranges from pixels a person points at: click a marker in the live window and its colour
// tracker gets H, S and V ranges from the pixels around the click.
//
// Robust statistics: the range is the [low, high] percentile interval of each channel widened by
// a margin, so a few background pixels at the disc's rim do not stretch it. Hue is circular
// (OpenCV's 8-bit hue runs 0..179): the percentiles are taken around the circular mean, so a red
// marker straddling 0 gives a wrapped range with lo > hi (e.g. {172, 8}).
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "softsight/track/colour_tracker.h"

namespace softsight {

struct HsvPickOptions {
  // Radius of the disc of pixels sampled around the click, px. Default 5 (97 pixels). Larger is
  // steadier on noisy video but must stay inside the marker.
  int radius_px = 5;
  // Percentiles bounding the sampled values, in percent. Default 5 / 95: up to 5 % of the
  // samples on either side (rim pixels, specular highlights) do not widen the range.
  double low_percentile = 5.0;
  double high_percentile = 95.0;
  // Margins added on each side of the percentile interval, in 8-bit HSV units. Wider tolerates
  // more lighting change, narrower rejects more of the background. Defaults 6 / 40 / 50.
  int hue_margin = 6;
  int saturation_margin = 40;
  int value_margin = 50;
  // Value (brightness) scales with the light, hue and saturation do not: the value range reaches
  // down to this fraction of the sampled values (or value_margin below them, whichever is lower)
  // and up to 255, so the marker stays in range while its light falls to this fraction (a cloud,
  // a lamp switched off, the camera's exposure) or rises. The tracker's learned model tells the
  // marker from a look-alike of the same hue in another light. Default 0.4; 1 keeps the margin only.
  double darkest_light = 0.4;
  // Pixels less saturated than this have no meaningful hue; they do not vote for the hue range.
  // A patch where fewer than half the pixels reach it is not a coloured marker. Default 40. It is
  // also the range's saturation floor, except for a pale marker on paler surroundings
  // (PickHsvRange).
  int min_saturation = 40;

  // Returns true when every field is usable; otherwise false with `error` naming the field.
  bool Check(std::string* error) const;
};

struct HsvPick {
  // Ready for ColourParams (h.lo > h.hi when the range wraps through 0).
  HsvRange h{}, s{}, v{};
  // A white or black dot (PickHsvRange on a patch without colour that stands out from its
  // surroundings by its gray level): the gray-level range (ColourParams::gray) halfway between
  // the dot's levels and its surroundings', open towards white (or black). h, s, v are then the
  // full ranges.
  int sample_count = 0;     // Pixels sampled inside the image.
  double hue_spread = 0.0;  // Width of the hue percentile interval before margins, hue units.
  std::optional<HsvRange> gray{};
  // Where the pixels were sampled (PickHsvRange): the click, or, for a click off a coloured
  // marker's centre, the centre of the blob the first pick gives through it.
  cv::Point2d sampled_at_px{};
};

// Picks ranges from HSV samples (CV_8UC3 pixels as produced by cv::cvtColor(BGR2HSV)). Returns
// nothing, with `why_not` saying why, when there are no samples or they are not coloured.
std::optional<HsvPick> PickHsvFromSamples(const std::vector<cv::Vec3b>& hsv_samples,
                                          const HsvPickOptions& options,
                                          std::string* why_not = nullptr);

// Picks ranges from the disc of `options.radius_px` around `click_px` (pixel-centre convention)
// in a BGR image. Pixels outside the image are skipped. A patch without colour is a white or
// black dot when its gray levels (10th to 90th percentile) all lie at least 20 above (or below)
// those of a ring 3 to 6 px outside the disc: the pick is then a gray-level range. A pale
// marker clicked more than 2 px off its centre is sampled again at the centre of the blob the
// first pick gives through the click (its rim and surroundings would widen the ranges). A pale
// marker whose saturation reaches min_saturation gets a lower floor (down to 16) when its
// surroundings are paler still and the floor cut a part of it off (a dome's whitened top): the
// saturation floor then lies a third of the way from the surroundings' to the marker's.
std::optional<HsvPick> PickHsvRange(const cv::Mat& bgr, cv::Point2d click_px,
                                    const HsvPickOptions& options, std::string* why_not = nullptr);

// What a click on a marker in `live` gives, and `softsight pick` reproduces: the ranges picked
// from the pixels around the click (PickHsvRange) and the square search box of `box_side_px`
// centred where the pixels were sampled (the click, or the marker's centre; clipped to the
// image), where the colour tracker looks for the marker first.
struct MarkerColourPick {
  HsvPick ranges{};
  cv::Rect roi{};
};

std::optional<MarkerColourPick> PickMarkerColourAt(const cv::Mat& bgr, cv::Point2d click_px,
                                                   const HsvPickOptions& options,
                                                   int box_side_px,
                                                   std::string* why_not = nullptr);

// Makes `colour` track the picked colour: its h, s, v ranges and roi become the pick's, and an
// automatic colour or gray-level range it had is dropped (the pick replaces them); a white or
// black dot's pick sets the gray-level range.
void ApplyColourPick(const MarkerColourPick& pick, ColourParams* colour);

// A colour name for an 8-bit hue (0..179): red, orange, yellow, green, cyan, blue, purple,
// magenta. Used to name the markers `init` and `pick` write.
const char* HueName(int hue);
// The name `init` and `pick` give a picked marker: the hue's name, or "white" / "black".
std::string PickName(const HsvPick& pick);

// True when an 8-bit HSV pixel lies inside the three ranges (hue wrap included). The reference the
// tests and the live window's preview use; the colour tracker has its own vectorised threshold.
bool HsvInRange(const cv::Vec3b& hsv, const HsvRange& h, const HsvRange& s, const HsvRange& v);

}  // namespace softsight
