// What `calibrate` refuses, for the tests of its single-camera and stereo modes.
#pragma once

#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "app/calibrate_command.h"
#include "softsight/core/error.h"

namespace softsight::testing {

// The one-line message RunCalibrate throws for `options`, or "(no error)".
inline std::string CalibrateErrorOf(const CalibrateOptions& options) {
  std::ostringstream report;
  try {
    RunCalibrate(options, report);
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
    return message;
  }
  return "(no error)";
}

}  // namespace softsight::testing
