// The scene's static backdrop: a lab bench with real texture (a lighting gradient, soft blobs,
// fine grain), a dark cable and a few screws. Low-saturation throughout, so nothing in it passes
// a marker's HSV thresholds. Deterministic from the seed.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

namespace softsight::sim {

// Renders the backdrop at `supersample` x the size into `background_ss` and its area-averaged
// downsample into `background` (both CV_8UC3).
void RenderBackground(cv::Size size, int supersample, uint64_t seed, cv::Mat* background_ss,
                      cv::Mat* background);

// The same for a blotchy wood-like bench (BackgroundKind::kBench): wood grain, irregular dark,
// reddish, greenish and bluish patches (some as saturated as a marker, but large and ragged,
// never compact discs), two tape strips and a cable. Deterministic from the seed.
void RenderBenchBackground(cv::Size size, int supersample, uint64_t seed, cv::Mat* background_ss,
                           cv::Mat* background);

}  // namespace softsight::sim
