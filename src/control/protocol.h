// The wire protocol between the host and the pressure-control board (docs/protocol.md).
//
// One message per line, plain ASCII, readable in a terminal:
//   $SETP 17 25000*239F\n
// '$', a command word, space-separated decimal integer arguments, '*', four upper-case hex digits
// of the CRC-16/CCITT-FALSE of every byte between '$' and '*', then '\n' ('\r' before it is
// ignored). Pressures are
// gauge pressures in pascals, duties in per-mille, times in milliseconds: integers only, so the
// board never formats or parses a float.
//
// This file is shared with the firmware (firmware/softsight_board): plain C++11, no heap, no
// standard library beyond the C headers an AVR toolchain provides.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace softsight {
namespace wire {

// 2: the check became a CRC-16 (version 1 had an 8-bit XOR, which two flips of the same bit in
// two bytes pass).
const int32_t kProtocolVersion = 2;
// Longest line, from '$' to the checksum digits inclusive (without "\r\n").
const size_t kMaxLineLength = 96;
// Buffer size that holds any encoded line with its "\n" and a terminating NUL.
const size_t kLineBufferSize = kMaxLineLength + 2;
const int kMaxArgs = 7;

enum class MessageType : uint8_t {
  kNone = 0,
  // Host -> board.
  kHello,        // $HELLO <version>
  kSetPressure,  // $SETP <seq> <setpoint_pa>          closed-loop pressure mode
  kSetDuty,      // $DUTY <seq> <duty_permille>        open loop: > 0 inflate, < 0 deflate
  kRead,         // $READ <seq>                        read state, changes nothing
  kStop,         // $STOP <seq>                        vent to the safe state
  kPing,         // $PING <seq>                        heartbeat, changes nothing
  kSetGains,     // $GAIN <seq> <kp> <ki> <vent>       inner-loop gains: per-mille duty per kPa
                 //                                    (kp), per kPa*s (ki); venting's share of
                 //                                    the duty in per-mille (vent)
  // Board -> host.
  kHelloReply,   // $HI <version> <pressure_limit_pa> <loop_hz> <watchdog_ms>
  kState,        // $STATE <seq> <time_ms> <pressure_pa> <setpoint_pa> <duty_permille> <flags> <rejected>
  kError,        // $ERR <seq> <error_code>
};

// Board state flags (the <flags> field of $STATE, a bit set written in decimal).
enum StateFlag : uint16_t {
  kFlagVented = 1,       // Outputs are in the safe state (pump off, inflate closed, vent open).
  kFlagWatchdog = 2,     // Vented because no valid command arrived for watchdog_ms.
  kFlagLimit = 4,        // The pressure limit guard is overriding the outputs.
  kFlagOpenLoop = 8,     // Duty mode ($DUTY).
  kFlagClosedLoop = 16,  // Pressure mode ($SETP).
  kFlagHandshake = 32,   // A $HELLO with the right version was received.
  kFlagRejected = 64,    // At least one line was rejected since the previous $STATE.
};

// Codes of $ERR: the line was well formed but cannot be carried out.
enum ErrorCode : int32_t {
  kErrVersion = 1,    // $HELLO with another protocol version.
  kErrNoHello = 2,    // A command before a successful handshake.
  kErrRange = 3,      // An argument outside its range (setpoint above the limit, |duty| > 1000,
                      // a gain outside 0..kMaxGainPermille, a vent share outside
                      // 1..kMaxVentPermille).
};

// The largest inner-loop gain $GAIN carries, per-mille duty per kPa (kp) or per kPa*s (ki): 1000
// duty per kPa, a full valve swing for a pascal of error, is far beyond any useful loop. A gain
// above it is a corrupted or mistyped value, refused with kErrRange.
const int32_t kMaxGainPermille = 1000000;
// The venting share of $GAIN, per-mille of the loop's duty when it vents: 1..10000 (0.001..10).
// A vent faster than the pump needs less duty for the same pressure rate; never 0, so the loop
// can always vent.
const int32_t kMaxVentPermille = 10000;

// Why a line was rejected. Rejected lines are counted and never acted on.
enum class DecodeStatus : uint8_t {
  kOk = 0,
  kEmpty,            // Only whitespace (not counted as an error by the receivers).
  kNoStart,          // Does not begin with '$' (garbage, or the tail of a truncated line).
  kNoChecksum,       // No "*HHHH" at the end (truncated).
  kBadChecksum,      // CRC mismatch (corrupted: any 1, 2 or 3 flipped bits, any burst <= 16).
  kBadCharacter,     // A byte outside printable ASCII.
  kUnknownCommand,   // A command word this side does not know.
  kBadArguments,     // Wrong argument count, or an argument that is not a decimal integer.
  kTooLong,          // Longer than kMaxLineLength (reported by LineAssembler).
};

struct Message {
  MessageType type = MessageType::kNone;
  int32_t args[kMaxArgs] = {0, 0, 0, 0, 0, 0, 0};
  uint8_t argc = 0;
};

// Number of arguments each message type carries.
int ArgumentCount(MessageType type);
// The command word, e.g. "SETP".
const char* CommandWord(MessageType type);
bool IsHostCommand(MessageType type);
const char* DecodeStatusName(DecodeStatus status);

// CRC-16/CCITT-FALSE (polynomial 0x1021, initial value 0xFFFF, no reflection, no final XOR) of
// the bytes in [begin, end); "123456789" gives 0x29B1. Its generator has the factor x + 1 and a
// primitive factor of period 32767, so every error of 1, 2 or 3 bits and every burst of up to 16
// bits in a line of up to 4095 bytes changes it.
uint16_t Crc16(const char* begin, const char* end);

// Encodes `message` as "$WORD a b c*HHHH\n" into `out` (NUL-terminated). Returns the length without
// the NUL, or 0 when `capacity` is too small or the argument count is wrong.
size_t EncodeMessage(const Message& message, char* out, size_t capacity);

// Decodes one line (without its '\n'; a trailing '\r' is allowed). Never reads past `length`.
DecodeStatus DecodeLine(const char* line, size_t length, Message* message);

// Splits a byte stream into lines. A line longer than kMaxLineLength is dropped whole (up to its
// '\n') and reported once as kTooLong.
class LineAssembler {
 public:
  enum class Event : uint8_t { kNone, kLine, kTooLong };

  // Feeds one byte; kLine means line()/length() hold a complete line (without '\n').
  Event push(char c);
  const char* line() const { return buffer_; }
  size_t length() const { return length_; }
  void reset();

 private:
  char buffer_[kMaxLineLength + 2] = {0};
  size_t length_ = 0;
  bool overflow_ = false;
  bool complete_ = false;
};

}  // namespace wire
}  // namespace softsight
