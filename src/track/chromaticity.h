// A pixel's chromaticity: B, G, R over their sum, which hardly changes with the light's strength
// (a side light shades a domed marker from bright to dark across its face; its chromaticity
// stays). Near-black pixels' ratios are noise: the sum is damped by kChromaDarkLevels, so they
// count as dark grey. Shared by the template trackers' chromaticity blob and the colour
// trackers' contrast in chromaticity.
#pragma once

#include <array>
#include <cstddef>

#include <opencv2/core.hpp>

namespace softsight {

inline constexpr double kChromaDarkLevels = 30.0;

inline cv::Vec3d Chromaticity(double b, double g, double r) {
  const double scale = 1.0 / (b + g + r + kChromaDarkLevels);
  return {b * scale, g * scale, r * scale};
}

// The same of 8-bit levels, bit for bit, without a division a pixel: the scale of each sum of
// levels (0..765) computed once by the same expression (the sum of three levels is exact in a
// double, so b + g + r + kChromaDarkLevels is the same double either way).
// The table: entry i is the scale of the sum of levels i (0..765).
inline const std::array<double, 766>& ChromaticityScales() {
  static const std::array<double, 766> scales = [] {
    std::array<double, 766> s{};
    for (int i = 0; i < 766; ++i) s[i] = 1.0 / (static_cast<double>(i) + kChromaDarkLevels);
    return s;
  }();
  return scales;
}

inline cv::Vec3d ChromaticityOfLevels(int b, int g, int r) {
  const double scale = ChromaticityScales()[static_cast<size_t>(b + g + r)];
  return {b * scale, g * scale, r * scale};
}

}  // namespace softsight
