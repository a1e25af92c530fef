#include "softsight/control/control_config.h"

namespace softsight {

bool ControlConfig::Check(std::string* error) const {
  std::string problem;
  if (!controller.Check(&problem)) {
    if (error) *error = "controller." + problem;
    return false;
  }
  if (!link.Check(&problem)) {
    if (error) *error = "link." + problem;
    return false;
  }
  if (!rig.Check(&problem)) {
    if (error) *error = "rig." + problem;
    return false;
  }
  return true;
}

}  // namespace softsight
