#include "softsight/config/control_config.h"

#include "config/config_sections.h"
#include "config/option_yaml.h"
#include "control/control_options.h"
#include "softsight/core/error.h"

namespace softsight {

void ReadControlConfig(YamlMap& control, ControlConfig* config) {
  // Every key, its unit and range is a row of ControlConfigTable() (control/control_options.cc).
  ReadOptions(control, ControlConfigTable(), config);
  control.finish();
  std::string problem;
  if (!config->Check(&problem)) FailAtKey(control, problem);
}

void WriteControlConfig(const ControlConfig& config, YAML::Emitter& out) {
  WriteOptions(ControlConfigTable(), config, out);
}

ControlConfig LoadControlConfig(const std::string& file) {
  try {
    const YAML::Node root = LoadYamlFile(file);
    ControlConfig config;
    if (!root.IsDefined() || root.IsNull()) return config;
    YamlMap top(root, file, "");
    if (top.has("control")) {
      YamlMap control = top.map("control");
      ReadControlConfig(control, &config);
    }
    return config;
  } catch (const YAML::Exception& e) {
    RethrowYamlError(file, e);
  }
}

}  // namespace softsight
