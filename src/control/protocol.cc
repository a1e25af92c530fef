// Shared with the firmware: plain C++11, no heap, C headers only (see protocol.h).
#include "control/protocol.h"

#include <string.h>

namespace softsight {
namespace wire {
namespace {

struct CommandInfo {
  MessageType type;
  const char* word;
  int8_t argc;
  bool from_host;
};

const CommandInfo kCommands[] = {
    {MessageType::kHello, "HELLO", 1, true},     {MessageType::kSetPressure, "SETP", 2, true},
    {MessageType::kSetDuty, "DUTY", 2, true},    {MessageType::kRead, "READ", 1, true},
    {MessageType::kStop, "STOP", 1, true},       {MessageType::kPing, "PING", 1, true},
    {MessageType::kSetGains, "GAIN", 4, true},
    {MessageType::kHelloReply, "HI", 4, false},  {MessageType::kState, "STATE", 7, false},
    {MessageType::kError, "ERR", 2, false},
};
const int kCommandCount = sizeof(kCommands) / sizeof(kCommands[0]);

const CommandInfo* Find(MessageType type) {
  for (int i = 0; i < kCommandCount; ++i) {
    if (kCommands[i].type == type) return &kCommands[i];
  }
  return 0;
}

const char kHex[] = "0123456789ABCDEF";

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;  // Lower case is not produced by any encoder, so it is not accepted either.
}

// Parses a decimal int32 in [begin, end): optional '-', 1..10 digits, no overflow.
bool ParseInt(const char* begin, const char* end, int32_t* value) {
  bool negative = false;
  if (begin < end && *begin == '-') {
    negative = true;
    ++begin;
  }
  if (begin == end || end - begin > 10) return false;
  int64_t v = 0;
  for (const char* p = begin; p < end; ++p) {
    if (*p < '0' || *p > '9') return false;
    v = v * 10 + (*p - '0');
  }
  if (negative) v = -v;
  if (v > 2147483647LL || v < -2147483647LL) return false;
  *value = static_cast<int32_t>(v);
  return true;
}

// Writes `value` in decimal at out[pos...]; returns the new position or 0 when out of room.
size_t AppendInt(int32_t value, char* out, size_t pos, size_t capacity) {
  char digits[12];
  int n = 0;
  int64_t v = value;
  const bool negative = v < 0;
  if (negative) v = -v;
  do {
    digits[n++] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v > 0);
  if (pos + n + (negative ? 1 : 0) >= capacity) return 0;
  if (negative) out[pos++] = '-';
  while (n > 0) out[pos++] = digits[--n];
  return pos;
}

}  // namespace

int ArgumentCount(MessageType type) {
  const CommandInfo* info = Find(type);
  return info ? info->argc : -1;
}

const char* CommandWord(MessageType type) {
  const CommandInfo* info = Find(type);
  return info ? info->word : "";
}

bool IsHostCommand(MessageType type) {
  const CommandInfo* info = Find(type);
  return info != 0 && info->from_host;
}

const char* DecodeStatusName(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::kOk: return "ok";
    case DecodeStatus::kEmpty: return "empty line";
    case DecodeStatus::kNoStart: return "no '$' at the start";
    case DecodeStatus::kNoChecksum: return "no '*HHHH' CRC (truncated?)";
    case DecodeStatus::kBadChecksum: return "CRC mismatch";
    case DecodeStatus::kBadCharacter: return "non-printable byte";
    case DecodeStatus::kUnknownCommand: return "unknown command";
    case DecodeStatus::kBadArguments: return "bad arguments";
    case DecodeStatus::kTooLong: return "line too long";
  }
  return "?";
}

uint16_t Crc16(const char* begin, const char* end) {
  // Bit by bit rather than with a 512-byte table: an AVR has 2 KB of RAM, and a 96-byte line
  // takes well under a millisecond.
  uint16_t crc = 0xFFFF;
  for (const char* p = begin; p < end; ++p) {
    crc = static_cast<uint16_t>(crc ^ (static_cast<uint16_t>(static_cast<uint8_t>(*p)) << 8));
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x8000) != 0 ? static_cast<uint16_t>((crc << 1) ^ 0x1021)
                                : static_cast<uint16_t>(crc << 1);
    }
  }
  return crc;
}

