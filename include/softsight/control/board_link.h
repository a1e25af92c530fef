// The host side of the wire protocol (docs/protocol.md): handshake, commands, and the board's
// answers, over any Transport. Every command waits for the answer with its sequence number;
// rejected lines (garbage, truncated, bad CRC) and stale answers are counted and skipped. Each
// try has a fixed deadline, reply_timeout_ms after the line went out, however much else the
// board says meanwhile, so a command ends within (retries + 1) * reply_timeout_ms.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <stdexcept>
#include <string>

#include "softsight/control/transport.h"

namespace softsight {

// The wire format itself is internal to the control library (shared with the firmware:
// docs/protocol.md).
namespace wire {
struct Message;
enum class MessageType : uint8_t;
}  // namespace wire

struct LinkOptions {
  int baud = 115200;          // Serial baud rate. Default 115200 (a 60-byte line takes ~5 ms).
  int reply_timeout_ms = 100; // Deadline of each try, from sending it. Default 100 ms.
  int retries = 2;            // Re-sends before giving up with an error. Default 2.

  bool Check(std::string* error) const;
};

// What the link takes from its surroundings: the clock and the user's stop request. Tests inject a
// simulated clock; `softsight control` passes its Ctrl-C / SIGTERM flag.
struct LinkEnvironment {
  // Monotonic time in milliseconds. Empty: std::chrono::steady_clock.
  std::function<int64_t()> now_ms{};
  // Polled while waiting for an answer (at least every kStopPollMs); true ends the wait with
  // StopRequested. Never consulted by stop(), which must vent whatever happens. Empty: never.
  std::function<bool()> stop_requested{};
};

// Thrown by a wait for an answer that a stop request cut short: not an error of the link.
class StopRequested : public std::runtime_error {
 public:
  StopRequested() : std::runtime_error("stop requested") {}
};

// The highest pressure limit a $HI may report, kPa: more is no soft actuator's limit but a wrong
// or corrupted board configuration.
constexpr double kMaxBoardPressureLimitKpa = 1000.0;

// The range a sensed pressure can physically have, kPa (gauge): from full vacuum to the highest
// reading a soft-robot pressure sensor gives (twice the highest limit a board may report).
// An answer outside it, or with a duty outside -1..1, an echoed setpoint outside
// 0..kMaxBoardPressureLimitKpa, undefined flag bits or negative counts, is not believed: it is
// counted as a rejected line and the command sent again, never used or written.
constexpr double kMinSensedPressureKpa = -101.325;
constexpr double kMaxSensedPressureKpa = 2 * kMaxBoardPressureLimitKpa;

// How long a STOP is tried, all re-sends together, ms: venting is tried at once and again
// (every reply_timeout_ms, beyond `retries` if need be) until this is spent, but a silent board
// cannot hold the exit for retries x reply_timeout_ms (up to 110 s); its watchdog vents on its
// own when the commands stop.
constexpr int kMaxStopMs = 1500;

// The largest inner-loop gain the wire carries (duty per kPa, or per kPa*s): a full valve swing
// for a pascal of error, far beyond any useful loop.
constexpr double kMaxInnerGain = 1000.0;
// The range of the venting factor the wire carries.
constexpr double kMinVentScale = 0.001;
constexpr double kMaxVentScale = 10.0;

// Gains the host sets on the board's inner pressure loop for one session ($GAIN, right after the
// handshake), when the board's own do not suit the plant: a tube between the valves and the
// chamber delays the loop, and gains made for a short tube make it oscillate. `softsight
// identify` measures the delay and chooses them. kp_per_kpa 0 (the default): the board's own
// gains, nothing sent.
struct InnerLoopGains {
  double kp_per_kpa = 0.0;    // Valve duty per kPa of pressure error; 0: the board's own gains.
  double ki_per_kpa_s = 0.0;  // Valve duty per kPa*s.
  // The duty is multiplied by this when the loop vents: a vent faster than the pump would
  // otherwise give the loop more gain one way than the other. Default 1.
  double vent_scale = 1.0;

