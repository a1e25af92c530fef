// The `control:` section of a config file, for `softsight control` and `softsight rig`.
#pragma once

#include <string>

#include "softsight/control/control_config.h"

namespace softsight {

// Reads only the `control:` section of `file` (other sections are left to LoadTrackingConfig);
// defaults when the file has none. Throws InputError naming file, line and key.
ControlConfig LoadControlConfig(const std::string& file);

}  // namespace softsight
