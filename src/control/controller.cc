#include "softsight/control/controller.h"
#include "softsight/core/format.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "control/control_options.h"
#include "control/model_loop.h"

namespace softsight {
namespace {

// The error's derivative on the measurement (bending, the angle decreasing, reduces the
// setpoint's rise), low-pass filtered over `filter_s`; 0 without a previous measurement.
double FilteredDerivative(double previous_deg_per_s, double measured_deg,
                          std::optional<double> last_measured_deg, double dt_s, double filter_s) {
  if (!last_measured_deg || !(dt_s > 0.0)) return 0.0;
  const double raw = -(measured_deg - *last_measured_deg) / dt_s;  // d(error)/dt at fixed target.
  const double a = filter_s > 0.0 ? dt_s / (filter_s + dt_s) : 1.0;
  double derivative = previous_deg_per_s;
  derivative += a * (raw - derivative);
  return derivative;
}

// The target's rate, for the lead (none across a jump, or before a previous target), and its
// acceleration (0 without two rates).
struct TargetMotion {
  std::optional<double> rate_deg_per_s;
  double accel_deg_per_s2 = 0.0;
};

TargetMotion MotionOf(double target_deg, std::optional<double> last_target_deg,
                      std::optional<double> last_rate_deg_per_s, double dt_s) {
  TargetMotion motion;
  if (last_target_deg && dt_s > 0.0) {
    motion.rate_deg_per_s = (target_deg - *last_target_deg) / dt_s;
    if (std::abs(*motion.rate_deg_per_s) > kStepRateDegPerS) motion.rate_deg_per_s.reset();
  }
  if (motion.rate_deg_per_s && last_rate_deg_per_s && dt_s > 0.0) {
    motion.accel_deg_per_s2 = (*motion.rate_deg_per_s - *last_rate_deg_per_s) / dt_s;
  }
  return motion;
}

// Anti-windup (conditional integration): the new integral is kept only when the output is not
// held back by a limit in the direction the error pushes it, and the error is within the
// integral band (when there is one).
bool KeepsIntegral(double error_deg, double limited_kpa, double wanted_kpa,
                   double integral_band_deg) {
  const bool pushing_up = error_deg > 0.0 && limited_kpa < wanted_kpa - 1e-9;
  const bool pushing_down = error_deg < 0.0 && limited_kpa > wanted_kpa + 1e-9;
  const bool outside_band = integral_band_deg > 0.0 && std::abs(error_deg) >= integral_band_deg;
  return !pushing_up && !pushing_down && !outside_band;
}

}  // namespace

bool ControllerOptions::Check(std::string* error) const {
  // Each field's range is its row in control/control_options.cc; only rules across fields here.
  if (const auto problem = CheckOptions(ControllerOptionsTable(), *this)) {
    return Fail(error, *problem);
  }
  if (!(max_kpa > min_kpa)) {
    return Fail(error, "max_kpa: " + RoundTripNumber(max_kpa) + " must be above min_kpa (" +
                           RoundTripNumber(min_kpa) + ")");
  }
  return true;
}

AngleController::AngleController(const ControllerOptions& options) : options_(options) {
  assert(options_.Check(nullptr));
}

AngleController::~AngleController() = default;

void AngleController::set_model(const ActuatorModel& model, double vent_scale) {
  model_loop_.reset();
  if (options_.model_inverse && model.identified()) {
    model_loop_ = std::make_unique<ModelLoop>(model, vent_scale, options_);
  }
}

void AngleController::observe_pressure(double pressure_kpa) {
  if (model_loop_) model_loop_->observe_pressure(pressure_kpa);
}

void AngleController::limit_max_kpa(double max_kpa) {
  // Never above the board's limit; ControlSession::start() refuses a min_kpa that is not below
  // it, so the range stays non-empty.
  options_.max_kpa = std::min(options_.max_kpa, max_kpa);
}

void AngleController::reset() {
  last_time_s_.reset();
  loss_start_s_.reset();
  last_measured_deg_.reset();
  last_target_deg_.reset();
  last_target_rate_.reset();
  last_input_deg_.reset();
  reference_deg_.reset();
  bend_direction_ = 1.0;
  integral_kpa_ = 0.0;
  derivative_deg_per_s_ = 0.0;
  setpoint_kpa_ = 0.0;
  vented_ = true;
  if (model_loop_) model_loop_->reset();
}

double AngleController::model_setpoint(double time_s, double target_deg,
                                       std::optional<double> measured_deg,
                                       const Preview& preview, double dt_s) {
  // Within the output limits and the slew limit from the last setpoint.
  double lo = options_.min_kpa, hi = options_.max_kpa;
  if (options_.max_rate_kpa_per_s > 0.0 && dt_s > 0.0) {
    const double step = options_.max_rate_kpa_per_s * dt_s;
    lo = std::clamp(setpoint_kpa_ - step, lo, hi);
    hi = std::clamp(setpoint_kpa_ + step, lo, hi);
  }
  const double setpoint =
      std::clamp(model_loop_->update(time_s, measured_deg, target_deg, preview, lo, hi), lo, hi);
  model_loop_->sent(setpoint);
  setpoint_kpa_ = setpoint;
  return setpoint;
}

ControllerOutput AngleController::update(double time_s, double target_deg_in,
                                         std::optional<double> measured_deg,
                                         const Preview& preview) {
  double target_deg = target_deg_in;  // Becomes the reference (below) when it is ramped.
  const double dt_s = last_time_s_ ? std::max(0.0, time_s - *last_time_s_) : 0.0;
  last_time_s_ = time_s;
  ControllerOutput out;

  if (!measured_deg) {
    // Hold the last setpoint with the integral frozen; vent once the loss lasts too long.
    last_measured_deg_.reset();  // No derivative across the gap.
    if (!loss_start_s_) loss_start_s_ = time_s;
    // Holding for hold_s means: the first frame without a measurement plus hold_s.
    if (!vented_ && time_s - *loss_start_s_ <= options_.hold_s + 1e-9) {
      out.action = ControllerOutput::Action::kHold;
      out.setpoint_kpa = setpoint_kpa_;
      // The model-based loop runs on its model meanwhile (its pressure is the board's sensed
      // one): a setpoint held in the middle of a step would overshoot it.
      if (model_loop_) out.setpoint_kpa = model_setpoint(time_s, target_deg, std::nullopt, preview, dt_s);
      return out;
    }
    vented_ = true;
    integral_kpa_ = 0.0;
    setpoint_kpa_ = 0.0;
    reference_deg_.reset();
    if (model_loop_) model_loop_->reset();
    out.action = ControllerOutput::Action::kVent;
    return out;
  }

  loss_start_s_.reset();
  vented_ = false;
  out.error_deg = *measured_deg - target_deg;
  if (model_loop_) {
    out.action = ControllerOutput::Action::kTrack;
    out.setpoint_kpa = model_setpoint(time_s, target_deg, measured_deg, preview, dt_s);
    return out;
  }
  // With a feed-forward the slew limit shapes the reference too: the loop follows a reference
  // that moves towards the target at most as fast as the slew limit lets the feed-forward move
  // (max_rate / ff deg/s), starting where the actuator is. So P and I act on the error from a
  // reachable reference: a step gives no proportional kick beyond the ramp and no wind-up.
  if (options_.ff_kpa_per_deg > 0.0 && options_.max_rate_kpa_per_s > 0.0) {
    if (!reference_deg_) reference_deg_ = *measured_deg;
    const double step = options_.max_rate_kpa_per_s / options_.ff_kpa_per_deg * dt_s;
    reference_deg_ = std::clamp(target_deg, *reference_deg_ - step, *reference_deg_ + step);
    target_deg = *reference_deg_;
  }
  const double error_deg = *measured_deg - target_deg;

  derivative_deg_per_s_ = FilteredDerivative(derivative_deg_per_s_, *measured_deg,
                                             last_measured_deg_, dt_s,
                                             options_.derivative_filter_s);
  last_measured_deg_ = measured_deg;

  // The target's last direction of motion (a smaller angle is more bend) selects the branch of
  // the hysteresis the actuator is on.
  if (last_target_deg_ && target_deg < *last_target_deg_) bend_direction_ = 1.0;
  if (last_target_deg_ && target_deg > *last_target_deg_) bend_direction_ = -1.0;
  const TargetMotion motion = MotionOf(target_deg_in, last_input_deg_, last_target_rate_, dt_s);
  const std::optional<double>& target_rate_deg_per_s = motion.rate_deg_per_s;
  const double target_accel_deg_per_s2 = motion.accel_deg_per_s2;
  last_target_deg_ = target_deg;
  last_input_deg_ = target_deg_in;
  last_target_rate_ = target_rate_deg_per_s;
  const double led_bend_deg = 180.0 - target_deg -
                              options_.ff_lead_s * target_rate_deg_per_s.value_or(0.0) -
                              options_.ff_lead2_s2 * target_accel_deg_per_s2;
  const double feedforward_kpa = options_.bias_kpa + options_.ff_kpa_per_deg * led_bend_deg +
                                 0.5 * options_.hysteresis_kpa * bend_direction_;
  const double pd_kpa = feedforward_kpa + options_.kp_kpa_per_deg * error_deg -
                        options_.kd_kpa_s_per_deg * derivative_deg_per_s_;
  const double candidate_integral =
      integral_kpa_ + options_.ki_kpa_per_deg_s * error_deg * dt_s;
  double wanted = pd_kpa + candidate_integral;

  // Output limits, then the slew limit from the previous setpoint.
  double limited = std::clamp(wanted, options_.min_kpa, options_.max_kpa);
  if (options_.max_rate_kpa_per_s > 0.0) {  // From the previous setpoint (0 at the start).
    const double step = options_.max_rate_kpa_per_s * dt_s;
    limited = std::clamp(limited, setpoint_kpa_ - step, setpoint_kpa_ + step);
  }
  if (KeepsIntegral(error_deg, limited, wanted, options_.integral_band_deg)) {
    integral_kpa_ = candidate_integral;
  }
  // The integral alone never needs to exceed the output range.
  integral_kpa_ = std::clamp(integral_kpa_, options_.min_kpa - options_.max_kpa,
                             options_.max_kpa - options_.min_kpa);
  setpoint_kpa_ = limited;
  out.action = ControllerOutput::Action::kTrack;
  out.setpoint_kpa = limited;
  return out;
}

}  // namespace softsight
