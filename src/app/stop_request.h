// Ctrl-C (SIGINT) and SIGTERM as a polite request: long-running commands poll it between frames,
// then finish their files, vent the actuator and print their summary instead of dying mid-write.
// `track`, `control` and `rig` then exit 128 + the signal's number (130 for SIGINT, 143 for
// SIGTERM), as a shell reports a process killed by it, so a script can tell an interrupted run
// from a complete one.
#pragma once

#include <atomic>
#include <csignal>
#include <string>

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
  // The signal that asked to stop (SIGINT or SIGTERM), 0 while none has.
  int signal() const;

 private:
  using Handler = void (*)(int);
  Handler previous_int_;
  Handler previous_term_;
};

// Whether the living StopRequest has caught a signal (false while none lives): for waits deep in
// a library (a publisher waiting for its subscribers) that cannot hold the instance.
bool AnyStopRequested();

// For a summary: "stopped by Ctrl-C (SIGINT)", "stopped by SIGTERM".
std::string StopSignalReason(int signal);

// 128 + signal for a run a signal stopped, else `code`.
int ExitCodeAfterStop(int code);

}  // namespace softsight
