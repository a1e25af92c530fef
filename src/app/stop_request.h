// Ctrl-C (SIGINT) and SIGTERM as a polite request: long-running commands poll it between frames,
// then finish their files, vent the actuator and print their summary instead of dying mid-write.
#pragma once

#include <atomic>
#include <csignal>

namespace softsight {

// While an instance lives, SIGINT and SIGTERM set a flag instead of ending the process; the
// previous handlers come back when it goes out of scope. One at a time (the flag is global).
class StopRequest {
 public:
  StopRequest();
  ~StopRequest();
  StopRequest(const StopRequest&) = delete;
  StopRequest& operator=(const StopRequest&) = delete;

  bool requested() const;

 private:
  using Handler = void (*)(int);
  Handler previous_int_;
  Handler previous_term_;
};

}  // namespace softsight
