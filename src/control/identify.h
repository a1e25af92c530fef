// System identification of a pneumatic bending actuator, and outer-loop gains from the model.
//
// The experiment (IdentificationExperiment) chooses one pressure setpoint per camera frame, open
// loop, never above its ceiling:
//   1. baseline: vented until the angle is steady (the straight angle), then the inner-loop probe
//      (control/inner_loop_probe.h: full inflation, valves closed, full venting, open loop), whose
//      tube delay decides the gains the board's pressure loop gets for the rest (InnerLoopGainsFor);
//   2. steps up: `levels` equal pressure steps to the ceiling, each held until the angle is steady;
//   3. steps down the same levels to 0 (the second branch of the hysteresis);
//   4. PRBS: a pseudo-random binary sequence (31 bits of a 5-bit shift register) of +-amplitude
//      around a working point in the middle of the linear part of the static map.
// It aborts (throws IdentifyAbort, one line) when the markers stay lost, the sensed pressure goes
// above the ceiling, the pressure does not follow the setpoint, or the angle does not respond; the
// caller's ControlSession then vents (STOP).
//
// The fit (FitActuatorModel) gives the static map from the steps (bend start, slope, saturation,
// hysteresis width from the two branches), the inner loop's response (setpoint -> sensed pressure:
// first-order lag plus dead time) and the bending dynamics (sensed pressure -> static map with its
// hysteresis -> first-order lag plus dead time -> angle) from the PRBS, each by least squares, with
// its RMS residual and the ranges it was fitted over.
//
// The gains (TuneController) follow Skogestad's SIMC rule for a PI controller on the first-order
// plus dead time model of setpoint -> angle (S. Skogestad, "Simple analytic rules for model
// reduction and PID controller tuning", J. Process Control 13 (2003) 291-309):
//   the two lags by the half rule: tau = tau1 + tau2 / 2, theta = theta_p + theta_b + tau2 / 2
//     + half a camera period (the controller acts once per frame);
//   kp = tau / (K (tau_c + theta)),  ki = kp / min(tau, 4 (tau_c + theta)),
// with tau_c the chosen closed-loop time (default: the measured dead times plus half a camera
// period, at least three camera periods), K the static slope; the
// feed-forward from the static map (bias_kpa = bend start, ff_kpa_per_deg = 1 / K), its lead
// (ff_lead_s = the lags and dead times, ff_lead2_s2 = the product of the two lags: the inverse of
// both) and the hysteresis compensation (hysteresis_kpa = hysteresis width / K) do most of the
// work; the PI removes what the model misses, integrating only within 3 deg of the reference
// (integral_band_deg), so it does not wind up on the transient the feed-forward answers.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "control/inner_loop_probe.h"
#include "softsight/control/actuator_model.h"
#include "softsight/control/controller.h"
#include "softsight/control/session.h"
#include "softsight/core/error.h"

namespace softsight {

struct IdentifyOptions {
  int levels = 8;                   // Pressure steps from 0 to the ceiling (and back).
  double min_hold_s = 0.6;          // Each step is held at least this long ...
  double max_hold_s = 4.0;          // ... and at most this long,
  double steady_deg = 0.2;          // ... until the angle moved less than this
  double steady_window_s = 0.3;     //     over this long.
  double prbs_bit_s = 0.3;          // Length of one PRBS bit.
  double prbs_amplitude = 0.12;     // PRBS +-amplitude, fraction of the linear pressure range.
  double lost_s = 0.3;              // Markers missing this long: abort.
  double min_response_deg = 3.0;    // Less angle change than this at half the ceiling: abort.
  double over_ceiling_kpa = 2.0;    // Sensed pressure this far above the ceiling: abort.
  std::optional<double> closed_loop_s;  // SIMC tau_c; default max(dead times, 3 camera periods).
};

// Why the experiment stopped early: one line, for the user.
class IdentifyAbort : public InputError {
 public:
  using InputError::InputError;
};

struct IdentifySample {
  double time_s = 0.0;
  std::optional<double> angle_deg;  // Measured in this frame.
  double setpoint_kpa = 0.0;        // Sent in this frame (0 while the probe drives the valves).
  std::optional<double> duty;       // Sent in this frame instead, by the inner-loop probe.
  int64_t board_time_ms = 0;        // The board's clock in its answer.
  double pressure_kpa = 0.0;        // The board's sensed pressure in its answer.
  int phase = 0;                    // IdentificationExperiment::Phase.
};

struct StaticPoint {
  double pressure_kpa = 0.0;  // Mean sensed pressure over the steady window.
  double angle_deg = 0.0;     // Mean angle over the steady window.
  bool up = true;             // Branch: reached from below (up) or from above (down).
};

class IdentificationExperiment {
 public:
  // (kInnerLoop runs between the baseline and the steps; numbered last so that the numbers the
  // CSV's identify_phase column had keep their meaning.)
  enum Phase { kBaseline = 0, kStepsUp = 1, kStepsDown = 2, kPrbs = 3, kDone = 4, kInnerLoop = 5 };

