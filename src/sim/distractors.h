// Distractors on a cached backdrop, shared by the actuator and plate scenes.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/sim/scene.h"

namespace softsight::sim {

// Empty when every distractor has a finite centre and angle and positive radii, else the
// message naming the first bad one.
std::string CheckDistractors(const std::vector<Distractor>& distractors);

// Draws them into the supersampled backdrop and recomputes its downsample `background`.
void DrawDistractors(const std::vector<Distractor>& distractors, int supersample,
                     cv::Mat& background_ss, cv::Mat& background);

}  // namespace softsight::sim
