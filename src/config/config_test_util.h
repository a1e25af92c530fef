// Test helper shared by the config module's tests.
#pragma once

#include <string>

#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/config/config.h"

namespace softsight::testing {

// Loads `text` as the config file markers.yaml and returns its error message ("" when it loads).
inline std::string ConfigErrorOf(const std::string& text) {
  TempDir dir;
  WriteTextFile(dir.file("markers.yaml"), text);
  try {
    LoadTrackingConfig(dir.file("markers.yaml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace softsight::testing
