// The control section's settings, registered once: key, unit, range and doc of every field
// (defaults: the structs). Ranges are what a person could sensibly mean, so that a typo (an
// extra zero) is an error rather than a burst actuator.
#include "control/control_options.h"

#include <cmath>

namespace softsight {
namespace {

OptionTable<ControllerOptions> MakeController() {
  using P = ControllerOptions;
  return {
      DoubleOption<P>("kp_kpa_per_deg", &P::kp_kpa_per_deg)
          .Range(0, 100)
          .Unit("kPa/deg")
          .Doc("proportional gain: kPa of setpoint per degree of error (the paper's P law)"),
      DoubleOption<P>("ki_kpa_per_deg_s", &P::ki_kpa_per_deg_s)
          .Range(0, 1000)
          .Unit("kPa/(deg s)")
          .Doc("integral gain; removes the steady-state error, 0 disables it"),
      DoubleOption<P>("integral_band_deg", &P::integral_band_deg)
          .Range(0, 180)
          .Unit("deg")
          .Doc("the integral accumulates only while |error| is below this (0: always)"),
      DoubleOption<P>("kd_kpa_s_per_deg", &P::kd_kpa_s_per_deg)
          .Range(0, 100)
          .Unit("kPa s/deg")
          .Doc("derivative gain on the measurement (the camera's angle is noisy)"),
      DoubleOption<P>("derivative_filter_s", &P::derivative_filter_s)
          .Range(0, 10)
          .Unit("s")
          .Doc("first-order filter of the derivative"),
      DoubleOption<P>("bias_kpa", &P::bias_kpa)
          .Range(-100, 1000)
          .Unit("kPa")
          .Doc("feed-forward: the pressure at which the actuator starts to bend"),
      DoubleOption<P>("ff_kpa_per_deg", &P::ff_kpa_per_deg)
          .Range(0, 100)
          .Unit("kPa/deg")
          .Doc("feed-forward per degree of target bend (inverse static gain; 0: off)"),
      DoubleOption<P>("hysteresis_kpa", &P::hysteresis_kpa)
          .Range(0, 100)
          .Unit("kPa")
          .Doc("hysteresis compensation: +-half of it on the feed-forward by the target's "
               "direction (0: off)"),
      DoubleOption<P>("ff_lead_s", &P::ff_lead_s)
          .Range(0, 10)
          .Unit("s")
          .Doc("dynamic feed-forward: lead of the target bend by its rate (0: off)"),
      DoubleOption<P>("ff_lead2_s2", &P::ff_lead2_s2)
          .Range(0, 100)
          .Unit("s^2")
          .Doc("dynamic feed-forward, second order: the target bend's acceleration times this"),
      DoubleOption<P>("min_kpa", &P::min_kpa)
          .Range(0, 1000)
          .Unit("kPa")
          .Doc("lowest setpoint sent"),
      DoubleOption<P>("max_kpa", &P::max_kpa)
          .Range(0, 1000)
          .Unit("kPa")
          .Doc("highest setpoint sent (above min_kpa; the board clamps to its own limit too)"),
      DoubleOption<P>("max_rate_kpa_per_s", &P::max_rate_kpa_per_s)
          .Range(0, 100000)
          .Unit("kPa/s")
          .Doc("setpoint slew limit, protects the silicone on target steps (0: unlimited)"),
      BoolOption<P>("model_inverse", &P::model_inverse)
          .Doc("model-based loop: the identified model (control.model) inverted as the "
               "feed-forward, with the profile's look-ahead over the dead times, corrected by the "
               "measured model error; false: the PI with the ff_* terms above"),
      DoubleOption<P>("model_correction_s", &P::model_correction_s)
          .Range(0.001, 10)
          .Unit("s")
          .Doc("model-based loop: low-pass time of the model error it corrects (the feedback's "
               "speed)"),
      DoubleOption<P>("hold_s", &P::hold_s)
          .Range(0, 60)
          .Unit("s")
          .Doc("vision lost: keep the last setpoint this long, then vent"),
      DoubleOption<P>("target_silence_s", &P::target_silence_s)
          .Range(0.01, 600)
          .Unit("s")
          .Doc("--target-from: the target's source silent this long (frames' clock) vents the "
               "actuator until it sends again"),
      DoubleOption<P>("target_max_rate_deg_per_s", &P::target_max_rate_deg_per_s)
          .Range(0, 100000)
          .Unit("deg/s")
          .Doc("--target-from: the loop follows a new target at most this fast (a jump becomes "
               "a ramp; 0: unlimited)"),
  };
}

OptionTable<LinkOptions> MakeLink() {
  using P = LinkOptions;
  return {
      IntOption<P>("baud", &P::baud)
          .OneOf({9600, 19200, 38400, 57600, 115200, 230400})
          .Doc("serial baud rate (a 60-byte line takes ~5 ms at 115200)"),
      IntOption<P>("reply_timeout_ms", &P::reply_timeout_ms)
          .Range(5, 10000)
          .Unit("ms")
          .Doc("deadline of each try, from sending it (other lines never extend it); then re-send"),
      IntOption<P>("retries", &P::retries).Range(0, 10).Doc("re-sends before giving up with an error"),
  };
}

OptionTable<InnerLoopGains> MakeInnerLoop() {
  using P = InnerLoopGains;
  return {
      DoubleOption<P>("kp_per_kpa", &P::kp_per_kpa)
          .Range(0, kMaxInnerGain)
          .Unit("duty/kPa")
          .Doc("the board's pressure loop gain for this run, sent at the handshake with the two "
               "below (0: the board's own gains, nothing sent); identify sets it for a tube"),
      DoubleOption<P>("ki_per_kpa_s", &P::ki_per_kpa_s)
          .Range(0, kMaxInnerGain)
          .Unit("duty/(kPa s)")
          .Doc("the board's pressure loop integral gain for this run (with kp_per_kpa > 0)"),
      DoubleOption<P>("vent_scale", &P::vent_scale)
          .Range(kMinVentScale, kMaxVentScale)
          .Doc("the loop's duty is multiplied by this when it vents, for a vent faster than the "
               "pump (with kp_per_kpa > 0)"),
  };
}

// A board setting in kPa (the file) held in integer Pa (the board).
Option<BoardConfig> KpaOption(const char* key, int32_t BoardConfig::*pa) {
  return CustomOption<BoardConfig>(
             key, OptionKind::kDouble,
             [pa](const BoardConfig& b) -> std::optional<OptionValue> {
               return OptionValue((b.*pa) / 1000.0);
             },
             [pa](BoardConfig& b, const std::optional<OptionValue>& v) {
               if (v) b.*pa = static_cast<int32_t>(std::lround(std::get<double>(*v) * 1000.0));
             })
      .Unit("kPa");
}

OptionTable<BoardConfig> MakeBoard() {
  using P = BoardConfig;
  return {
      OptionBuilder<P>(KpaOption("pressure_limit_kpa", &P::pressure_limit_pa))
          .Range(1, 1000)
          .Doc("hard gauge pressure limit the board's guard enforces"),
      OptionBuilder<P>(KpaOption("guard_margin_kpa", &P::guard_margin_pa))
          .Range(0, 100)
          .Doc("the guard trips at limit - margin (one loop period of inflation must fit)"),
      OptionBuilder<P>(KpaOption("guard_release_kpa", &P::guard_release_pa))
          .Range(0, 100)
          .Doc("hysteresis: the guard releases this far below its trip point"),
      OptionBuilder<P>(KpaOption("deadband_kpa", &P::deadband_pa))
          .Range(0, 100)
          .Doc("|error| below this holds both valves closed (no chatter)"),
      IntOption<P>("loop_hz", &P::loop_hz)
          .Range(200, 5000)
          .Unit("Hz")
          .Doc("inner pressure loop rate, much faster than a camera"),
      IntOption<P>("watchdog_ms", &P::watchdog_ms)
          .Range(10, 10000)
          .Unit("ms")
          .Doc("no valid command for this long: vent to the safe state"),
      DoubleOption<P>("kp_per_kpa", &P::kp_per_kpa)
          .Range(0, 1000)
          .Unit("duty/kPa")
          .Doc("pressure loop proportional gain; higher is faster but chatters on/off valves"),
      DoubleOption<P>("ki_per_kpa_s", &P::ki_per_kpa_s)
          .Range(0, 1000)
          .Unit("duty/(kPa s)")
          .Doc("pressure loop integral gain"),
  };
}

OptionTable<PlantOptions> MakePlant() {
  using P = PlantOptions;
  return {
      DoubleOption<P>("chamber_volume_ml", &P::chamber_volume_ml)
          .Range(0.1, 10000)
          .Unit("mL")
          .Doc("chamber + tubing; larger: slower pressure"),
      DoubleOption<P>("pump_flow_l_per_min", &P::pump_flow_l_per_min)
          .Range(0, 1000)
          .Unit("L/min")
          .Doc("free flow of the pump"),
      DoubleOption<P>("pump_stall_kpa", &P::pump_stall_kpa)
          .Range(1, 10000)
          .Unit("kPa")
          .Doc("pressure at which the pump's flow drops to 0"),
      DoubleOption<P>("vent_flow_l_per_min", &P::vent_flow_l_per_min)
          .Range(0.001, 1000)
          .Unit("L/min")
          .Doc("vent valve flow at 10 kPa, fully open"),
      DoubleOption<P>("leak_l_per_min", &P::leak_l_per_min)
          .Range(0, 1000)
          .Unit("L/min")
          .Doc("leak at 10 kPa (linear)"),
      DoubleOption<P>("bend_start_kpa", &P::bend_start_kpa)
          .Range(0, 1000)
          .Unit("kPa")
          .Doc("below this the actuator does not bend"),
      DoubleOption<P>("bend_deg_per_kpa", &P::bend_deg_per_kpa)
          .Range(0.001, 1000)
          .Unit("deg/kPa")
          .Doc("slope of the equilibrium bend"),
      DoubleOption<P>("max_bend_deg", &P::max_bend_deg)
          .Range(1, 340)
          .Unit("deg")
          .Doc("mechanical end stop of the bend"),
      DoubleOption<P>("bend_lag_s", &P::bend_lag_s)
          .Range(0.001, 100)
          .Unit("s")
          .Doc("time constant of the bending response"),
      DoubleOption<P>("hysteresis_deg", &P::hysteresis_deg)
          .Range(0, 90)
          .Unit("deg")
          .Doc("width of the play operator"),
      DoubleOption<P>("tube_delay_s", &P::tube_delay_s)
          .Range(0, 0.5)
          .Unit("s")
          .Doc("transport delay of the tube from the valves to the chamber and its sensor"),
  };
}

OptionTable<RigOptions> MakeRig() {
  using P = RigOptions;
  OptionTable<P> table;
  AppendOptions(&table, "board", &P::board, BoardConfigTable());
  AppendOptions(&table, "plant", &P::plant, PlantOptionsTable());
  table.push_back(DoubleOption<P>("end_marker_span", &P::end_marker_span)
                      .Range(0.01, 1)
                      .Doc("body fraction between the base and tip markers"));
  table.push_back(DoubleOption<P>("sensor_noise_kpa", &P::sensor_noise_kpa)
                      .Range(0, 100)
                      .Unit("kPa")
                      .Doc("pressure sensor noise, standard deviation"));
  table.push_back(IntOption<P>("seed", &P::seed).Range(0, 1 << 30).Doc("of the sensor noise"));
  return table;
}

OptionTable<ActuatorModel> MakeModel() {
  using P = ActuatorModel;
  const auto row = [](const char* key, double P::*field, double lo, double hi, const char* unit,
                      const char* doc) -> Option<P> {
    return DoubleOption<P>(key, field).Range(lo, hi).Unit(unit).Doc(doc);
  };
  return {
      row("straight_deg", &P::straight_deg, 0, 180, "deg", "angle when vented (identified)"),
      row("bend_start_kpa", &P::bend_start_kpa, 0, 1000, "kPa",
          "static map: the angle starts to fall above this pressure"),
      row("slope_deg_per_kpa", &P::slope_deg_per_kpa, 0, 1000, "deg/kPa",
          "static map: angle change per kPa, mid line of the two branches (0: no model)"),
      row("saturation_kpa", &P::saturation_kpa, 0, 1000, "kPa",
          "static map: the angle stops falling above this (0: none seen)"),
      row("hysteresis_deg", &P::hysteresis_deg, 0, 180, "deg",
          "static map: width between the up and down branches"),
      row("static_rms_deg", &P::static_rms_deg, 0, 180, "deg", "RMS residual of the static fit"),
      row("valve_dead_time_s", &P::valve_dead_time_s, 0, 100, "s",
          "valve command -> sensed pressure moving: the tube's delay (inner-loop probe)"),
      row("inflate_kpa_per_s", &P::inflate_kpa_per_s, 0, 1e6, "kPa/s",
          "pressure rate at full inflation, near vented"),
      row("vent_kpa_per_s", &P::vent_kpa_per_s, 0, 1e6, "kPa/s",
          "pressure rate at full venting, at vent_at_kpa"),
      row("vent_at_kpa", &P::vent_at_kpa, 0, 1000, "kPa",
          "the pressure full venting's rate was measured at (it grows with sqrt(p))"),
      row("pressure_lag_s", &P::pressure_lag_s, 0, 100, "s",
          "inner loop setpoint -> sensed pressure: first-order lag"),
      row("pressure_dead_time_s", &P::pressure_dead_time_s, 0, 100, "s",
          "inner loop: dead time"),
      row("pressure_rms_kpa", &P::pressure_rms_kpa, 0, 1000, "kPa",
          "RMS residual of the inner-loop fit"),
      row("pressure_duty_per_kpa", &P::pressure_duty_per_kpa, 0, 1000, "duty/kPa",
          "inner loop as the board runs it: duty = g * pressure error, saturating at full duty, "
          "times the probe's rates (0: not fitted)"),
      row("pressure_duty_dead_time_s", &P::pressure_duty_dead_time_s, 0, 100, "s",
          "that inner-loop model's dead time"),
      row("pressure_duty_rms_kpa", &P::pressure_duty_rms_kpa, 0, 1000, "kPa",
          "RMS residual of that fit"),
      row("lag_s", &P::lag_s, 0, 100, "s", "sensed pressure -> angle: first-order lag"),
      row("dead_time_s", &P::dead_time_s, 0, 100, "s",
          "sensed pressure -> angle: dead time (camera and tracker included)"),
      row("dynamic_rms_deg", &P::dynamic_rms_deg, 0, 180, "deg",
          "RMS residual of the bending dynamics fit"),
      row("valid_min_kpa", &P::valid_min_kpa, 0, 1000, "kPa", "lowest pressure the fit covers"),
      row("valid_max_kpa", &P::valid_max_kpa, 0, 1000, "kPa", "highest pressure the fit covers"),
      row("valid_min_deg", &P::valid_min_deg, 0, 180, "deg", "smallest angle the fit covers"),
      row("valid_max_deg", &P::valid_max_deg, 0, 180, "deg", "largest angle the fit covers"),
      row("closed_loop_s", &P::closed_loop_s, 0, 100, "s",
          "SIMC closed-loop time the controller's gains were computed with"),
  };
}

OptionTable<ControlConfig> MakeControl() {
  using P = ControlConfig;
  OptionTable<P> table;
  AppendOptions(&table, "controller", &P::controller, ControllerOptionsTable());
  AppendOptions(&table, "link", &P::link, LinkOptionsTable());
  AppendOptions(&table, "inner_loop", &P::inner_loop, InnerLoopGainsTable());
  AppendOptions(&table, "rig", &P::rig, RigOptionsTable());
  AppendOptions(&table, "model", &P::model, ModelOptionsTable());
  return table;
}

}  // namespace

const OptionTable<ControllerOptions>& ControllerOptionsTable() {
  static const OptionTable<ControllerOptions> table = MakeController();
  return table;
}
const OptionTable<LinkOptions>& LinkOptionsTable() {
  static const OptionTable<LinkOptions> table = MakeLink();
  return table;
}
const OptionTable<InnerLoopGains>& InnerLoopGainsTable() {
  static const OptionTable<InnerLoopGains> table = MakeInnerLoop();
  return table;
}
const OptionTable<BoardConfig>& BoardConfigTable() {
  static const OptionTable<BoardConfig> table = MakeBoard();
  return table;
}
const OptionTable<PlantOptions>& PlantOptionsTable() {
  static const OptionTable<PlantOptions> table = MakePlant();
  return table;
}
const OptionTable<RigOptions>& RigOptionsTable() {
  static const OptionTable<RigOptions> table = MakeRig();
  return table;
}
const OptionTable<ActuatorModel>& ModelOptionsTable() {
  static const OptionTable<ActuatorModel> table = MakeModel();
  return table;
}
const OptionTable<ControlConfig>& ControlConfigTable() {
  static const OptionTable<ControlConfig> table = MakeControl();
  return table;
}

}  // namespace softsight
