// The marker config reader on arbitrary bytes: an InputError (one line) or a config, never a
// crash, a hang, another exception type or a sanitizer report.
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "softsight/core/error.h"
#include "softsight/config/config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = softsight::fuzz::WriteScratchFile("markers.yaml", data, size);
  try {
    softsight::LoadTrackingConfig(path);
  } catch (const softsight::InputError& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) __builtin_trap();
  }
  return 0;
}
