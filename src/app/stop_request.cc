#include "app/stop_request.h"

namespace softsight {
namespace {

// Only a lock-free atomic may be touched from a signal handler.
std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void OnStopSignal(int) { g_stop_requested = true; }

}  // namespace

StopRequest::StopRequest() {
  g_stop_requested = false;
  previous_int_ = std::signal(SIGINT, OnStopSignal);
  previous_term_ = std::signal(SIGTERM, OnStopSignal);
}

StopRequest::~StopRequest() {
  std::signal(SIGINT, previous_int_);
  std::signal(SIGTERM, previous_term_);
}

bool StopRequest::requested() const { return g_stop_requested; }

}  // namespace softsight