  // `ceiling_kpa`: the highest setpoint the experiment sends (the caller takes it below the
  // controller's max_kpa and the board's limit). Throws InputError when it is not positive.
  IdentificationExperiment(const IdentifyOptions& options, double ceiling_kpa);

  // The setpoint to send for the frame at `time_s` whose angle is `angle_deg` (absent: markers
  // not found); while duty() is given, that valve duty is sent instead. Throws IdentifyAbort.
  // After the last phase: 0 and done().
  double next(double time_s, std::optional<double> angle_deg);
  // The valve duty of this frame while the inner-loop probe drives the valves, else nothing.
  std::optional<double> duty() const { return duty_; }
  // The gains for the board's inner loop the probe has just chosen, once (the caller sends them
  // before this frame's command); nothing in every other frame.
  std::optional<InnerLoopGains> take_gains_to_send();
  // The board's answer to that command (its sensed pressure and its clock). Throws IdentifyAbort
  // when the pressure is above the ceiling by more than over_ceiling_kpa.
  void answered(double pressure_kpa, int64_t board_time_ms = 0);

  bool done() const { return phase_ == kDone; }
  Phase phase() const { return phase_; }
  double ceiling_kpa() const { return ceiling_kpa_; }
  const std::vector<IdentifySample>& samples() const { return samples_; }
  const std::vector<StaticPoint>& static_points() const { return static_points_; }
  std::optional<double> straight_deg() const { return straight_deg_; }
  // What the probe measured, and the gains chosen from it (not given: the board's own).
  const std::optional<InnerLoopMeasurement>& inner_loop() const { return inner_loop_; }
  const InnerLoopGains& inner_loop_gains() const { return inner_loop_gains_; }

 private:
  // True once the current hold has lasted min_hold_s and the angle is steady (or max_hold_s).
  bool hold_complete(double time_s) const;
  StaticPoint steady_point(bool up) const;
  void start_hold(double time_s, double setpoint_kpa);
  void start_prbs(double time_s);
  // One frame of the inner-loop probe; on to the steps (in the same frame) when it is done.
  void probe(double time_s);

  IdentifyOptions options_;
  double ceiling_kpa_;
  Phase phase_ = kBaseline;
  std::vector<IdentifySample> samples_;
  std::vector<StaticPoint> static_points_;
  std::optional<double> straight_deg_;
  std::optional<double> lost_since_s_;
  double hold_start_s_ = 0.0;
  size_t hold_first_sample_ = 0;
  double setpoint_kpa_ = 0.0;
  int level_ = 0;
  // The inner-loop probe.
  std::optional<InnerLoopProbe> probe_;
  std::optional<double> duty_;
  std::optional<InnerLoopMeasurement> inner_loop_;
  InnerLoopGains inner_loop_gains_;
  bool gains_to_send_ = false;
  // PRBS.
  double prbs_start_s_ = 0.0;
  double prbs_centre_kpa_ = 0.0;
  double prbs_amplitude_kpa_ = 0.0;
  std::vector<int> prbs_bits_;
};

// The static map alone, from the steps (also used by the experiment to place the PRBS).
// Throws IdentifyAbort when the points do not show a bend (fewer than three bent points).
ActuatorModel FitStaticMap(const std::vector<StaticPoint>& points, double straight_deg);

// The whole model from a finished experiment. Throws IdentifyAbort when it cannot be fitted.
ActuatorModel FitActuatorModel(const IdentificationExperiment& experiment);

// The model's prediction of the angle for a sensed-pressure history (the same simulation the fit
// uses): for plots of data against model. `samples` as recorded; returns one angle per sample.
std::vector<double> PredictAngles(const ActuatorModel& model,
                                  const std::vector<IdentifySample>& samples);
// The inner loop's model: the sensed pressure it predicts from the setpoints sent.
std::vector<double> PredictPressures(const ActuatorModel& model,
                                     const std::vector<IdentifySample>& samples);

// The highest setpoint the experiment sends: the controller's max_kpa, at most 90 % of the
// board's limit and 4 kPa below it (so neither the abort margin nor the board's guard is reached).
double IdentificationCeiling(const ControllerOptions& controller, double board_limit_kpa);

// One frame of the experiment through `session` (open loop, ControlSession::step_pressure): the
// experiment's setpoint is sent and the board's answer recorded. Throws IdentifyAbort (the
// session vents when it is destroyed) or the link's InputError.
ControlSample StepIdentification(IdentificationExperiment& experiment, ControlSession& session,
                                 double time_s, std::optional<double> angle_deg);

// Outer-loop gains from the model by the SIMC rule (above), starting from `base` (whose limits,
// slew rate and hold time are kept). `frame_period_s`: the camera's. Sets model->closed_loop_s.
ControllerOptions TuneController(ActuatorModel* model, const ControllerOptions& base,
                                 double frame_period_s,
                                 std::optional<double> closed_loop_s = std::nullopt);

}  // namespace softsight
