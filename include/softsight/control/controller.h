// The host's outer loop, run once per camera frame: bending-angle error -> pressure setpoint for the
// board's inner loop (the paper's cascade, section 3.3).
//
// Sign convention: the paper's angle at the middle marker is 180 deg when straight and decreases as
// the actuator bends, so error_deg = measured_deg - target_deg is positive when the actuator must
// bend more, and a positive error asks for more pressure. All gains are therefore >= 0.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "softsight/control/actuator_model.h"

namespace softsight {

struct ControllerOptions {
  // Proportional gain, kPa of setpoint per degree of error. The paper's law is P only.
  double kp_kpa_per_deg = 0.25;
  // Integral gain, kPa per (degree * s). Removes the steady-state error a pressure setpoint leaves
  // with P only; 0 disables it.
  double ki_kpa_per_deg_s = 1.3;
  // The integral only accumulates while |error| is below this (integral separation): a large
  // error is the feed-forward's and P's to remove, and integrating it only winds up (overshoot
  // after a step the feed-forward already answers). Default 0: always.
  double integral_band_deg = 0.0;
  // Derivative gain on the measurement (no kick on target steps), kPa * s / degree. Default 0: the
  // camera's angle is noisy.
  double kd_kpa_s_per_deg = 0.0;
  double derivative_filter_s = 0.05;  // First-order filter of the derivative. Default 0.05 s.
  // Feed-forward: bias_kpa + ff_kpa_per_deg * (180 - target_deg) is added to the output. bias_kpa
  // is the pressure at which the actuator starts to bend; ff_kpa_per_deg the inverse of its
  // static gain (kPa per degree of angle) when known from an open-loop characterisation. With a
  // good feed-forward the PI only corrects the residual, and targets that move are followed with
  // much less lag. Defaults 3 kPa and 0 (off).
  double bias_kpa = 3.0;
  double ff_kpa_per_deg = 0.0;
  // Hysteresis compensation, the inverse of the actuator's play: the feed-forward adds half of
  // this while the target last moved towards more bend and subtracts half once it moved back
  // (the identified hysteresis width in kPa: model.hysteresis_deg / model.slope_deg_per_kpa).
  // Default 0: off.
  double hysteresis_kpa = 0.0;
  // Dynamic feed-forward: the target bend is led by this many seconds of its rate of change (the
  // inverse of the actuator's lags, to first order: the identified lags and dead times), so a
  // moving target is not followed a lag behind. Jumps of the target (faster than
  // kStepRateDegPerS) are steps, which no lead can anticipate: they get none. Default 0: off.
  double ff_lead_s = 0.0;
  // Its second-order term: the target bend's acceleration times this (the product of the two
  // identified lags, so that lead and this invert both exactly). Default 0: off.
  double ff_lead2_s2 = 0.0;
  // Output limits, kPa. The board enforces its own hard limit as well; max_kpa is clamped to it.
  double min_kpa = 0.0;
  double max_kpa = 45.0;
  // Setpoint slew limit, kPa/s; 0 = unlimited. Default 60: protects the silicone on target steps.
  // With a feed-forward it also ramps the reference the loop follows (max_rate / ff deg/s).
  double max_rate_kpa_per_s = 60.0;
  // Model-based loop (what `softsight identify` writes): instead of the PI and the ff_* terms,
  // the identified model (AngleController::set_model) inverted as the feed-forward, and the
  // model's error (measured angle - the model's angle for the sensed pressures), low-passed over
  // model_correction_s, taken off the target it inverts (internal model control). Per frame:
  //   bend wanted       = (straight - target) at the frame's end plus the dead times (the
  //                       profile's look-ahead), led by the bending lag (its rate times lag_s),
  //                       +- half the hysteresis by its direction, - the model error
  //   pressure wanted   = the static map's inverse of that bend
  //   setpoint          = the one that brings the model's inner loop (from the board's sensed
  //                       pressure, pump- and vent-limited) to that pressure by the frame's end
  // and, while the model lags the target by more than a degree (a step), full pressure (or
  // none) as long as the model predicts no overshoot when it switches to the target's pressure
  // the frame after (the fastest approach the pump allows). Output limits and the slew limit
  // hold as for the PI; the model sees the setpoint as sent, so nothing winds up. Default off.
  bool model_inverse = false;
  double model_correction_s = 0.1;
  // Vision loss: keep the last setpoint (integral frozen) while the measurement has been missing
  // for at most this long (from the first frame without one), then vent. Default 0.5 s.
  double hold_s = 0.5;
  // Targets from outside (`control --target-from`): a source silent for longer than this (since
  // its last target, on the frames' clock) vents the actuator until it speaks again. Default
  // 0.5 s: a few missed messages of a 10 Hz experiment script are not silence.
  double target_silence_s = 0.5;
  // How fast the loop's target may follow a target from outside, deg/s: a jump becomes a ramp
  // at this rate; 0 = unlimited (the setpoint's own slew limit, max_rate_kpa_per_s, still holds).
  // Default 0.
  double target_max_rate_deg_per_s = 0.0;