size_t EncodeMessage(const Message& message, char* out, size_t capacity) {
  const CommandInfo* info = Find(message.type);
  if (info == 0 || message.argc != info->argc || capacity < 8) return 0;
  size_t pos = 0;
  out[pos++] = '$';
  for (const char* w = info->word; *w != '\0'; ++w) {
    if (pos + 1 >= capacity) return 0;
    out[pos++] = *w;
  }
  for (int i = 0; i < message.argc; ++i) {
    if (pos + 1 >= capacity) return 0;
    out[pos++] = ' ';
    pos = AppendInt(message.args[i], out, pos, capacity);
    if (pos == 0) return 0;
  }
  if (pos + 7 > capacity || pos + 5 > kMaxLineLength) return 0;  // "*HHHH\n" and the NUL.
  const uint16_t crc = Crc16(out + 1, out + pos);
  out[pos++] = '*';
  for (int shift = 12; shift >= 0; shift -= 4) out[pos++] = kHex[(crc >> shift) & 0x0F];
  out[pos++] = '\n';
  out[pos] = '\0';
  return pos;
}

DecodeStatus DecodeLine(const char* line, size_t length, Message* message) {
  message->type = MessageType::kNone;
  message->argc = 0;
  if (length > 0 && line[length - 1] == '\r') --length;
  bool blank = true;
  for (size_t i = 0; i < length; ++i) {
    const unsigned char c = static_cast<unsigned char>(line[i]);
    if (c < 0x20 || c > 0x7E) return DecodeStatus::kBadCharacter;
    if (c != ' ') blank = false;
  }
  if (blank) return DecodeStatus::kEmpty;
  if (length > kMaxLineLength) return DecodeStatus::kTooLong;
  if (line[0] != '$') return DecodeStatus::kNoStart;
  if (length < 7 || line[length - 5] != '*') return DecodeStatus::kNoChecksum;
  uint16_t received = 0;
  for (size_t i = length - 4; i < length; ++i) {
    const int digit = HexValue(line[i]);
    if (digit < 0) return DecodeStatus::kNoChecksum;
    received = static_cast<uint16_t>((received << 4) | digit);
  }
  const char* body_end = line + length - 5;
  if (Crc16(line + 1, body_end) != received) return DecodeStatus::kBadChecksum;

  // Tokens separated by exactly one space: the encoder writes nothing else, so anything else is a
  // sign of corruption that happened to keep the checksum.
  const char* p = line + 1;
  const char* word_end = p;
  while (word_end < body_end && *word_end != ' ') ++word_end;
  const CommandInfo* info = 0;
  for (int i = 0; i < kCommandCount; ++i) {
    const size_t n = strlen(kCommands[i].word);
    if (static_cast<size_t>(word_end - p) == n && strncmp(p, kCommands[i].word, n) == 0) {
      info = &kCommands[i];
      break;
    }
  }
  if (info == 0) return DecodeStatus::kUnknownCommand;
  int argc = 0;
  p = word_end;
  while (p < body_end) {
    if (*p != ' ' || argc == kMaxArgs) return DecodeStatus::kBadArguments;
    ++p;
    const char* end = p;
    while (end < body_end && *end != ' ') ++end;
    if (!ParseInt(p, end, &message->args[argc])) return DecodeStatus::kBadArguments;
    ++argc;
    p = end;
  }
  if (argc != info->argc) return DecodeStatus::kBadArguments;
  message->type = info->type;
  message->argc = static_cast<uint8_t>(argc);
  return DecodeStatus::kOk;
}

LineAssembler::Event LineAssembler::push(char c) {
  if (complete_) {
    length_ = 0;
    complete_ = false;
  }
  if (c == '\n') {
    if (overflow_) {
      overflow_ = false;
      length_ = 0;
      return Event::kTooLong;
    }
    buffer_[length_] = '\0';
    complete_ = true;
    return Event::kLine;
  }
  if (overflow_) return Event::kNone;
  if (length_ >= kMaxLineLength + 1) {  // +1: room for a '\r' before '\n'.
    overflow_ = true;
    return Event::kNone;
  }
  buffer_[length_++] = c;
  return Event::kNone;
}

void LineAssembler::reset() {
  length_ = 0;
  overflow_ = false;
  complete_ = false;
}

}  // namespace wire
}  // namespace softsight
