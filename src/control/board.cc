// Shared with the firmware: plain C++11, no heap, C headers only (see board.h).
#include "control/board.h"

namespace softsight {
namespace {

float Clamp(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }

}  // namespace

const char* CheckBoardConfig(const BoardConfig& c) {
  if (c.pressure_limit_pa <= 0) return "pressure_limit_pa must be > 0";
  if (c.guard_margin_pa < 0 || c.guard_release_pa < 0 ||
      c.guard_margin_pa + c.guard_release_pa >= c.pressure_limit_pa) {
    return "guard_margin_pa + guard_release_pa must be >= 0 and below pressure_limit_pa";
  }
  if (c.loop_hz < 200) return "loop_hz must be >= 200";
  if (c.watchdog_ms < 10) return "watchdog_ms must be >= 10";
  if (!(c.kp_per_kpa >= 0.0f) || !(c.ki_per_kpa_s >= 0.0f)) return "kp/ki must be >= 0";
  if (c.deadband_pa < 0) return "deadband_pa must be >= 0";
  return 0;
}

float PressureLoop::update(int32_t setpoint_pa, int32_t pressure_pa) {
  const float error_kpa = static_cast<float>(setpoint_pa - pressure_pa) * 0.001f;
  const float dt_s = 1.0f / static_cast<float>(config_.loop_hz);
  if (setpoint_pa - pressure_pa < config_.deadband_pa &&
      pressure_pa - setpoint_pa < config_.deadband_pa) {
    return 0.0f;  // Hold: both valves closed, integral frozen.
  }
  const float unclamped = config_.kp_per_kpa * error_kpa + integral_;
  // Conditional integration: only while the output is not saturated in the error's direction.
  const bool saturated_up = unclamped >= 1.0f && error_kpa > 0.0f;
  const bool saturated_down = unclamped <= -1.0f && error_kpa < 0.0f;
  if (!saturated_up && !saturated_down) {
    integral_ = Clamp(integral_ + config_.ki_per_kpa_s * error_kpa * dt_s, -1.0f, 1.0f);
  }
  const float duty = Clamp(config_.kp_per_kpa * error_kpa + integral_, -1.0f, 1.0f);
  return duty < 0.0f ? Clamp(duty * vent_scale_, -1.0f, 0.0f) : duty;
}

Board::Board(const BoardConfig& config) : config_(config), loop_(config) {}

uint16_t Board::flags() const {
  uint16_t f = 0;
  if (mode_ == Mode::kIdle || mode_ == Mode::kStopped || mode_ == Mode::kWatchdog || guard_) {
    f |= wire::kFlagVented;
  }
  if (mode_ == Mode::kWatchdog) f |= wire::kFlagWatchdog;
  if (guard_) f |= wire::kFlagLimit;
  if (mode_ == Mode::kDuty) f |= wire::kFlagOpenLoop;
  if (mode_ == Mode::kPressure) f |= wire::kFlagClosedLoop;
  if (handshake_) f |= wire::kFlagHandshake;
  if (rejected_ != rejected_reported_) f |= wire::kFlagRejected;
  return f;
}

size_t Board::receive(char c, uint32_t now_ms) {
  const wire::LineAssembler::Event event = assembler_.push(c);
  if (event == wire::LineAssembler::Event::kTooLong) {
    ++rejected_;
    return 0;
  }
  if (event != wire::LineAssembler::Event::kLine) return 0;
  wire::Message message;
  const wire::DecodeStatus status =
      wire::DecodeLine(assembler_.line(), assembler_.length(), &message);
  if (status == wire::DecodeStatus::kEmpty) return 0;
  if (status != wire::DecodeStatus::kOk || !wire::IsHostCommand(message.type)) {
    ++rejected_;  // Never acted on, never answered: the host times out and retries.
    return 0;
  }
  last_valid_ms_ = now_ms;
  return handle(message, now_ms);
}

size_t Board::handle(const wire::Message& m, uint32_t now_ms) {
  if (m.type == wire::MessageType::kHello) {
    // A new session starts from the safe state.
    mode_ = Mode::kIdle;
    loop_.reset();
    // A host's gains last for its session only: the next one starts from the board's own.
    loop_.set_gains(config_.kp_per_kpa, config_.ki_per_kpa_s, 1.0f);
    setpoint_pa_ = 0;
    command_duty_permille_ = 0;
    if (m.args[0] != wire::kProtocolVersion) {
      handshake_ = false;
      return answer_error(0, wire::kErrVersion);
    }
    handshake_ = true;
    wire::Message hi;
    hi.type = wire::MessageType::kHelloReply;
    hi.argc = 4;
    hi.args[0] = wire::kProtocolVersion;
    hi.args[1] = config_.pressure_limit_pa;
    hi.args[2] = config_.loop_hz;
    hi.args[3] = config_.watchdog_ms;
    return wire::EncodeMessage(hi, reply_, sizeof(reply_));
  }
  const int32_t seq = m.args[0];
  if (!handshake_) return answer_error(seq, wire::kErrNoHello);
  switch (m.type) {
    case wire::MessageType::kSetPressure:
      if (m.args[1] < 0 || m.args[1] > config_.pressure_limit_pa) {
        return answer_error(seq, wire::kErrRange);
      }
      if (mode_ != Mode::kPressure) loop_.reset();
      mode_ = Mode::kPressure;
      setpoint_pa_ = m.args[1];
      break;
    case wire::MessageType::kSetDuty:
      if (m.args[1] < -1000 || m.args[1] > 1000) return answer_error(seq, wire::kErrRange);
      mode_ = Mode::kDuty;
      command_duty_permille_ = m.args[1];
      setpoint_pa_ = 0;
      break;
    case wire::MessageType::kSetGains:
      if (m.args[1] < 0 || m.args[1] > wire::kMaxGainPermille || m.args[2] < 0 ||
          m.args[2] > wire::kMaxGainPermille || m.args[3] < 1 ||
          m.args[3] > wire::kMaxVentPermille) {
        return answer_error(seq, wire::kErrRange);
      }
      loop_.set_gains(static_cast<float>(m.args[1]) * 0.001f,
                      static_cast<float>(m.args[2]) * 0.001f,
                      static_cast<float>(m.args[3]) * 0.001f);
      break;
    case wire::MessageType::kStop:
      mode_ = Mode::kStopped;
      setpoint_pa_ = 0;
      command_duty_permille_ = 0;
      loop_.reset();
      break;
    case wire::MessageType::kRead:
    case wire::MessageType::kPing:
    default:
      break;
  }
  return answer_state(seq, now_ms);
}

size_t Board::answer_state(int32_t seq, uint32_t now_ms) {
  wire::Message s;
  s.type = wire::MessageType::kState;
  s.argc = 7;
  s.args[0] = seq;
  s.args[1] = static_cast<int32_t>(now_ms & 0x7FFFFFFFu);
  s.args[2] = pressure_pa_;
  s.args[3] = mode_ == Mode::kPressure ? setpoint_pa_ : 0;
  s.args[4] = duty_permille_;
  s.args[5] = flags();
  s.args[6] = static_cast<int32_t>(rejected_ & 0x7FFFFFFFu);
  rejected_reported_ = rejected_;
  return wire::EncodeMessage(s, reply_, sizeof(reply_));
}

size_t Board::answer_error(int32_t seq, int32_t code) {
  wire::Message e;
  e.type = wire::MessageType::kError;
  e.argc = 2;
  e.args[0] = seq;
  e.args[1] = code;
  return wire::EncodeMessage(e, reply_, sizeof(reply_));
}

ValveOutputs Board::update(uint32_t now_ms, int32_t pressure_pa) {
  pressure_pa_ = pressure_pa;
  const bool active = mode_ == Mode::kPressure || mode_ == Mode::kDuty;
  if (active && now_ms - last_valid_ms_ > config_.watchdog_ms) {
    mode_ = Mode::kWatchdog;
    setpoint_pa_ = 0;
    command_duty_permille_ = 0;
    loop_.reset();
  }

  const int32_t trip_pa = config_.pressure_limit_pa - config_.guard_margin_pa;
  if (pressure_pa >= trip_pa) guard_ = true;
  if (guard_ && pressure_pa < trip_pa - config_.guard_release_pa) guard_ = false;

  float duty = 0.0f;
  if (mode_ == Mode::kPressure) {
    // Never ask the loop for more than the guard allows, so it does not fight the guard.
    int32_t target = setpoint_pa_;
    const int32_t ceiling = trip_pa - config_.guard_release_pa;
    if (target > ceiling) target = ceiling;
    duty = loop_.update(target, pressure_pa);
  } else if (mode_ == Mode::kDuty) {
    duty = static_cast<float>(command_duty_permille_) * 0.001f;
  }

  ValveOutputs out;  // Safe state.
  if (guard_) {
    loop_.unwind_inflation();
    duty_permille_ = -1000;
    return out;
  }
  if (mode_ != Mode::kPressure && mode_ != Mode::kDuty) {
    duty_permille_ = 0;
    return out;
  }
  duty_permille_ = static_cast<int32_t>(duty * 1000.0f + (duty >= 0.0f ? 0.5f : -0.5f));
  out.inflate = duty > 0.0f ? duty : 0.0f;
  out.pump = duty > 0.0f ? 1.0f : 0.0f;
  out.deflate = duty < 0.0f ? -duty : 0.0f;
  return out;
}

}  // namespace softsight
