#include "softsight/sim/builtin_scenes.h"

#include "softsight/core/error.h"

namespace softsight {

BuiltinSceneOptions ParseBuiltinScene(const std::string& name) {
  if (name == "plate") return PlateSceneOptions{};
  if (name == "bending" || name == "wedge1" || name == "wedge4" || name == "bench") {
    SceneOptions scene;
    SetActuatorScene(name, &scene);
    return scene;
  }
  throw InputError("unknown scene '" + name + "' (choose " + BuiltinSceneNames() + ")");
}

void SetActuatorScene(const std::string& name, SceneOptions* scene) {
  if (name == "bench") {
    scene->kind = SceneKind::kBending;
    scene->background = BackgroundKind::kBench;
    scene->distractors = MakeMarkerDistractors(*scene, scene->seed);
    return;
  }
  if (name == "bending" || name == "wedge1" || name == "wedge4") {
    scene->kind = ParseSceneKind(name);
    return;
  }
  throw InputError("unknown scene '" + name + "' (choose bending, wedge1, wedge4 or bench)");
}

const char* BuiltinSceneNames() { return "bending, wedge1, wedge4, bench or plate"; }

}  // namespace softsight
