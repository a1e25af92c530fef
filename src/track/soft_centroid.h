// The soft centroid, shared by every tracker that measures a blob: each pixel near the blob's
// edge weighs by its membership, how far its value lies from the local background (0) towards
// the marker's core (1) along the line through them, so a pixel half covered by the marker
// counts half. On an anti-aliased or slightly blurred disc this is several times more accurate
// than counting pixels in or out (colour_verification_test: SoftCentroidAccuracy...).
#pragma once

#include <algorithm>
#include <cstdint>

namespace softsight::track_internal {

// Membership of `pixel` (`channels` values) between `background` and `core`. Within `deadband`
// of either end it is 0 or 1 (sensor noise on the background or the core must not move the
// centroid); in between, the fraction, stretched to 0..1. When background and core are too alike
// to tell (squared distance <= 1), `inside_when_alike` decides.
inline double Membership(const uint8_t* pixel, int channels, const double* background,
                         const double* core, double deadband, bool inside_when_alike) {
  double num = 0, den = 0;
  for (int k = 0; k < channels; ++k) {
    const double d = core[k] - background[k];
    num += (pixel[k] - background[k]) * d;
    den += d * d;
  }
  if (!(den > 1.0)) return inside_when_alike ? 1.0 : 0.0;
  return std::clamp((num / den - deadband) / (1.0 - 2.0 * deadband), 0.0, 1.0);
}

}  // namespace softsight::track_internal
