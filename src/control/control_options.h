// The option tables of the `control:` section (softsight/core/option_table.h): every key of the controller,
// the link and the simulated rig, with its unit, range and doc. The structs' Check() functions run
// them; the config reader and writer (config/control_config.cc) iterate them.
#pragma once

#include "softsight/control/control_config.h"
#include "softsight/core/option_table.h"

namespace softsight {

const OptionTable<ControllerOptions>& ControllerOptionsTable();
const OptionTable<LinkOptions>& LinkOptionsTable();
const OptionTable<InnerLoopGains>& InnerLoopGainsTable();
const OptionTable<BoardConfig>& BoardConfigTable();  // in kPa where the board counts Pa
const OptionTable<PlantOptions>& PlantOptionsTable();
const OptionTable<RigOptions>& RigOptionsTable();    // with board.* and plant.*
const OptionTable<ActuatorModel>& ModelOptionsTable();  // what `softsight identify` found
// controller.*, link.*, rig.*, model.*: the whole section.
const OptionTable<ControlConfig>& ControlConfigTable();

}  // namespace softsight
