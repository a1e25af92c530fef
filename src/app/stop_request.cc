#include "app/stop_request.h"

#include <pthread.h>
#include <signal.h>

namespace softsight {
namespace {

// Only lock-free atomics may be touched from a signal handler.
std::atomic<int> g_stop_signal{0};       // This StopRequest's signal.
std::atomic<int> g_last_stop_signal{0};  // Any StopRequest's, for the exit code.
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void OnStopSignal(int signal) {
  g_stop_signal = signal;
  g_last_stop_signal = signal;
}

}  // namespace

bool AnyStopRequested() { return g_stop_signal != 0; }

StopRequest::StopRequest() {
  g_stop_signal = 0;
  previous_int_ = std::signal(SIGINT, OnStopSignal);
  previous_term_ = std::signal(SIGTERM, OnStopSignal);
  // A parent may start this process with both signals blocked until the handler is in place
  // (`track` with several inputs does): one that arrived meanwhile is delivered now.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_UNBLOCK, &stop_signals, nullptr);
}

StopRequest::~StopRequest() {
  // Once a stop was asked for, the process is winding down to exit with 128 + signal: a second
  // stop signal (the terminal's to the whole process group and the one `track` with several
  // inputs forwards to each job arrive close together) must not kill it before that.
  if (g_stop_signal != 0) return;
  std::signal(SIGINT, previous_int_);
  std::signal(SIGTERM, previous_term_);
}

bool StopRequest::requested() const { return g_stop_signal != 0; }

int StopRequest::signal() const { return g_stop_signal; }

std::string StopSignalReason(int signal) {
  if (signal == SIGINT) return "stopped by Ctrl-C (SIGINT)";
  if (signal == SIGTERM) return "stopped by SIGTERM";
  return "stopped by signal " + std::to_string(signal);
}

int ExitCodeAfterStop(int code) {
  const int signal = g_last_stop_signal;
  return signal != 0 ? 128 + signal : code;
}

}  // namespace softsight
