#include "softsight/control/session.h"

#include <algorithm>

#include "softsight/core/error.h"

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
  if (target_.duty < -1.0 || target_.duty > 1.0) {
    throw InputError("--pwm " + std::to_string(target_.duty) + ": duty must be in -1..1");
  }
  if (target_.pressure_kpa < 0.0) {
    throw InputError("--pressure-kpa " + std::to_string(target_.pressure_kpa) + ": must be >= 0");
  }
}

BoardInfo ControlSession::start() {
  const BoardInfo info = link_.handshake();
  controller_.limit_max_kpa(info.pressure_limit_kpa);
  if (target_.mode == ControlMode::kPressure && target_.pressure_kpa > info.pressure_limit_kpa) {
    throw InputError("--pressure-kpa " + std::to_string(target_.pressure_kpa) +
                     ": above the board's limit of " + std::to_string(info.pressure_limit_kpa) +
                     " kPa");
  }
  return info;
}

ControlSample ControlSession::step(double time_s, std::optional<double> measured_deg) {
  if (!start_time_s_) start_time_s_ = time_s;
  ControlSample sample;
  sample.time_s = time_s - *start_time_s_;
  sample.measured_deg = measured_deg;
  switch (target_.mode) {
    case ControlMode::kAngle: {
      const double target_deg = target_.profile.at(sample.time_s);
      sample.target_deg = target_deg;
      const ControllerOutput out = controller_.update(time_s, target_deg, measured_deg);
      sample.action = out.action;
      if (out.action == ControllerOutput::Action::kVent) {
        sample.board = link_.stop();
      } else {
        sample.setpoint_kpa = out.setpoint_kpa;
        sample.board = link_.set_pressure_kpa(out.setpoint_kpa);
      }
      break;
    }
    case ControlMode::kPressure:
      sample.action = ControllerOutput::Action::kTrack;
      sample.setpoint_kpa = target_.pressure_kpa;
      sample.board = link_.set_pressure_kpa(target_.pressure_kpa);
      break;
    case ControlMode::kDuty:
      sample.action = ControllerOutput::Action::kTrack;
      sample.duty_command = target_.duty;
      sample.board = link_.set_duty(target_.duty);
      break;
  }
  return sample;
}

BoardState ControlSession::stop() { return link_.stop(); }

}  // namespace softsight
