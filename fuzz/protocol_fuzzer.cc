// The serial protocol on arbitrary bytes, as both ends receive them: the host's line splitter and
// decoder, and the board's receive() (firmware code, built for the host). A decoded line must
// re-encode to a line that decodes to the same message; nothing may crash or read out of bounds.
#include <cstdint>
#include <cstring>

#include "control/board.h"
#include "control/protocol.h"

namespace {

using softsight::wire::DecodeLine;
using softsight::wire::DecodeStatus;
using softsight::wire::LineAssembler;
using softsight::wire::Message;

void CheckRoundTrip(const Message& message) {
  char line[softsight::wire::kLineBufferSize];
  const size_t length = softsight::wire::EncodeMessage(message, line, sizeof(line));
  if (length == 0) return;  // Arguments too long for a line: the encoder refuses, fine.
  Message again;
  if (DecodeLine(line, length - 1, &again) != DecodeStatus::kOk) __builtin_trap();
  if (again.type != message.type || again.argc != message.argc ||
      std::memcmp(again.args, message.args, sizeof(message.args)) != 0) {
    __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Host side: split into lines, decode each.
  LineAssembler assembler;
  for (size_t i = 0; i < size; ++i) {
    if (assembler.push(static_cast<char>(data[i])) != LineAssembler::Event::kLine) continue;
    Message message;
    if (DecodeLine(assembler.line(), assembler.length(), &message) == DecodeStatus::kOk) {
      CheckRoundTrip(message);
    }
  }
  // The whole input as one line too (DecodeLine must never read past `length`).
  Message message;
  if (DecodeLine(reinterpret_cast<const char*>(data), size, &message) == DecodeStatus::kOk) {
    CheckRoundTrip(message);
  }
  // Board side: every byte through receive(), with the inner loop running in between.
  softsight::Board board{softsight::BoardConfig{}};
  uint32_t now_ms = 0;
  for (size_t i = 0; i < size; ++i) {
    const size_t reply = board.receive(static_cast<char>(data[i]), now_ms);
    if (reply > 0 && (reply >= softsight::wire::kLineBufferSize ||
                      board.reply()[reply - 1] != '\n')) {
      __builtin_trap();
    }
    if (i % 8 == 0) board.update(now_ms += 2, static_cast<int32_t>(data[i]) * 250);
  }
  return 0;
}
