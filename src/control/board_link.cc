#include "softsight/control/board_link.h"

#include <cmath>

#include "softsight/core/error.h"
#include "control/control_options.h"

namespace softsight {
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

}  // namespace

bool LinkOptions::Check(std::string* error) const {
  // Each field's range is its row in control/control_options.cc.
  if (const auto problem = CheckOptions(LinkOptionsTable(), *this)) return Fail(error, *problem);
  return true;
}

BoardLink::BoardLink(Transport& transport, LinkOptions options)
    : transport_(transport), options_(options) {}

BoardInfo BoardLink::handshake() {
  wire::Message hello;
  hello.type = wire::MessageType::kHello;
  hello.argc = 1;
  hello.args[0] = wire::kProtocolVersion;
  const std::string line = Encode(hello);
  for (int attempt = 0; attempt <= options_.retries; ++attempt) {
    if (attempt > 0) ++stats_.resends;
    transport_.write_line(line);
    while (auto reply = transport_.read_line(options_.reply_timeout_ms)) {
      wire::Message m;
      const wire::DecodeStatus status = wire::DecodeLine(reply->data(), reply->size(), &m);
      if (status == wire::DecodeStatus::kEmpty) continue;
      if (status != wire::DecodeStatus::kOk) {
        ++stats_.rejected_lines;
        continue;
      }
      if (m.type == wire::MessageType::kError && m.args[1] == wire::kErrVersion) {
        throw InputError(port_name() + ": the board does not speak protocol version " +
                         std::to_string(wire::kProtocolVersion) + "; update its firmware");
      }
      if (m.type != wire::MessageType::kHelloReply) {
        ++stats_.stale_answers;
        continue;
      }
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
      return info;
    }
  }
  throw InputError(port_name() + ": no answer to the handshake after " +
                   std::to_string(options_.retries + 1) +
                   " tries; is the softsight firmware running, at " +
                   std::to_string(options_.baud) + " baud?");
}

BoardState BoardLink::set_pressure_kpa(double setpoint_kpa) {
  return request(wire::MessageType::kSetPressure,
                 static_cast<int32_t>(std::lround(setpoint_kpa * 1e3)), "SETP");
}

BoardState BoardLink::set_duty(double duty) {
  return request(wire::MessageType::kSetDuty, static_cast<int32_t>(std::lround(duty * 1e3)),
                 "DUTY");
}

BoardState BoardLink::read_state() { return request(wire::MessageType::kRead, 0, "READ"); }
BoardState BoardLink::stop() { return request(wire::MessageType::kStop, 0, "STOP"); }
BoardState BoardLink::heartbeat() { return request(wire::MessageType::kPing, 0, "PING"); }

BoardState BoardLink::request(wire::MessageType type, int32_t value, const char* what) {
  wire::Message command;
  command.type = type;
  command.argc = static_cast<uint8_t>(wire::ArgumentCount(type));
  const int32_t seq = next_seq_;
  next_seq_ = next_seq_ >= 999999 ? 1 : next_seq_ + 1;
  command.args[0] = seq;
  command.args[1] = value;
  const std::string line = Encode(command);
  for (int attempt = 0; attempt <= options_.retries; ++attempt) {
    if (attempt > 0) ++stats_.resends;
    transport_.write_line(line);
    while (auto reply = transport_.read_line(options_.reply_timeout_ms)) {
      wire::Message m;
      const wire::DecodeStatus status = wire::DecodeLine(reply->data(), reply->size(), &m);
      if (status == wire::DecodeStatus::kEmpty) continue;
      if (status != wire::DecodeStatus::kOk || wire::IsHostCommand(m.type)) {
        ++stats_.rejected_lines;
        continue;
      }
      if (m.type == wire::MessageType::kHelloReply || m.args[0] != seq) {
        ++stats_.stale_answers;
        continue;
      }
      if (m.type == wire::MessageType::kError) {
        throw InputError(port_name() + ": the board refused " + std::string(what) + " " +
                         std::to_string(value) + ": " + ErrorName(m.args[1]));
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
  }
  throw InputError(port_name() + ": no answer to " + what + " after " +
                   std::to_string(options_.retries + 1) +
                   " tries; is the board still powered and running the softsight firmware?");
}

}  // namespace softsight
