#include "softsight/control/control_config.h"

#include <algorithm>

#include "control/control_options.h"
#include "core/option_table.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"

namespace softsight {

bool ActuatorModel::Check(std::string* error) const {
  // Each field's range is its row in control/control_options.cc. No rule across fields: a model
  // is written whole by `softsight identify`, and a person editing one figure is not wrong.
  if (const auto problem = CheckOptions(ModelOptionsTable(), *this)) return Fail(error, *problem);
  return true;
}

double PressureForAngle(const ActuatorModel& model, double angle_deg) {
  if (!(model.slope_deg_per_kpa > 0.0)) return model.bend_start_kpa;
  return model.bend_start_kpa +
         std::max(0.0, model.straight_deg - angle_deg) / model.slope_deg_per_kpa;
}

ActuatorReach ReachOf(const ActuatorModel& model, double max_kpa) {
  ActuatorReach reach;
  reach.most_bent_deg = model.valid_min_deg;
  reach.straightest_deg = model.valid_max_deg;
  reach.up_to_kpa = model.valid_max_kpa;
  if (max_kpa < model.valid_max_kpa) {
    // A max_kpa lowered since the identification: no more bending than the static map gives there.
    reach.most_bent_deg = std::max(
        reach.most_bent_deg,
        model.straight_deg -
            model.slope_deg_per_kpa * std::max(0.0, max_kpa - model.bend_start_kpa));
    reach.up_to_kpa = max_kpa;
  }
  return reach;
}

std::optional<std::string> OutsideReach(const ActuatorModel& model, double lowest_deg,
                                        double highest_deg, double max_kpa) {
  if (!model.identified()) return std::nullopt;
  const double tolerance_deg = std::max(0.5, 2.0 * model.static_rms_deg);
  const ActuatorReach reach = ReachOf(model, max_kpa);
  const std::string range = FixedNumber(reach.most_bent_deg, 1) + ".." +
                            FixedNumber(reach.straightest_deg, 1) + " deg up to " +
                            FixedNumber(reach.up_to_kpa, 1) + " kPa";
  if (lowest_deg < reach.most_bent_deg - tolerance_deg) {
    const double needed_kpa = PressureForAngle(model, lowest_deg);
    const bool past_the_stop = model.saturation_kpa > 0.0 && needed_kpa > model.saturation_kpa;
    return FixedNumber(lowest_deg, 1) + " deg is beyond the actuator's reach: it bends to " + range +
           " (control.model, from `softsight identify`); " +
           (past_the_stop ? "it stops bending from " + FixedNumber(model.saturation_kpa, 1) +
                                " kPa, so no pressure gives " + FixedNumber(lowest_deg, 1) + " deg"
                          : FixedNumber(lowest_deg, 1) + " deg would need about " +
                                FixedNumber(needed_kpa, 1) + " kPa");
  }
  if (highest_deg > reach.straightest_deg + tolerance_deg) {
    return FixedNumber(highest_deg, 1) + " deg is straighter than the actuator gets when vented (" +
           FixedNumber(reach.straightest_deg, 1) + " deg; control.model: " + range + ")";
  }
  return std::nullopt;
}

bool ControlConfig::Check(std::string* error) const {
  // Each part checks its table and its own cross-field rules; the key gets the part's prefix.
  std::string problem;
  if (!controller.Check(&problem)) return Fail(error, "controller." + problem);
  if (!link.Check(&problem)) return Fail(error, "link." + problem);
  if (!inner_loop.Check(&problem)) return Fail(error, "inner_loop." + problem);
  if (!rig.Check(&problem)) return Fail(error, "rig." + problem);
  if (!model.Check(&problem)) return Fail(error, "model." + problem);
  return true;
}

}  // namespace softsight
