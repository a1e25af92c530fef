// Reader of the config's `control:` section (examples/rig.yaml documents every key).
#pragma once

#include <yaml-cpp/yaml.h>

#include "io/yaml_map.h"
#include "softsight/control/control_config.h"

namespace softsight {

// Consumes the keys of the `control:` mapping into `config` (defaults stay where a key is absent),
// finishes the mapping (unknown keys are errors) and checks the result. Throws InputError naming
// file, line and key.
void ReadControlConfig(YamlMap& control, ControlConfig* config);

// The keys of `config` that differ from the defaults, into the `control:` mapping `out` writes.
void WriteControlConfig(const ControlConfig& config, YAML::Emitter& out);

}  // namespace softsight
