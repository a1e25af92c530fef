// The image-sequence pattern parser: arbitrary text is accepted as one number or refused with
// an InputError; what it accepts formats and matches back to the same index.
#include <cstdint>
#include <string>

#include "io/sequence_pattern.h"
#include "softsight/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  softsight::SequencePattern pattern;
  try {
    pattern = softsight::ParseSequencePattern(text);
  } catch (const softsight::InputError&) {
    return 0;
  }
  for (int64_t index : {int64_t{0}, int64_t{7}, int64_t{123456}, int64_t{999999999999999999}}) {
    if (pattern.Match(pattern.Format(index)) != index) __builtin_trap();
  }
  return 0;
}
