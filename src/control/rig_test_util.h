// The simulated rig in the same process and the same thread as the host, without a
// pseudo-terminal: what the host writes is handled at once, the answers wait in a buffer, and the
// link's clock is the rig's simulated clock (plus the time the link spent waiting for lines that
// never came). Nothing waits for real, so runs are fast and their timing is exact: for tests where
// the pty adds nothing.
#pragma once

#include <cstdint>
#include <string>

#include "softsight/control/board_link.h"
#include "softsight/control/rig.h"
#include "softsight/control/transport.h"
#include "softsight/core/error.h"

namespace softsight::testing {

class DirectRigTransport : public Transport {
 public:
  explicit DirectRigTransport(SimulatedRig& rig) : rig_(rig) {}

  void write_line(std::string_view line) override {
    if (!connected_) throw InputError(name_ + ": disconnected");
    rig_.receive(line, &pending_);
  }
  std::optional<std::string> read_line(int timeout_ms) override {
    if (!connected_) throw InputError(name_ + ": disconnected");
    const size_t end = pending_.find('\n');
    if (end == std::string::npos) {
      waited_ms_ += timeout_ms;
      return std::nullopt;
    }
    std::string line = pending_.substr(0, end);
    pending_.erase(0, end + 1);
    return line;
  }
  const std::string& name() const override { return name_; }

  // The cable is pulled: every later write or read fails; the rig keeps running (and its watchdog
  // vents it as time advances).
  void disconnect() { connected_ = false; }
  // The link's clock: the rig's, plus the waits that found nothing.
  LinkEnvironment environment() {
    LinkEnvironment env;
    env.now_ms = [this] {
      return static_cast<int64_t>(rig_.snapshot().time_s * 1000.0) + waited_ms_;
    };
    return env;
  }

 private:
  SimulatedRig& rig_;
  std::string pending_;
  int64_t waited_ms_ = 0;
  bool connected_ = true;
  std::string name_ = "serial port (in-process simulated rig)";
};

}  // namespace softsight::testing
