// The host side of the wire protocol (docs/protocol.md): handshake, commands, and the board's
// answers, over any Transport. Every command waits for the answer with its sequence number;
// rejected lines (garbage, truncated, bad checksum) and stale answers are counted and skipped.
#pragma once

#include <cstdint>
#include <string>

#include "softsight/control/protocol.h"
#include "softsight/control/transport.h"

namespace softsight {

struct LinkOptions {
  int baud = 115200;          // Serial baud rate. Default 115200 (a 60-byte line takes ~5 ms).
  int reply_timeout_ms = 100; // Wait for an answer this long before re-sending. Default 100 ms.
  int retries = 2;            // Re-sends before giving up with an error. Default 2.

  bool Check(std::string* error) const;
};

// What the board said in its $HI answer.
struct BoardInfo {
  int protocol_version = 0;
  double pressure_limit_kpa = 0.0;
  int loop_hz = 0;
  int watchdog_ms = 0;
};

// The board's state from a $STATE answer, in host units.
struct BoardState {
  int32_t seq = 0;
  int64_t time_ms = 0;          // Board clock.
  double pressure_kpa = 0.0;    // Sensed chamber pressure (gauge).
  double setpoint_kpa = 0.0;    // Active pressure setpoint (0 unless in pressure mode).
  double duty = 0.0;            // Applied duty in [-1, 1]: > 0 inflating, < 0 venting.
  uint16_t flags = 0;           // wire::StateFlag bits.
  uint32_t board_rejected = 0;  // Lines the board has rejected since power-up/handshake.

  bool vented() const { return (flags & wire::kFlagVented) != 0; }
  bool watchdog() const { return (flags & wire::kFlagWatchdog) != 0; }
  bool limit() const { return (flags & wire::kFlagLimit) != 0; }
};

struct LinkStats {
  uint64_t rejected_lines = 0;  // Lines from the board that failed decoding (never acted on).
  uint64_t stale_answers = 0;   // Valid answers to an earlier sequence number.
  uint64_t resends = 0;         // Commands sent again after a timeout.
};

class BoardLink {
 public:
  // `transport` must outlive the link.
  BoardLink(Transport& transport, LinkOptions options = {});

  // Versioned handshake. Throws InputError naming the port when the board does not answer or
  // speaks another protocol version.
  BoardInfo handshake();

  BoardState set_pressure_kpa(double setpoint_kpa);
  BoardState set_duty(double duty);  // [-1, 1]; > 0 inflate, < 0 vent.
  BoardState read_state();
  BoardState stop();                 // Vent to the safe state.
  BoardState heartbeat();

  const LinkStats& stats() const { return stats_; }
  const std::string& port_name() const { return transport_.name(); }

 private:
  BoardState request(wire::MessageType type, int32_t value, const char* what);

  Transport& transport_;
  LinkOptions options_;
  int32_t next_seq_ = 1;
  LinkStats stats_;
};

}  // namespace softsight
