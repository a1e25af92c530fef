#include "softsight/sim/builtin_scenes.h"

#include "softsight/core/error.h"

namespace softsight {

BuiltinSceneOptions ParseBuiltinScene(const std::string& name) {
  if (name == "plate") return PlateSceneOptions{};
  SceneOptions scene;
  if (name == "bench") {
    scene.background = BackgroundKind::kBench;
    scene.distractors = MakeMarkerDistractors(scene, scene.seed);
    return scene;
  }
  if (name == "bending" || name == "wedge1" || name == "wedge4") {
    scene.kind = ParseSceneKind(name);
    return scene;
  }
  throw InputError("unknown scene '" + name + "' (choose " + BuiltinSceneNames() + ")");
}

const char* BuiltinSceneNames() { return "bending, wedge1, wedge4, bench or plate"; }

}  // namespace softsight
