// One closed-loop (or open-loop) run, one step per camera frame: target -> outer loop -> board,
// and the board's answer back. Knows nothing of images: the caller hands it the measured angle.
#pragma once

#include <optional>

#include "softsight/control/board_link.h"
#include "softsight/control/controller.h"
#include "softsight/control/profile.h"

namespace softsight {

enum class ControlMode {
  kAngle,     // Closed loop on the measured angle (the cascade).
  kPressure,  // Open loop: a fixed pressure setpoint (characterising an actuator).
  kDuty,      // Open loop: a fixed valve duty, no pressure loop.
};

struct ControlTarget {
  ControlMode mode = ControlMode::kAngle;
  TargetProfile profile = TargetProfile::Constant(180.0);  // kAngle.
  double pressure_kpa = 0.0;                               // kPressure.
  double duty = 0.0;                                       // kDuty, in [-1, 1].
};

// What happened in one frame: the row of the control log.
struct ControlSample {
  double time_s = 0.0;                   // Since the first step.
  std::optional<double> target_deg;      // kAngle only.
  std::optional<double> measured_deg;
  ControllerOutput::Action action = ControllerOutput::Action::kVent;
  std::optional<double> setpoint_kpa;    // Sent pressure setpoint (absent when venting / duty).
  std::optional<double> duty_command;    // Sent duty (kDuty).
  BoardState board;                      // The board's answer.
};

class ControlSession {
 public:
  // `link` must outlive the session. Throws InputError when the options fail their Check().
  ControlSession(const ControllerOptions& options, BoardLink& link, ControlTarget target);

  // Handshake; the controller's max_kpa is clamped to the board's limit. Throws InputError.
  BoardInfo start();
  // One frame at `time_s` (the frame's timestamp). Throws InputError when the link fails.
  ControlSample step(double time_s, std::optional<double> measured_deg);
  // Vents the actuator (end of run).
  BoardState stop();

  const AngleController& controller() const { return controller_; }

 private:
  AngleController controller_;
  BoardLink& link_;
  ControlTarget target_;
  std::optional<double> start_time_s_;
};

}  // namespace softsight
