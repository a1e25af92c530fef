// The built-in rendered scenes, by the names `synth:NAME` inputs use. One table, so every tool
// that opens a built-in scene offers the same ones.
#pragma once

#include <string>
#include <variant>

#include "softsight/sim/plate_scene.h"
#include "softsight/sim/scene.h"

namespace softsight {

// "bending", "wedge1", "wedge4": the actuator scenes on the default backdrop.
// "bench": the bending scene on the textured bench (BackgroundKind::kBench) with the marker
//   distractors of MakeMarkerDistractors, no roi needed to be hard.
// "plate": the plate scene (gray, five white dots, tilting to 50 degrees and scaling 1x to 2x).
using BuiltinSceneOptions = std::variant<SceneOptions, PlateSceneOptions>;

// Throws InputError naming the scene and listing the choices.
BuiltinSceneOptions ParseBuiltinScene(const std::string& name);

// Makes `scene` the named actuator scene ("bending", "wedge1", "wedge4" or "bench") while keeping
// its size, timing, body and seed: sets the kind, and for "bench" the textured bench and the
// marker distractors, which depend on everything else, so call it when the rest is final.
// Throws InputError listing the actuator scenes.
void SetActuatorScene(const std::string& name, SceneOptions* scene);
// "bending, wedge1, wedge4, bench or plate", for messages and help texts.
const char* BuiltinSceneNames();

}  // namespace softsight
