// Errors a user can cause (bad config, missing file, corrupt video, unplugged port).
//
// Three kinds of failure are kept apart in softsight:
// - a lost marker is a normal result (Observation::found() == false);
// - bad user input throws InputError, whose what() is one line naming the file/key/frame/port
//   and the offending value; the program prints it once and exits with kInputErrorExitCode;
// - a broken invariant is a programming error and asserts (CV_DbgAssert / assert).
#pragma once

#include <stdexcept>
#include <string>

namespace softsight {

inline constexpr int kInputErrorExitCode = 2;

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace softsight
