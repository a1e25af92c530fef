// The marker config a person would write for the renderer's default bending scene (red, blue and
// green markers, base to tip), shared by the pipeline's tests (test code only).
#pragma once

#include <string>

#include "softsight/config/config.h"
#include "softsight/sim/scene.h"
#include "softsight/track/colour_tracker.h"

namespace softsight::testing {

// A colour marker: `hue` (OpenCV 0..179, wrapping when lo > hi), any strong saturation (>= 80)
// and brightness (>= 40).
inline MarkerSpec ColourMarker(const std::string& name, HsvRange hue) {
  MarkerSpec spec;
  spec.name = name;
  ColourParams& colour = spec.params.get<ColourParams>();
  colour.h = hue;
  colour.s = {80, 255};
  colour.v = {40, 255};
  return spec;
}

// Red, blue and green, measured as the paper's base, middle and tip.
inline TrackingConfig ThreeMarkerSceneConfig() {
  TrackingConfig config;
  config.markers = {ColourMarker("red", {170, 10}), ColourMarker("blue", {100, 130}),
                    ColourMarker("green", {45, 85})};
  config.measure.base = "red";
  config.measure.middle = "blue";
  config.measure.tip = "green";
  return config;
}

// The default bending scene, small (320x240, 6 px markers) so a run of many frames is quick.
inline SceneOptions SmallScene(int frames) {
  SceneOptions scene;
  scene.size = {320, 240};
  scene.length_px = 150;
  scene.width_px = 24;
  scene.marker_radius_px = 6;
  scene.frame_count = frames;
  scene.max_bend_deg = 120;
  return scene;
}

}  // namespace softsight::testing
