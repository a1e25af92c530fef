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
  std::optional<double> target_deg{};    // kAngle only.
  std::optional<double> measured_deg{};
  ControllerOutput::Action action = ControllerOutput::Action::kVent;
  std::optional<double> setpoint_kpa{};  // Sent pressure setpoint (absent when venting / duty).
  std::optional<double> duty_command{};  // Sent duty (kDuty).
  BoardState board{};                    // The board's answer.
};

// Safety is structural: once start() has shaken hands, the session sends STOP when it ends,
// however it ends (the end of the run, a board ERR, a failed link, a fault, any exception), unless
// stop() already has. Every pressure command is clamped to the controller's max_kpa (itself at
// most the board's limit) and the sample records the clamped value, the one on the wire; in duty
// mode the valves are closed (duty 0) while the sensed pressure is at max_kpa; every answer is
// checked against the board's limit.
class ControlSession {
 public:
  // `link` must outlive the session. Throws InputError when the options or the target (NaN,
  // infinite, out of range) are unusable.
  ControlSession(const ControllerOptions& options, BoardLink& link, ControlTarget target);
  // Vents the actuator (STOP) if the session was started and not stopped; never throws.
  ~ControlSession();
  ControlSession(const ControlSession&) = delete;
  ControlSession& operator=(const ControlSession&) = delete;

  // Gains for the board's inner loop, sent by start() right after the handshake (and at once when
  // the session has started: an identification that has just measured the plant). Not given:
  // the board keeps its own. Throws InputError when they are unusable or the board refuses them.
  void set_inner_loop_gains(const InnerLoopGains& gains);
  // The identified actuator for the model-based loop (ControllerOptions::model_inverse; its
  // vent scale is the inner-loop gains' when they are given: call after set_inner_loop_gains).
  // Nothing changes without model_inverse or an identified model.
  void set_model(const ActuatorModel& model);

  // Handshake; the controller's max_kpa is clamped to the board's limit, and so is an open-loop
  // pressure target (see pressure_clamped_from()). Throws InputError (after venting) when the
  // controller's min_kpa is not below the board's limit: every setpoint would be above it.
  BoardInfo start();
  // One frame at `time_s` (the frame's timestamp). Throws InputError when the link fails, the
  // board refuses a command, or the board reports a pressure above its limit (a fault: the
  // session vents before throwing). Throws StopRequested when the user asked to stop mid-wait.
  ControlSample step(double time_s, std::optional<double> measured_deg);
  // One frame open loop at a pressure chosen for this frame (an identification experiment), with
  // the same clamp to max_kpa and the same checks of the answer as step().
  ControlSample step_pressure(double time_s, double setpoint_kpa,
                              std::optional<double> measured_deg);
  // One frame open loop at a valve duty chosen for this frame (an identification experiment),
  // with the same hold at max_kpa as the duty mode of step().
  ControlSample step_duty(double time_s, double duty, std::optional<double> measured_deg);
  // Vents the actuator (end of run).
  BoardState stop();

  // A target from outside (`control --target-from`), followed from the next step(): replaces
  // the angle target with this constant one. Angle mode only (a debug assertion).
  void set_angle_target(double target_deg);
  // One frame with the actuator vented (the target's source went silent): the sample has no
  // target and the action kVent; the outer loop starts afresh (reset) at the next step().
  // Throws as step().
  ControlSample vent(double time_s, std::optional<double> measured_deg);

  // The open-loop pressure target as given, when start() lowered it to max_kpa.
  std::optional<double> pressure_clamped_from() const { return pressure_clamped_from_; }
  // The pressure the open-loop target sends (after the clamp).
  double pressure_target_kpa() const { return target_.pressure_kpa; }
  const AngleController& controller() const { return controller_; }
  // Duty mode: frames in which the duty asked for was replaced by 0 (valves closed) because the
  // sensed pressure had reached max_kpa.
  int64_t duty_held_at_limit() const { return duty_held_at_limit_; }
  // Answers to this session's commands in which the board said its watchdog had vented, or its
  // pressure guard was overriding the outputs: the actuator did not do what was sent.
  int64_t watchdog_answers() const { return watchdog_answers_; }
  int64_t limit_answers() const { return limit_answers_; }

 private:
  // Sends the setpoint clamped to [min_kpa, max_kpa]; `sent` receives the clamped value.
  BoardState send_pressure(double setpoint_kpa, std::optional<double>* sent);
  // A frame's sample: its time since the first step, the angle, action kTrack.
  ControlSample begin_sample(double time_s, std::optional<double> measured_deg);
  // Sends `duty`, or 0 (valves closed) when inflating would take the pressure to max_kpa.
  void send_duty(double duty, ControlSample* sample);
  void send_inner_loop_gains();
  // Throws (after venting) when the board says its pressure is above its own limit.
  const BoardState& checked(const BoardState& state);

  AngleController controller_;
  BoardLink& link_;
  ControlTarget target_;
  InnerLoopGains inner_loop_;
  std::optional<double> start_time_s_;
  std::optional<double> pressure_clamped_from_;
  double board_limit_kpa_ = 0.0;
  double last_pressure_kpa_ = 0.0;  // Sensed in the last answer.
  double inflate_rise_kpa_ = 0.0;   // The rise over the last frame that inflated (duty mode).
  int64_t duty_held_at_limit_ = 0;
  int64_t watchdog_answers_ = 0;
  int64_t limit_answers_ = 0;
  bool started_ = false;
  bool stopped_ = false;
};

}  // namespace softsight
