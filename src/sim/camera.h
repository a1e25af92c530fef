// The simulated camera applied to a rendered frame: optics (blur), illumination (gain), then
// sensor noise. Shared by every scene so NoiseOptions mean the same everywhere.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "softsight/sim/scene.h"

namespace softsight::sim {

// Per-frame noise stream: a function of (seed, frame), so frames can be rendered in any order.
uint64_t Mix(uint64_t seed, uint64_t index);

// The illumination gain of frame `index`: gain_start ramping linearly to gain_end.
double GainAt(const NoiseOptions& noise, int index, int frame_count);

// Blur, gain and noise on `image` (CV_8UC1 or CV_8UC3) in place; `noise_buffer` is scratch.
void ApplyCamera(const NoiseOptions& noise, double gain, int index, cv::Mat& image,
                 cv::Mat& noise_buffer);

}  // namespace softsight::sim
