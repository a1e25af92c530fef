#include "softsight/control/control_config.h"

#include "core/option_table.h"

namespace softsight {

bool ControlConfig::Check(std::string* error) const {
  // Each part checks its table and its own cross-field rules; the key gets the part's prefix.
  std::string problem;
  if (!controller.Check(&problem)) return Fail(error, "controller." + problem);
  if (!link.Check(&problem)) return Fail(error, "link." + problem);
  if (!rig.Check(&problem)) return Fail(error, "rig." + problem);
  return true;
}

}  // namespace softsight
