#include "web/rig_panel.h"

#include <cstdio>
#include <exception>

#include "softsight/control/actuator_model.h"
#include "pipeline/control_sample_columns.h"
#include "softsight/core/format.h"
#include "stream/stream_format.h"

namespace softsight {
namespace {

using Action = ControllerOutput::Action;

const char* ActionName(Action action) {
  switch (action) {
    case Action::kTrack: return "track";
    case Action::kHold: return "hold";
    case Action::kVent: return "vent";
  }
  return "vent";
}

// ,"key":value (null when absent), with a fixed number of decimals.
void AppendField(std::string& out, const char* key, std::optional<double> value, int decimals = 3) {
  out += ",\"";
  out += key;
  out += "\":";
  if (!value) {
    out += "null";
    return;
  }
  char number[40];
  std::snprintf(number, sizeof number, "%.*f", decimals, *value);
  out += number;
}

void AppendBool(std::string& out, const char* key, bool value) {
  out += ",\"";
  out += key;
  out += "\":";
  out += value ? "true" : "false";
}

}  // namespace

RigPanel::RigPanel(ControlSession& session, const BoardInfo& board, std::string port,
                   const ActuatorModel& model)
    : session_(session), board_(board), port_(std::move(port)), model_(model) {
  json_.reserve(512);
}

const char* RigPanel::StateName(State state) {
  switch (state) {
    case State::kIdle: return "idle";
    case State::kRunning: return "running";
    case State::kHolding: return "holding";
    case State::kFailed: return "failed";
  }
  return "failed";
}

std::string RigPanel::refused(const TargetProfile& profile) const {
  if (state_ == State::kFailed) {
    return "rig: the link to the board failed; nothing more is sent (restart serve)";
  }
  const double max_kpa = session_.controller().options().max_kpa;
  if (auto problem = OutsideReach(model_, profile.lowest_deg(), profile.highest_deg(), max_kpa)) {
    return "rig: " + *problem + "; nothing changed";
  }
  if (auto problem = OutsideRateReach(model_, profile)) return "rig: " + *problem + "; nothing changed";
  return "";
}

std::string RigPanel::run_target(double target_deg, uint64_t page) {
  const TargetProfile profile = TargetProfile::Constant(target_deg);
  std::string why = refused(profile);
  if (!why.empty()) return why;
  if (state_ == State::kRunning && profile_.duration_s() == 0.0) {
    // The run goes on to the new target: no new start (the integral and slew carry over).
    profile_ = profile;
    owner_ = page;
    messages_.push_back("rig: target " + FixedNumber(target_deg, 1) + " deg");
    return "";
  }
  start(profile, page, "target " + FixedNumber(target_deg, 1) + " deg");
  return "";
}

std::string RigPanel::run_profile(const TargetProfile& profile, uint64_t page) {
  std::string why = refused(profile);
  if (!why.empty()) return why;
  start(profile, page,
        "profile of " + std::to_string(profile.segments().size()) + " segments, " +
            FixedNumber(profile.duration_s(), 1) + " s, " + FixedNumber(profile.lowest_deg(), 1) +
            ".." + FixedNumber(profile.highest_deg(), 1) + " deg");
  return "";
}

void RigPanel::start(const TargetProfile& profile, uint64_t page, const std::string& what) {
  profile_ = profile;
  owner_ = page;
  run_start_s_.reset();  // Time 0 is the next frame's.
  hold_since_s_.reset();
  profile_done_said_ = false;
  state_ = State::kRunning;
  messages_.push_back("rig: running, " + what);
}

template <typename Call>
void RigPanel::guarded(Call call) {
  try {
    call();
  } catch (const std::exception& error) {
    state_ = State::kFailed;
    messages_.push_back(std::string("rig: ") + error.what() +
                        "; nothing more is sent: the board's watchdog vents within " +
                        std::to_string(board_.watchdog_ms) + " ms");
  }
}

void RigPanel::vent_now(const std::string& message) {
  state_ = State::kIdle;
  hold_since_s_.reset();
  guarded([&] { last_ = session_.vent(last_time_s_.value_or(0.0), last_measured_deg_); });
  if (state_ != State::kFailed) messages_.push_back(message);
  ++updates_;
}

void RigPanel::stop(const std::string& who) {
  if (state_ == State::kFailed) {
    // The link failed once; it may answer a STOP still. Its own bound (kMaxStopMs) keeps this
    // short, and the board's watchdog vents anyway.
    try {
      last_.board = session_.stop();
      messages_.push_back("rig: STOP (" + who + ") sent after the failure: vented");
    } catch (const std::exception& error) {
      messages_.push_back("rig: STOP (" + who + "): " + error.what() +
                          "; the board's watchdog vents within " + std::to_string(board_.watchdog_ms) +
                          " ms");
    }
    ++updates_;
    return;
  }
  const bool was_running = state_ != State::kIdle;
  vent_now("rig: STOP (" + who + ")" + (was_running ? ": run ended, vented" : ": vented"));
}

void RigPanel::page_left(uint64_t page) {
  if (state_ != State::kRunning || page != owner_) return;
  const std::optional<double> held = last_.action == Action::kVent ? std::nullopt : last_.setpoint_kpa;
  if (!held) {
    vent_now("rig: the page running the loop left mid-run (the loop was venting): vented");
    return;
  }
  state_ = State::kHolding;
  held_kpa_ = *held;
  hold_since_s_ = last_time_s_.value_or(0.0);
  messages_.push_back("rig: the page running the loop left mid-run: holding " +
                      FixedNumber(held_kpa_, 1) + " kPa for " +
                      ShortNumber(session_.controller().options().hold_s) + " s, then venting");
}

void RigPanel::consume(const Frame& frame, const FrameResult& result) {
  step(frame.time_s, result.measurement.angle_deg);
}

void RigPanel::step(double time_s, std::optional<double> measured_deg) {
  // The same frame again (a re-track after an edit) is no new time step for the loop.
  if (last_time_s_ && time_s <= *last_time_s_) return;
  last_time_s_ = time_s;
  last_measured_deg_ = measured_deg;
  switch (state_) {
    case State::kFailed:
      return;
    case State::kIdle:
      guarded([&] { last_ = session_.vent(time_s, measured_deg); });
      break;
    case State::kRunning: {
      if (!run_start_s_) run_start_s_ = time_s;
      const double elapsed_s = time_s - *run_start_s_;
      guarded([&] {
        session_.set_angle_target(profile_.at(elapsed_s));
        last_ = session_.step(time_s, measured_deg);
      });
      if (profile_.duration_s() > 0.0 && elapsed_s > profile_.duration_s() && !profile_done_said_) {
        profile_done_said_ = true;
        messages_.push_back("rig: the profile ended; holding its last target " +
                            FixedNumber(profile_.at(elapsed_s), 1) + " deg until STOP");
      }
      break;
    }
    case State::kHolding: {
      const double hold_s = session_.controller().options().hold_s;
      // (A microsecond's slack: frame times are index / fps, and 15 frames of 1/30 s are 0.5 s.)
      if (time_s - *hold_since_s_ >= hold_s - 1e-6) {
        vent_now("rig: held " + ShortNumber(hold_s) + " s after the page left: vented");
        return;
      }
      guarded([&] {
        last_ = session_.step_pressure(time_s, held_kpa_, measured_deg);
        last_.action = Action::kHold;
      });
      break;
    }
  }
  ++updates_;
}

const std::string& RigPanel::status_json() {
  json_.assign("{\"type\":\"rig\",\"state\":\"");
  json_ += StateName(state_);
  json_ += "\",\"action\":\"";
  json_ += ActionName(last_.action);
  json_ += '"';
  AppendField(json_, "t", last_.time_s);
  AppendField(json_, "target_deg", last_.target_deg, 2);
  AppendField(json_, "measured_deg", last_.measured_deg, 2);
  AppendField(json_, "setpoint_kpa", last_.setpoint_kpa, 2);
  AppendField(json_, "pressure_kpa", last_.board.pressure_kpa, 2);
  AppendField(json_, "board_setpoint_kpa", last_.board.setpoint_kpa, 2);
  AppendField(json_, "duty", last_.board.duty, 3);
  AppendField(json_, "flags", last_.board.flags, 0);
  AppendBool(json_, "vented", last_.board.vented());
  AppendBool(json_, "watchdog", last_.board.watchdog());
  AppendBool(json_, "limit", last_.board.limit());
  const bool profiled = state_ == State::kRunning && profile_.duration_s() > 0.0 && run_start_s_;
  AppendField(json_, "profile_s", profiled ? std::optional(*last_time_s_ - *run_start_s_) : std::nullopt);
  AppendField(json_, "profile_length_s", profile_.duration_s() > 0.0 ? std::optional(profile_.duration_s()) : std::nullopt);
  AppendField(json_, "hold_left_s",
              state_ == State::kHolding
                  ? std::optional(session_.controller().options().hold_s -
                                  (*last_time_s_ - *hold_since_s_))
                  : std::nullopt);
  json_ += ",\"updates\":" + std::to_string(updates_) + "}";
  return json_;
}

std::vector<CsvColumn> RigPanel::columns() const {
  std::vector<CsvColumn> columns = ControlSampleColumns(&last_);
  columns.push_back(NumberColumn("rig_state", [this](const FrameResult&) -> std::optional<double> {
    return static_cast<double>(static_cast<int>(state_));
  }));
  return columns;
}

std::string RigPanel::limits_json() const {
  const ControllerOptions& c = session_.controller().options();
  std::string json = "{\"port\":";
  AppendJsonString(port_, json);
  json += ",\"protocol\":" + std::to_string(board_.protocol_version);
  AppendField(json, "board_limit_kpa", board_.pressure_limit_kpa, 1);
  json += ",\"loop_hz\":" + std::to_string(board_.loop_hz);
  json += ",\"watchdog_ms\":" + std::to_string(board_.watchdog_ms);
  AppendField(json, "min_kpa", c.min_kpa, 1);
  AppendField(json, "max_kpa", c.max_kpa, 1);
  AppendField(json, "max_rate_kpa_per_s", c.max_rate_kpa_per_s, 1);
  AppendField(json, "hold_s", c.hold_s, 2);
  AppendBool(json, "model_based", session_.controller().model_based());
  if (model_.identified()) {
    const ActuatorReach reach = ReachOf(model_, c.max_kpa);
    AppendField(json, "reach_min_deg", reach.most_bent_deg, 1);
    AppendField(json, "reach_max_deg", reach.straightest_deg, 1);
  } else {
    AppendField(json, "reach_min_deg", 0.0, 1);
    AppendField(json, "reach_max_deg", 180.0, 1);
  }
  return json + "}";
}

std::vector<std::string> RigPanel::take_messages() {
  std::vector<std::string> out;
  out.swap(messages_);
  return out;
}

}  // namespace softsight
