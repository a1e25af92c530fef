// The model-based outer loop (ControllerOptions::model_inverse): the identified actuator
// (ActuatorModel) run alongside the real one and inverted, frame by frame.
//
// The model: the board's pressure loop as it works (a duty proportional to the pressure error,
// saturating at full duty, times the probe's inflation rate or its venting rate ~ sqrt(p), after
// the loop's dead time), the static map with its play (hysteresis) and the bending lag. Its
// pressure is reset to the board's sensed pressure in every answer, so only the bending is the
// model's own; the measured angle minus the model's angle (low-passed) is the model's error,
// taken off the target the loop inverts (internal model control: no offset, no wind-up, since
// the model is driven by what was sent).
//
// Each frame's setpoint: the bend the target asks for at the frame's end plus the dead times
// (the profile is known ahead: the look-ahead compensates them), led by the bending lag, plus
// the model's gap to the target closed over three frames (or twice the dead times), with half
// the hysteresis on the side the model's play must move, through the static map's inverse to a
// pressure; then
// the setpoint that takes the model's pressure there by the frame's end (bisection through the
// pump- and vent-limited inner loop). While the model lags the target by more than kJumpDeg
// (after a step), full pressure or none instead, as long as the model predicts that switching
// to the target's pressure in the next frame does not overshoot it: the fastest approach the
// pump and the vent allow.
#pragma once

#include <deque>
#include <optional>
#include <utility>

#include "softsight/control/actuator_model.h"
#include "softsight/control/controller.h"

namespace softsight {

class ModelLoop {
 public:
  // The model must be identified (slope > 0). `vent_scale`: the board loop's venting duty factor.
  ModelLoop(const ActuatorModel& model, double vent_scale, const ControllerOptions& options);

  // The setpoint for the frame at `time_s`, within [lo_kpa, hi_kpa] (the output and slew limits
  // from the last setpoint), given the measured angle and the target ahead (`preview`, or the
  // constant `target_deg`).
  // Without a measurement (markers lost) the model runs on with its last error; it must have
  // started with one.
  double update(double time_s, std::optional<double> measured_deg, double target_deg,
                const AngleController::Preview& preview, double lo_kpa, double hi_kpa);
  // The setpoint actually sent for the frame just decided (after the caller's clamps).
  void sent(double setpoint_kpa);
  void observe_pressure(double pressure_kpa);
  void reset();

  // A model lagging its target by more than this is catching up with a step.
  static constexpr double kJumpDeg = 1.0;
  // The overshoot a full-pressure frame may leave in the model's prediction.
  static constexpr double kOvershootDeg = 0.2;

 private:
  struct State {
    double time_s = 0.0;
    double p = 0.0;     // Chamber pressure, kPa.
    double play = 0.0;  // The play operator's output, deg of angle.
    double d = 0.0;     // Deflection (straight - angle), deg.
  };
  // dp/dt of the board's loop at pressure p with setpoint u.
  double pressure_rate(double p, double u) const;
  // Advances `s` to `to_s`; `command(t)` is the setpoint sent at time t (before the dead time).
  template <typename Command>
  void advance(State* s, double to_s, const Command& command) const;
  double sent_at(double time_s) const;  // From the history of setpoints.
  double static_pressure(double deflection_deg, double direction) const;
  // update()'s first step: the model against this frame's measurement.
  void follow_measurement(double time_s, std::optional<double> measured_deg);

  // The model.
  double straight_, p0_, k_, sat_, half_, tau_b_, theta_b_, g_, theta_p_, inflate_, vent_,
      vent_at_;
  double correction_s_;
  double max_rate_;
  // The state.
  bool started_ = false;
  State state_;
  double frame_s_ = 1.0 / 30.0;
  double correction_ = 0.0;
  double direction_ = 1.0;
  double initial_u_ = 0.0;
  std::deque<std::pair<double, double>> sent_;       // (time, setpoint)
  std::deque<std::pair<double, double>> deflection_;  // (time, d), for the bending dead time
};

}  // namespace softsight
