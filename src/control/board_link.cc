#include "softsight/control/board_link.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "control/control_options.h"
#include "control/protocol.h"
#include "softsight/core/error.h"

namespace softsight {

bool BoardState::vented() const { return (flags & wire::kFlagVented) != 0; }
bool BoardState::watchdog() const { return (flags & wire::kFlagWatchdog) != 0; }
bool BoardState::limit() const { return (flags & wire::kFlagLimit) != 0; }

namespace {

std::string Encode(const wire::Message& m) {
  char buffer[wire::kLineBufferSize];
  const size_t n = wire::EncodeMessage(m, buffer, sizeof(buffer));
  return std::string(buffer, n);
}

const char* ErrorName(int32_t code) {
  switch (code) {
    case wire::kErrVersion: return "protocol version mismatch";
    case wire::kErrNoHello: return "no handshake yet";
    case wire::kErrRange: return "argument out of range";
    default: return "unknown error code";
  }
}

// Why a $STATE answer cannot be what a board measures, or nullptr when it can.
const char* ImplausibleState(const wire::Message& m) {
  const double pressure_kpa = m.args[2] * 1e-3;
  const double setpoint_kpa = m.args[3] * 1e-3;
  if (!(pressure_kpa >= kMinSensedPressureKpa && pressure_kpa <= kMaxSensedPressureKpa)) {
    return "a sensed pressure below vacuum or above any sensor's range";
  }
  if (!(setpoint_kpa >= 0.0 && setpoint_kpa <= kMaxBoardPressureLimitKpa)) {
    return "an echoed setpoint outside 0..1000 kPa";
  }
  if (m.args[4] < -1000 || m.args[4] > 1000) return "a duty outside -1..1";
  if (m.args[5] < 0 || m.args[5] >= 2 * wire::kFlagRejected) return "undefined flag bits";
  if (m.args[6] < 0) return "a negative count of rejected lines";
  if (m.args[1] < 0) return "a negative board clock";
  return nullptr;
}

}  // namespace

bool LinkOptions::Check(std::string* error) const {
  // Each field's range is its row in control/control_options.cc.
  if (const auto problem = CheckOptions(LinkOptionsTable(), *this)) return Fail(error, *problem);
  return true;
}

bool InnerLoopGains::Check(std::string* error) const {
  // Each field's range is its row in control/control_options.cc; only the pairing here.
  // Each field's range is its row in control/control_options.cc.
  if (const auto problem = CheckOptions(InnerLoopGainsTable(), *this)) return Fail(error, *problem);
  return true;
}

// The wire carries gains in per-mille; its limit and the host's are one.
static_assert(kMaxInnerGain * 1000.0 == static_cast<double>(wire::kMaxGainPermille));
static_assert(kMaxVentScale * 1000.0 == static_cast<double>(wire::kMaxVentPermille));
static_assert(kMinVentScale * 1000.0 == 1.0);

BoardLink::BoardLink(Transport& transport, LinkOptions options, LinkEnvironment environment)
    : transport_(transport), options_(options), environment_(std::move(environment)) {}

int64_t BoardLink::now_ms() const {
  if (environment_.now_ms) return environment_.now_ms();
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::optional<wire::Message> BoardLink::exchange(
    const std::string& line, bool honour_stop,
    const std::function<Verdict(const wire::Message&)>& classify, int64_t budget_ms,
    uint64_t* rejected, std::string* why) {
  const int64_t give_up_ms = budget_ms > 0 ? now_ms() + budget_ms : 0;
  // With a budget (STOP) the tries go on until it is spent, however short each try is: a loaded
  // host or board that misses three 100 ms deadlines must not give up venting after 300 ms.
  for (int attempt = 0; attempt <= options_.retries || give_up_ms != 0; ++attempt) {
    if (give_up_ms != 0 && now_ms() >= give_up_ms) break;
    if (attempt > 0) ++stats_.resends;
    if (honour_stop && environment_.stop_requested && environment_.stop_requested()) {
      throw StopRequested();
    }
    transport_.write_line(line);
    if (attempt == 0) last_sent_ = std::chrono::steady_clock::now();
    // One deadline per try: lines that are not the answer (chatter, stale answers, garbage) are
    // counted but never extend it.
    int64_t deadline_ms = now_ms() + options_.reply_timeout_ms;
    if (give_up_ms != 0) deadline_ms = std::min(deadline_ms, give_up_ms);
    while (true) {
      if (honour_stop && environment_.stop_requested && environment_.stop_requested()) {
        throw StopRequested();
      }
      const int64_t left_ms = deadline_ms - now_ms();
      if (left_ms <= 0) break;
      const auto reply =
          transport_.read_line(static_cast<int>(std::min<int64_t>(left_ms, kStopPollMs)));
      if (!reply) continue;
      wire::Message m;
      const wire::DecodeStatus status = wire::DecodeLine(reply->data(), reply->size(), &m);
      if (status == wire::DecodeStatus::kEmpty) continue;
      const Verdict verdict = status == wire::DecodeStatus::kOk ? classify(m) : Verdict::kRejected;
      if (verdict == Verdict::kAnswer) return m;
      if (verdict == Verdict::kStale) {
        ++stats_.stale_answers;
      } else {
        ++stats_.rejected_lines;
        if (rejected != nullptr) ++*rejected;
        if (why != nullptr && status != wire::DecodeStatus::kOk) *why = wire::DecodeStatusName(status);
      }
    }
  }
  return std::nullopt;
}

BoardInfo BoardLink::handshake() {
  wire::Message hello;
  hello.type = wire::MessageType::kHello;
  hello.argc = 1;
  hello.args[0] = wire::kProtocolVersion;
  const std::optional<wire::Message> reply =
      exchange(Encode(hello), /*honour_stop=*/true, [this](const wire::Message& m) {
        if (m.type == wire::MessageType::kError && m.args[1] == wire::kErrVersion) {
          throw InputError(port_name() + ": the board does not speak protocol version " +
                           std::to_string(wire::kProtocolVersion) + "; update its firmware");
        }
        if (wire::IsHostCommand(m.type)) return Verdict::kRejected;
        return m.type == wire::MessageType::kHelloReply ? Verdict::kAnswer : Verdict::kStale;
      });
  if (!reply) {
    throw InputError(port_name() + ": no answer to the handshake after " +
                     std::to_string(options_.retries + 1) + " tries of " +
                     std::to_string(options_.reply_timeout_ms) +
                     " ms; is the softsight firmware (protocol version " +
                     std::to_string(wire::kProtocolVersion) + ") running, at " +
                     std::to_string(options_.baud) + " baud?");
  }
  const wire::Message& m = *reply;
  if (m.args[0] != wire::kProtocolVersion) {
    throw InputError(port_name() + ": the board speaks protocol version " +
                     std::to_string(m.args[0]) + ", softsight speaks " +
                     std::to_string(wire::kProtocolVersion) + "; update its firmware");
  }
  BoardInfo info;
  info.protocol_version = m.args[0];
  info.pressure_limit_kpa = m.args[1] * 1e-3;
  info.loop_hz = m.args[2];
  info.watchdog_ms = m.args[3];
  // A limit the host cannot trust makes every later check meaningless: refuse to start.
  if (!(info.pressure_limit_kpa > 0.0 && info.pressure_limit_kpa <= kMaxBoardPressureLimitKpa) ||
      info.loop_hz <= 0 || info.watchdog_ms <= 0) {
    char text[160];
    std::snprintf(text, sizeof(text),
                  "pressure limit %.3f kPa, loop %d Hz, watchdog %d ms (expected a limit in "
                  "(0, %.0f] kPa and a positive rate and watchdog)",
                  info.pressure_limit_kpa, info.loop_hz, info.watchdog_ms,
                  kMaxBoardPressureLimitKpa);
    throw InputError(port_name() + ": the board's handshake reports a nonsensical " + text +
                     "; check its firmware and configuration");
  }
  return info;
}

BoardState BoardLink::set_pressure_kpa(double setpoint_kpa) {
  return *request(wire::MessageType::kSetPressure,
                  {static_cast<int32_t>(std::lround(setpoint_kpa * 1e3))}, "SETP");
}

BoardState BoardLink::set_duty(double duty) {
  return *request(wire::MessageType::kSetDuty, {static_cast<int32_t>(std::lround(duty * 1e3))},
                  "DUTY");
}

BoardState BoardLink::set_inner_loop_gains(double kp_per_kpa, double ki_per_kpa_s,
                                           double vent_scale) {
  // Per-mille on the wire; a gain the wire cannot carry is the caller's bug (the config's
  // ranges keep it within kMaxInnerGain).
  const auto permille = [](double gain) {
    return static_cast<int32_t>(std::lround(std::clamp(gain, 0.0, kMaxInnerGain) * 1e3));
  };
  if (std::optional<BoardState> state =
          request(wire::MessageType::kSetGains,
                  {permille(kp_per_kpa), permille(ki_per_kpa_s),
                   static_cast<int32_t>(std::lround(
                       std::clamp(vent_scale, kMinVentScale, kMaxVentScale) * 1e3))},
                  "GAIN", /*allow_silence=*/true)) {
    return *state;
  }
  // Silence. A board that answers READ now is running but ignored GAIN: a firmware from before
  // the command (it rejects an unknown word without an answer, docs/protocol.md).
  const BoardState alive = read_state();
  throw InputError(port_name() + ": the board does not know the GAIN command (no answer to " +
                   std::to_string(options_.retries + 1) + " tries, though it answers READ; " +
                   std::to_string(alive.board_rejected) +
                   " lines rejected by it): its firmware predates inner-loop gains set by the "
                   "host; update it (firmware/README.md), or remove control.inner_loop from the "
                   "config to keep the board's own gains; vented");
}

BoardState BoardLink::read_state() { return *request(wire::MessageType::kRead, {}, "READ"); }
BoardState BoardLink::stop() { return *request(wire::MessageType::kStop, {}, "STOP"); }
BoardState BoardLink::heartbeat() { return *request(wire::MessageType::kPing, {}, "PING"); }

std::optional<BoardState> BoardLink::request(wire::MessageType type,
                                             std::initializer_list<int32_t> values,
                                             const char* what, bool allow_silence) {
  wire::Message command;
  command.type = type;
  command.argc = static_cast<uint8_t>(wire::ArgumentCount(type));
  const int32_t seq = next_seq_;
  next_seq_ = next_seq_ >= 999999 ? 1 : next_seq_ + 1;
  command.args[0] = seq;
  std::string arguments;  // As sent, for an error message.
  int i = 1;
  for (const int32_t value : values) {
    command.args[i++] = value;
    arguments += ' ';
    arguments += std::to_string(value);
  }
  const bool is_stop = type == wire::MessageType::kStop;
  uint64_t rejected = 0;
  std::string why;
  const std::optional<wire::Message> reply = exchange(
      Encode(command), /*honour_stop=*/!is_stop,
      [seq, &why](const wire::Message& m) {
        if (wire::IsHostCommand(m.type)) {
          why = "a host command echoed back";
          return Verdict::kRejected;
        }
        if (m.type == wire::MessageType::kHelloReply || m.args[0] != seq) return Verdict::kStale;
        if (m.type == wire::MessageType::kState) {
          if (const char* problem = ImplausibleState(m)) {
            why = problem;
            return Verdict::kRejected;
          }
        }
        return Verdict::kAnswer;
      },
      is_stop ? kMaxStopMs : 0, &rejected, &why);
  if (!reply) {
    if (rejected > 0) {
      // The board talks, but nothing it said could be used: not a power or cable problem.
      throw InputError(port_name() + ": no usable answer to " + what + ": " +
                       std::to_string(rejected) + " lines from the board rejected (last: " + why +
                       "); check the board's firmware, baud rate and sensor");
    }
    if (allow_silence) return std::nullopt;
    throw InputError(port_name() + ": no answer to " + what + " after " +
                     (is_stop ? std::to_string(kMaxStopMs) + " ms (the board's watchdog vents)"
                              : std::to_string(options_.retries + 1) + " tries of " +
                                    std::to_string(options_.reply_timeout_ms) + " ms") +
                     "; is the board still powered and running the softsight firmware?");
  }
  const wire::Message& m = *reply;
  if (m.type == wire::MessageType::kError) {
    throw InputError(port_name() + ": the board refused " + std::string(what) + arguments + ": " +
                     ErrorName(m.args[1]));
  }
  BoardState state;
  state.seq = m.args[0];
  state.time_ms = m.args[1];
  state.pressure_kpa = m.args[2] * 1e-3;
  state.setpoint_kpa = m.args[3] * 1e-3;
  state.duty = m.args[4] * 1e-3;
  state.flags = static_cast<uint16_t>(m.args[5]);
  state.board_rejected = static_cast<uint32_t>(m.args[6]);
  return state;
}

}  // namespace softsight