  // Returns false and names the bad field in `error`.
  bool Check(std::string* error) const;
};

// A target moving faster than this between two frames has jumped (a step), deg/s.
constexpr double kStepRateDegPerS = 300.0;

struct ControllerOutput {
  enum class Action { kTrack, kHold, kVent };
  Action action = Action::kVent;
  double setpoint_kpa = 0.0;          // To send to the board (0 when venting).
  std::optional<double> error_deg{};  // measured - target, when measured.
};

class ModelLoop;  // control/model_loop.h

class AngleController {
 public:
  explicit AngleController(const ControllerOptions& options);
  ~AngleController();
  AngleController(const AngleController&) = delete;
  AngleController& operator=(const AngleController&) = delete;

  // The target `ahead_s` after the current frame's (a profile's future): the model-based loop's
  // look-ahead. Without one the target is taken to stay where it is.
  using Preview = std::function<double(double ahead_s)>;

  // The identified actuator the model-based loop (options.model_inverse) inverts, and the vent
  // scale of the board's pressure loop (InnerLoopGains::vent_scale when the host sends gains,
  // else 1). Without an identified model (or with model_inverse off) the PI runs.
  void set_model(const ActuatorModel& model, double vent_scale = 1.0);
  bool model_based() const { return model_loop_ != nullptr; }

  // One frame at `time_s` (monotonic). `measured_deg` absent = the tracker lost a marker.
  ControllerOutput update(double time_s, double target_deg, std::optional<double> measured_deg,
                          const Preview& preview = {});
  // The board's sensed pressure in its answer to the last setpoint (the pressure when it
  // arrived): the model-based loop's pressure from then on.
  void observe_pressure(double pressure_kpa);
  void reset();

  double integral_kpa() const { return integral_kpa_; }
  const ControllerOptions& options() const { return options_; }
  // Clamps max_kpa to the board's limit (learned at the handshake).
  void limit_max_kpa(double max_kpa);

 private:
  // The model-based loop's setpoint (measured_deg absent: markers lost, the model runs on).
  double model_setpoint(double time_s, double target_deg, std::optional<double> measured_deg,
                        const Preview& preview, double dt_s);

  ControllerOptions options_;
  std::optional<double> last_time_s_;
  std::optional<double> loss_start_s_;  // First frame of the current vision loss.
  std::optional<double> last_measured_deg_;
  std::optional<double> last_target_deg_;
  std::optional<double> reference_deg_;  // The ramped target (with a feed-forward).
  std::optional<double> last_target_rate_;  // For the second-order lead.
  std::optional<double> last_input_deg_;    // The target as given (not ramped), for the lead.
  double bend_direction_ = 1.0;  // +1: the target last moved towards more bend; -1: back.
  double integral_kpa_ = 0.0;
  double derivative_deg_per_s_ = 0.0;
  double setpoint_kpa_ = 0.0;
  bool vented_ = true;
  std::unique_ptr<ModelLoop> model_loop_;
};

}  // namespace softsight
