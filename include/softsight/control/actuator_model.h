// What `softsight identify` learned about an actuator: the `control: model:` section of a config.
// Angles are the paper's angle at the middle marker (180 deg straight, smaller = more bent);
// pressures are gauge kPa. All zero (the default) means "not identified": nothing is written.
#pragma once

#include <optional>
#include <string>

#include "softsight/control/profile.h"

namespace softsight {

struct ActuatorModel {
  // Static map, pressure -> angle, from the steps up and down. Below bend_start_kpa the angle
  // stays at straight_deg; above it falls by slope_deg_per_kpa per kPa (the mean of the up and
  // down branches, which lie hysteresis_deg apart) until saturation_kpa, where it stops
  // (saturation_kpa 0: no saturation seen within the tested range).
  double straight_deg = 0.0;
  double bend_start_kpa = 0.0;
  double slope_deg_per_kpa = 0.0;
  double saturation_kpa = 0.0;
  double hysteresis_deg = 0.0;
  double static_rms_deg = 0.0;   // RMS residual of the static fit.
  // Valves -> sensed pressure, open loop (the inner-loop probe): the delay of a tube between them,
  // and the pressure rates of full inflation (near vented) and full venting (at about 25 % of the
  // experiment's ceiling).
  double valve_dead_time_s = 0.0;
  double inflate_kpa_per_s = 0.0;
  double vent_kpa_per_s = 0.0;
  double vent_at_kpa = 0.0;  // The pressure vent_kpa_per_s was measured at (an orifice: ~sqrt(p)).
  // Inner loop, pressure setpoint -> sensed pressure: first-order lag plus dead time.
  double pressure_lag_s = 0.0;
  double pressure_dead_time_s = 0.0;
  double pressure_rms_kpa = 0.0;  // RMS residual of that fit.
  // The same, as the board's loop works: a valve duty proportional to the pressure error,
  // saturating at full duty, times the probe's rates (inflation; venting ~ sqrt(p), times the
  // loop's vent scale): dp/dt = clamp(g (setpoint(t - dead) - p), -1, 1) * rate. A large chamber
  // is pump-limited on a large step, which a linear lag cannot say. The model-based loop
  // (ControllerOptions::model_inverse) inverts this one.
  double pressure_duty_per_kpa = 0.0;  // g; 0: not fitted.
  double pressure_duty_dead_time_s = 0.0;
  double pressure_duty_rms_kpa = 0.0;  // RMS residual of that fit.
  // Bending, sensed pressure -> angle: the static map (with its hysteresis) through a first-order
  // lag plus dead time (the camera's and the tracker's delay are in the dead time).
  double lag_s = 0.0;
  double dead_time_s = 0.0;
  double dynamic_rms_deg = 0.0;  // RMS residual of that fit.
  // The ranges the experiment covered: the model is valid within them only.
  double valid_min_kpa = 0.0;
  double valid_max_kpa = 0.0;
  double valid_min_deg = 0.0;
  double valid_max_deg = 0.0;
  // The tuning rule's closed-loop time constant (SIMC's tau_c) the gains were computed with.
  double closed_loop_s = 0.0;

  bool identified() const { return slope_deg_per_kpa > 0.0; }
  // Returns false and names the bad field.
  bool Check(std::string* error) const;
};

// The pressure the static map needs to hold `angle_deg` (on the mid line between the up and down
// branches): bend_start_kpa at straight_deg and above, then slope_deg_per_kpa per kPa.
double PressureForAngle(const ActuatorModel& model, double angle_deg);

// What the identification saw the actuator reach, as a run with output limit `max_kpa` can hold
// it: from the most bent angle (valid_min_deg, or less bending when max_kpa is below the
// pressure that gave it) to the straightest (valid_max_deg, vented).
struct ActuatorReach {
  double most_bent_deg = 0.0;
  double straightest_deg = 180.0;
  double up_to_kpa = 0.0;  // The pressure the most bent angle took.
};
ActuatorReach ReachOf(const ActuatorModel& model, double max_kpa);

// Nothing when every target in [lowest_deg, highest_deg] lies within ReachOf(model, max_kpa),
// with a tolerance of the larger of 0.5 deg and twice the static fit's residual; else the reason,
// one line naming the reachable range and the pressure the target would need, e.g. "120 deg is
// beyond the actuator's reach: it bends to 130.25..180 deg up to 45 kPa (...); 120 deg would
// need about 48.4 kPa". A model not identified reaches everything.
std::optional<std::string> OutsideReach(const ActuatorModel& model, double lowest_deg,
                                        double highest_deg, double max_kpa);

// Nothing when the actuator can move as fast as every ramp and sine of `profile` asks; else the
// first segment it cannot follow, in one line with what it can do. The pump raises the pressure
// at most inflate_kpa_per_s and the vent lowers it at most vent_kpa_per_s, so a ramp bends at
// most slope * inflate deg/s (straightens at most slope * vent), and a sine's swing at angular
// frequency w is at most 2 slope inflate / (w sqrt(1 + (w lag)^2)) deg (the first harmonic of a
// sawtooth rising at the pump's rate, vented at once, behind the bending lag): a bound no
// controller beats. The identified rates carry error: only a segment asking 20 % more than the
// bound is refused. Steps are never refused (they take the time they take). A model not
// identified, or without the rates, reaches everything.
std::optional<std::string> OutsideRateReach(const ActuatorModel& model,
                                            const TargetProfile& profile);
// The largest sine swing (deg) the actuator can follow at `frequency_hz` (the bound above);
// infinite for a model without the rates.
double MaxSineAmplitudeDeg(const ActuatorModel& model, double frequency_hz);

}  // namespace softsight
