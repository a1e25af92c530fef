// Everything the `control:` section of a config sets (examples/rig.yaml documents every key):
// the outer-loop gains, the serial link, and the simulated rig.
#pragma once

#include <string>

#include "softsight/control/board_link.h"
#include "softsight/control/controller.h"
#include "softsight/control/rig.h"

namespace softsight {

struct ControlConfig {
  ControllerOptions controller;
  LinkOptions link;
  RigOptions rig;  // Used by `softsight rig` and `softsight control --simulate` only.

  // Returns false and names the bad field ("controller.max_kpa must be > min_kpa").
  bool Check(std::string* error) const;
};

}  // namespace softsight
