// A pixel's chromaticity: B, G, R over their sum, which hardly changes with the light's strength
// (a side light shades a domed marker from bright to dark across its face; its chromaticity
// stays). Near-black pixels' ratios are noise: the sum is damped by kChromaDarkLevels, so they
// count as dark grey. Shared by the template trackers' chromaticity blob and the colour
// trackers' contrast in chromaticity.
#pragma once

#include <opencv2/core.hpp>

namespace softsight {

inline constexpr double kChromaDarkLevels = 30.0;

inline cv::Vec3d Chromaticity(double b, double g, double r) {
  const double scale = 1.0 / (b + g + r + kChromaDarkLevels);
  return {b * scale, g * scale, r * scale};
}

}  // namespace softsight
