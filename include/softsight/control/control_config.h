// Everything the `control:` section of a config sets (examples/rig.yaml documents every key):
// the outer-loop gains, the serial link, the board's inner-loop gains, the simulated rig, and the identified model.
#pragma once

#include <string>

#include "softsight/control/actuator_model.h"
#include "softsight/control/board_link.h"
#include "softsight/control/controller.h"
#include "softsight/control/rig.h"

namespace softsight {

struct ControlConfig {
  ControllerOptions controller{};
  LinkOptions link{};
  InnerLoopGains inner_loop{};  // Sent to the board at the handshake when given.
  RigOptions rig{};  // Used by `softsight rig` and `softsight control --simulate` only.
  ActuatorModel model{};  // Written by `softsight identify`; informative (the gains are above).

  // Returns false and names the bad field ("controller.max_kpa must be > min_kpa").
  bool Check(std::string* error) const;
};

}  // namespace softsight
