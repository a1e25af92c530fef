#include "softsight/control/session.h"

#include <cassert>

#include <algorithm>
#include <cstdio>

#include "softsight/core/error.h"
#include "softsight/core/format.h"

namespace softsight {
namespace {


const ControllerOptions& Checked(const ControllerOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw InputError("control.controller: " + error);
  return options;
}

}  // namespace

ControlSession::ControlSession(const ControllerOptions& options, BoardLink& link,
                               ControlTarget target)
    : controller_(Checked(options)), link_(link), target_(std::move(target)) {
  // Comparisons are false for NaN: test for the good range, not against the bad one.
  if (!(target_.duty >= -1.0 && target_.duty <= 1.0)) {
    throw InputError("--pwm " + ShortNumber(target_.duty) + ": duty must be in -1..1");
  }
  if (!(target_.pressure_kpa >= 0.0 && target_.pressure_kpa <= kMaxBoardPressureLimitKpa)) {
    throw InputError("--pressure-kpa " + ShortNumber(target_.pressure_kpa) +
                     ": must be a number in 0.." + ShortNumber(kMaxBoardPressureLimitKpa));
  }
}

ControlSession::~ControlSession() {
  if (!started_ || stopped_) return;
  stopped_ = true;
  try {
    link_.stop();
  } catch (const std::exception&) {
    // The link is already failing (that is likely why we are here); its error has been
    // reported, and the board's watchdog vents when the commands stop.
  }
}

BoardInfo ControlSession::start() {
  const BoardInfo info = link_.handshake();
  started_ = true;
  stopped_ = false;
  board_limit_kpa_ = info.pressure_limit_kpa;
  if (!(controller_.options().min_kpa < info.pressure_limit_kpa)) {
    stop();
    throw InputError("control.controller.min_kpa: " + ShortNumber(controller_.options().min_kpa) +
                     " kPa is not below the board's pressure limit of " +
                     ShortNumber(info.pressure_limit_kpa) + " kPa (" + link_.port_name() +
                     "); no setpoint sent, vented");
  }
  controller_.limit_max_kpa(info.pressure_limit_kpa);
  send_inner_loop_gains();  // Before any setpoint: the loop starts with the gains for the plant.
  const double max_kpa = controller_.options().max_kpa;
  if (target_.mode == ControlMode::kPressure && target_.pressure_kpa > max_kpa) {
    pressure_clamped_from_ = target_.pressure_kpa;
    target_.pressure_kpa = max_kpa;
  }
  return info;
}

BoardState ControlSession::send_pressure(double setpoint_kpa, std::optional<double>* sent) {
  const ControllerOptions& c = controller_.options();
  *sent = std::clamp(setpoint_kpa, c.min_kpa, c.max_kpa);
  return link_.set_pressure_kpa(**sent);
}

const BoardState& ControlSession::checked(const BoardState& state) {
  last_pressure_kpa_ = state.pressure_kpa;
  if (state.watchdog()) ++watchdog_answers_;
  if (state.limit()) ++limit_answers_;
  if (state.pressure_kpa > board_limit_kpa_) {
    stopped_ = true;
    try {
      link_.stop();
    } catch (const std::exception&) {
      // Reported below; the board's watchdog vents when the commands stop.
    }
    throw InputError(link_.port_name() + ": the board reports " + ShortNumber(state.pressure_kpa) +
                     " kPa, above its own limit of " + ShortNumber(board_limit_kpa_) +
                     " kPa (sensor or guard fault); sent STOP to vent, stopping");
  }
  return state;
}

ControlSample ControlSession::step(double time_s, std::optional<double> measured_deg) {
  ControlSample sample = begin_sample(time_s, measured_deg);
  switch (target_.mode) {
    case ControlMode::kAngle: {
      const double target_deg = target_.profile.at(sample.time_s);
      sample.target_deg = target_deg;
      // The profile is known ahead: the model-based loop looks ahead over the dead times.
      const TargetProfile& profile = target_.profile;
      const double now_s = sample.time_s;
      const ControllerOutput out = controller_.update(
          time_s, target_deg, measured_deg,
          [&profile, now_s](double ahead_s) { return profile.at(now_s + ahead_s); });
      sample.action = out.action;
      if (out.action == ControllerOutput::Action::kVent) {
        sample.board = checked(link_.stop());
      } else {
        sample.board = checked(send_pressure(out.setpoint_kpa, &sample.setpoint_kpa));
        controller_.observe_pressure(sample.board.pressure_kpa);
      }
      break;
    }
    case ControlMode::kPressure:
      sample.action = ControllerOutput::Action::kTrack;
      sample.board = checked(send_pressure(target_.pressure_kpa, &sample.setpoint_kpa));
      break;
    case ControlMode::kDuty:
      sample.action = ControllerOutput::Action::kTrack;
      send_duty(target_.duty, &sample);
      break;
  }
  return sample;
}

ControlSample ControlSession::begin_sample(double time_s, std::optional<double> measured_deg) {
  if (!start_time_s_) start_time_s_ = time_s;
  ControlSample sample;
  sample.time_s = time_s - *start_time_s_;
  sample.measured_deg = measured_deg;
  sample.action = ControllerOutput::Action::kTrack;
  return sample;
}

ControlSample ControlSession::step_pressure(double time_s, double setpoint_kpa,
                                            std::optional<double> measured_deg) {
  ControlSample sample = begin_sample(time_s, measured_deg);
  sample.board = checked(send_pressure(setpoint_kpa, &sample.setpoint_kpa));
  return sample;
}

void ControlSession::set_angle_target(double target_deg) {
  assert(target_.mode == ControlMode::kAngle);
  target_.profile = TargetProfile::Constant(target_deg);
}

ControlSample ControlSession::vent(double time_s, std::optional<double> measured_deg) {
  ControlSample sample = begin_sample(time_s, measured_deg);
  sample.action = ControllerOutput::Action::kVent;
  sample.board = checked(link_.stop());
  controller_.reset();
  return sample;
}

void ControlSession::send_duty(double duty, ControlSample* sample) {
  // Open-loop inflation stops at the host's own limit, not only at the board's guard: while
  // the sensed pressure is at max_kpa the valves stay closed (venting is always allowed).
  sample->duty_command = duty;
  // The next frame's pressure is foreseen from the rise of the last frame that inflated: the
  // valves close a frame early rather than one late.
  if (duty > 0.0 && last_pressure_kpa_ + inflate_rise_kpa_ >= controller_.options().max_kpa) {
    sample->duty_command = 0.0;
    ++duty_held_at_limit_;
  }
  const double before_kpa = last_pressure_kpa_;
  sample->board = checked(link_.set_duty(*sample->duty_command));
  if (*sample->duty_command > 0.0) {
    inflate_rise_kpa_ = std::max(0.0, last_pressure_kpa_ - before_kpa);
  }
}

ControlSample ControlSession::step_duty(double time_s, double duty,
                                        std::optional<double> measured_deg) {
  ControlSample sample = begin_sample(time_s, measured_deg);
  send_duty(std::clamp(duty, -1.0, 1.0), &sample);
  return sample;
}

void ControlSession::set_inner_loop_gains(const InnerLoopGains& gains) {
  std::string problem;
  if (!gains.Check(&problem)) throw InputError("control.inner_loop." + problem);
  inner_loop_ = gains;
  if (started_ && !stopped_) send_inner_loop_gains();
}

void ControlSession::set_model(const ActuatorModel& model) {
  controller_.set_model(model, inner_loop_.given() ? inner_loop_.vent_scale : 1.0);
}

void ControlSession::send_inner_loop_gains() {
  if (!inner_loop_.given()) return;
  checked(link_.set_inner_loop_gains(inner_loop_.kp_per_kpa, inner_loop_.ki_per_kpa_s,
                                     inner_loop_.vent_scale));
}

BoardState ControlSession::stop() {
  stopped_ = true;  // Tried: the destructor does not try a second time.
  return link_.stop();
}

}  // namespace softsight
