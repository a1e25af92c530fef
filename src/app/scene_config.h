// The marker configuration a person would write for a rendered scene, shared by `softsight demo`,
// `softsight evaluate` and `softsight serve` so all use the trackers with the same settings.
#pragma once

#include <opencv2/core.hpp>

#include <string>

#include "softsight/config/config.h"
#include "softsight/sim/scene.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {

// HSV thresholds a person would pick for a saturated marker colour: its hue +-12 (wrapping around
// 0 for red), any strong saturation (>= 80) and brightness (>= 40). No pre-filter: the caller
// adds one to suit the noise it expects.
ColourParams ThresholdsFor(const cv::Vec3b& bgr);

// The marker config a person would write for a rendered actuator scene: each marker's colour by
// ThresholdsFor with a light smoothing (the scenes carry sensor noise), the scene's measurements,
// 0.25 mm per pixel (as if the camera saw the actuator's plane so).
TrackingConfig ConfigForScene(const SceneOptions& scene);

// For a command given no --config: when `input` is a rendered actuator scene (synth:NAME), the
// path of its config in `folder` (<folder>/synth-NAME.yaml), written there by ConfigForScene
// unless that file exists already (a config saved from an earlier run is kept and used).
// Throws InputError naming --config for any other input.
std::string ConfigForBuiltinInput(const std::string& input, const std::string& folder);

}  // namespace softsight
