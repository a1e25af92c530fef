#include "app/flag_table.h"

namespace softsight {

std::string ConfigKeyHelp(const OptionSpec& spec, const std::string& key_path) {
  std::string help = spec.doc;
  if (!spec.unit.empty()) help += " [" + spec.unit + "]";
  return help + "; " + OptionRangeText(spec) + " (config: " + key_path + ")";
}

}  // namespace softsight