  bool given() const { return kp_per_kpa > 0.0; }
  // Each in its range. False names the bad field in `error`.
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
  uint16_t flags = 0;           // The board's <flags> bits (docs/protocol.md).
  uint32_t board_rejected = 0;  // Lines the board has rejected since power-up/handshake.

  bool vented() const;    // Outputs in the safe state (pump off, inflate closed, vent open).
  bool watchdog() const;  // Vented because no valid command arrived in time.
  bool limit() const;     // The pressure limit guard is overriding the outputs.
};

struct LinkStats {
  uint64_t rejected_lines = 0;  // Lines from the board that failed decoding (never acted on).
  uint64_t stale_answers = 0;   // Valid answers to an earlier sequence number.
  uint64_t resends = 0;         // Commands sent again after a timeout.
};

class BoardLink {
 public:
  // Longest single wait on the transport, so that a stop request is seen within this.
  static constexpr int kStopPollMs = 20;

  // `transport` must outlive the link.
  BoardLink(Transport& transport, LinkOptions options = {}, LinkEnvironment environment = {});

  // Versioned handshake. Throws InputError naming the port when the board does not answer,
  // speaks another protocol version, or reports a nonsensical limit (pressure limit <= 0 or above
  // kMaxBoardPressureLimitKpa, loop rate or watchdog <= 0).
  BoardInfo handshake();

  BoardState set_pressure_kpa(double setpoint_kpa);
  BoardState set_duty(double duty);  // [-1, 1]; > 0 inflate, < 0 vent.
  // The board's inner pressure loop gains for this session ($GAIN; a $HELLO restores the
  // board's own): duty per kPa of error and per kPa*s, each in [0, kMaxInnerGain], and the
  // factor of the duty when venting, in [kMinVentScale, kMaxVentScale]. Throws
  // InputError naming the port when the board refuses them, or when it answers READ but not
  // GAIN: a firmware that predates the command.
  BoardState set_inner_loop_gains(double kp_per_kpa, double ki_per_kpa_s, double vent_scale);
  BoardState read_state();
  // Vent to the safe state (ignores stop requests; gives up after kMaxStopMs).
  BoardState stop();
  BoardState heartbeat();

  const LinkStats& stats() const { return stats_; }
  // When the last command was written to the port (its first try), on the steady clock: the end
  // of a frame's capture-to-command latency.
  std::chrono::steady_clock::time_point last_sent() const { return last_sent_; }
  const std::string& port_name() const { return transport_.name(); }
  const LinkOptions& options() const { return options_; }

 private:
  enum class Verdict { kAnswer, kStale, kRejected };
  // Sends `line` up to retries + 1 times and returns the first line `classify` calls the answer;
  // nothing when every try passed its deadline, or all of them `budget_ms` (> 0). Throws
  // StopRequested when `honour_stop` and the user asked to stop. `rejected` receives how many
  // lines of this exchange were rejected, and `why` the reason for the last one.
  std::optional<wire::Message> exchange(
      const std::string& line, bool honour_stop,
      const std::function<Verdict(const wire::Message&)>& classify, int64_t budget_ms = 0,
      uint64_t* rejected = nullptr, std::string* why = nullptr);
  // Sends `type` with its sequence number and `values`; the board's STATE. Throws InputError
  // when the board refuses it, or after the retries; with `allow_silence`, a board that never
  // answered (and said nothing rejected) gives nothing instead.
  std::optional<BoardState> request(wire::MessageType type, std::initializer_list<int32_t> values,
                                    const char* what, bool allow_silence = false);
  int64_t now_ms() const;

  Transport& transport_;
  LinkOptions options_;
  LinkEnvironment environment_;
  int32_t next_seq_ = 1;
  LinkStats stats_;
  std::chrono::steady_clock::time_point last_sent_{};
};

}  // namespace softsight
