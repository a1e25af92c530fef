#include "softsight/control/control_config.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "control/control_options.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/core/option_table.h"

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

namespace {
// The identified rates are estimates: a segment is refused only past this share of its bound.
constexpr double kRateReachTolerance = 1.2;
}  // namespace

double MaxSineAmplitudeDeg(const ActuatorModel& model, double frequency_hz) {
  if (!model.identified() || model.inflate_kpa_per_s <= 0.0 || model.slope_deg_per_kpa <= 0.0 ||
      frequency_hz <= 0.0) {
    return std::numeric_limits<double>::infinity();
  }
  const double w = 2.0 * std::numbers::pi * frequency_hz;
  return 2.0 * model.slope_deg_per_kpa * model.inflate_kpa_per_s /
         (w * std::sqrt(1.0 + (w * model.lag_s) * (w * model.lag_s)));
}

std::optional<std::string> OutsideRateReach(const ActuatorModel& model,
                                            const TargetProfile& profile) {
  if (!model.identified() || model.inflate_kpa_per_s <= 0.0 || model.slope_deg_per_kpa <= 0.0) {
    return std::nullopt;
  }
  for (const TargetProfile::Segment& s : profile.segments()) {
    const std::string when = "at " + FixedNumber(s.start_s, 1) + " s";
    if (s.kind == TargetProfile::Segment::Kind::kRamp && s.duration_s > 0.0) {
      const double rate_deg_per_s = std::abs(s.to_deg - s.from_deg) / s.duration_s;
      const bool bending = s.to_deg < s.from_deg;  // 180 is straight: bending lowers the angle.
      const double kpa_per_s = bending ? model.inflate_kpa_per_s : model.vent_kpa_per_s;
      if (kpa_per_s <= 0.0) continue;
      const double most_deg_per_s = model.slope_deg_per_kpa * kpa_per_s;
      if (rate_deg_per_s > kRateReachTolerance * most_deg_per_s) {
        return "the ramp " + when + " (" + FixedNumber(s.from_deg, 1) + " to " +
               FixedNumber(s.to_deg, 1) + " deg at " + FixedNumber(rate_deg_per_s, 1) +
               " deg/s) is faster than the actuator: the " + (bending ? "pump raises" : "vent lowers") +
               " the pressure at most " + FixedNumber(kpa_per_s, 1) + " kPa/s, " +
               FixedNumber(most_deg_per_s, 1) + " deg/s (control.model)";
      }
    } else if (s.kind == TargetProfile::Segment::Kind::kSine && s.frequency_hz > 0.0) {
      const double most_deg = MaxSineAmplitudeDeg(model, s.frequency_hz);
      if (std::abs(s.amplitude_deg) <= kRateReachTolerance * most_deg) continue;
      // The highest frequency at which this swing is within the bound (it falls with frequency).
      double low = 0.0, high = s.frequency_hz;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (low + high);
        (MaxSineAmplitudeDeg(model, mid) >= std::abs(s.amplitude_deg) ? low : high) = mid;
      }
      return "the sine " + when + " (" + FixedNumber(std::abs(s.amplitude_deg), 1) + " deg at " +
             ShortNumber(s.frequency_hz) + " Hz) is faster than the actuator: the pump raises the "
             "pressure at most " + FixedNumber(model.inflate_kpa_per_s, 1) + " kPa/s, so at " +
             ShortNumber(s.frequency_hz) + " Hz it swings at most " + FixedNumber(most_deg, 1) +
             " deg, and " + FixedNumber(std::abs(s.amplitude_deg), 1) + " deg only up to " +
             FixedNumber(low, 2) + " Hz (control.model)";
    }
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
