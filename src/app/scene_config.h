// The marker configuration a person would write for a rendered scene, shared by `softsight demo`
// and `softsight evaluate` so both measure the trackers with the same settings.
#pragma once

#include <opencv2/core.hpp>

#include "softsight/track/colour_tracker.h"

namespace softsight {

// HSV thresholds a person would pick for a saturated marker colour: its hue +-12 (wrapping around
// 0 for red), any strong saturation (>= 80) and brightness (>= 40). No pre-filter: the caller
// adds one to suit the noise it expects.
ColourParams ThresholdsFor(const cv::Vec3b& bgr);

}  // namespace softsight
