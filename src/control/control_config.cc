#include "softsight/control/control_config.h"

#include "control/control_options.h"
#include "core/option_table.h"

namespace softsight {

bool ActuatorModel::Check(std::string* error) const {
  // Each field's range is its row in control/control_options.cc. No rule across fields: a model
  // is written whole by `softsight identify`, and a person editing one figure is not wrong.
  if (const auto problem = CheckOptions(ModelOptionsTable(), *this)) return Fail(error, *problem);
  return true;
}

bool ControlConfig::Check(std::string* error) const {
  // Each part checks its table and its own cross-field rules; the key gets the part's prefix.
  std::string problem;
  if (!controller.Check(&problem)) return Fail(error, "controller." + problem);
  if (!link.Check(&problem)) return Fail(error, "link." + problem);
  if (!rig.Check(&problem)) return Fail(error, "rig." + problem);
  if (!model.Check(&problem)) return Fail(error, "model." + problem);
  return true;
}

}  // namespace softsight
