// Internal to web (and its tests). The rig's control panel of `softsight serve --simulate` /
// `--board-port`: a started ControlSession driven from pages instead of a command line. One
// step per tracked frame (it is a sink of the run, like `control`'s ControlSink), on the frames'
// clock; every call on the run's thread.
//
// States: idle (the actuator vented every frame: the board's watchdog stays fed and the valves
// open), running (the closed loop on a target angle or a profile), holding (the page that ran
// it left mid-run: the last pressure setpoint is held for the controller's hold_s, as on vision
// loss, then the actuator is vented and the panel is idle), failed (the link or the board failed:
// nothing more is sent; the board's watchdog vents). stop() vents at once in every state, for
// any page: STOP always works.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "softsight/control/profile.h"
#include "softsight/io/csv_columns.h"
#include "softsight/control/session.h"
#include "softsight/pipeline/sink.h"

namespace softsight {

class RigPanel : public FrameSink {
 public:
  enum class State { kIdle, kRunning, kHolding, kFailed };

  // `session` has shaken hands (its controller's max_kpa is the board's limit at most) and must
  // outlive the panel. `board` is what the handshake said; `port` names the link for the page;
  // `model` the identified actuator (a target beyond its reach is refused; not identified:
  // everything reaches).
  RigPanel(ControlSession& session, const BoardInfo& board, std::string port,
           const ActuatorModel& model = {});

  // The page `page` runs the loop to `target_deg` (from idle: a new run; running: the new
  // target, the run going on). "" when done; else why it was refused, nothing changed.
  std::string run_target(double target_deg, uint64_t page);
  // The page runs `profile` from the next frame (its time 0); after its end it keeps its last
  // target until STOP. Refused (nothing changed) as run_target.
  std::string run_profile(const TargetProfile& profile, uint64_t page);
  // Vents now (a STOP to the board at once, not at the next frame) and ends any run; `who` says
  // why in the message. Never throws; in every state.
  void stop(const std::string& who);
  // A page left. The one that runs the loop, mid-run: hold, then vent.
  void page_left(uint64_t page);

  // FrameSink: one step with the frame's angle (absent: a marker lost; the controller holds,
  // then vents).
  void consume(const Frame& frame, const FrameResult& result) override;
  // One step at `time_s` (monotonic; a repeated time is ignored).
  void step(double time_s, std::optional<double> measured_deg);

  State state() const { return state_; }
  const ControlSample& last_sample() const { return last_; }
  // Steps and stops so far: changes whenever status_json() does.
  int64_t updates() const { return updates_; }
  // {"type":"rig", ...}: the state and the last sample (target, measured angle, setpoint, the
  // board's pressure, duty, flags, vented), for every page. Reused buffer.
  const std::string& status_json();
  // The host's and the board's limits, a JSON object for the page's greeting.
  std::string limits_json() const;
  // The loop's columns of each frame's row, as `control`'s CSV has them (target_deg,
  // setpoint_kpa, board_pressure_kpa, board_setpoint_kpa, duty, board_flags, control_action,
  // rig_state: 0 idle, 1 running, 2 holding, 3 failed): the sample of the frame's own step (the
  // panel is a sink before the page's and the recording's). The panel must outlive them.
  std::vector<CsvColumn> columns() const;
  // What the panel said since the last call (runs started, STOP, hold, vent, failures).
  std::vector<std::string> take_messages();

  static const char* StateName(State state);

 private:
  std::string refused(const TargetProfile& profile) const;
  void start(const TargetProfile& profile, uint64_t page, const std::string& what);
  // The session's call, guarded: a failing link or board ends in kFailed, never an exception.
  template <typename Call>
  void guarded(Call call);
  void vent_now(const std::string& message);

  ControlSession& session_;
  BoardInfo board_;
  std::string port_;
  ActuatorModel model_;
  State state_ = State::kIdle;
  TargetProfile profile_ = TargetProfile::Constant(180.0);
  std::optional<double> run_start_s_;   // Frame time of the run's first step (profile time 0).
  std::optional<double> hold_since_s_;  // Frame time the owner left (kHolding).
  double held_kpa_ = 0.0;
  uint64_t owner_ = 0;                  // The page that started or last set the run.
  std::optional<double> last_time_s_;
  std::optional<double> last_measured_deg_;
  bool profile_done_said_ = false;
  ControlSample last_;
  int64_t updates_ = 0;
  std::string json_;
  std::vector<std::string> messages_;
};

}  // namespace softsight
