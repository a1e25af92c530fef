// Errors a user can cause (bad config, missing file, corrupt video, unplugged port).
//
// Three kinds of failure are kept apart in softsight:
// - a lost marker is a normal result (Observation::found() == false);
// - bad user input throws InputError, whose what() is one line naming the file/key/frame/port
//   and the offending value; the program prints it once and exits with kInputErrorExitCode;
// - a broken invariant is a programming error and asserts (CV_DbgAssert / assert).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace softsight {

inline constexpr int kInputErrorExitCode = 2;


// `text` made safe for a one-line message: control characters, DEL and bytes that are not valid
// UTF-8 become \xNN (a newline \n), so a random-bytes config or file name cannot break the line
// or the terminal. Texts longer than `max_bytes` are cut and end in "...".
std::string EscapeForMessage(std::string_view text, size_t max_bytes = 400);

// The one exception type for what a user can fix. The message is made one line here, for every
// caller (the program, the library's users, Python): a value read from a file may hold a newline
// or control bytes, and each throw site need not remember to escape it.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message)
      : std::runtime_error(EscapeForMessage(message, kMaxInputErrorBytes)) {}
  static constexpr size_t kMaxInputErrorBytes = 4096;
};


}  // namespace softsight
