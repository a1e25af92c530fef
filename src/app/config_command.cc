// softsight config: the documentation of every config key, generated from the option tables, and
// a check of a config file without running anything.
#include <iostream>
#include <memory>
#include <string>

#include "app/commands.h"
#include "app/flag_table.h"
#include "config/config_sections.h"
#include "softsight/core/error.h"
#include "softsight/config/config.h"

namespace softsight {

namespace {

struct ConfigArgs {
  bool doc = false;
  std::string check;
};

const FlagTable<ConfigArgs>& ConfigFlags() {
  using A = ConfigArgs;
  static const FlagTable<ConfigArgs> table = {
      SwitchFlag<A>("--doc", &A::doc).Help("Print every config key as commented YAML"),
      ValueFlag<A>("--check", &A::check).Help("Read this config and report its first problem"),
  };
  return table;
}

}  // namespace

CommandRunner SetupConfigCommand(CLI::App& sub) {
  auto args = std::make_shared<ConfigArgs>();
  sub.footer(
      "--doc prints every key with its default, unit, range and meaning, as a commented config\n"
      "that loads as it is. --check reads a config as `track` would and reports the first\n"
      "problem (file:line: key: what is wrong), exit code 2, or prints 'ok'.\n"
      "Example: softsight config --doc > all_keys.yaml; softsight config --check markers.yaml");
  AddFlags(sub, ConfigFlags(), args.get());
  return [args] {
    if (!args->doc && args->check.empty()) throw InputError("config: give --doc or --check FILE");
    if (args->doc) std::cout << DocumentConfig();
    if (!args->check.empty()) {
      LoadTrackingConfig(args->check);
      std::cout << args->check << ": ok\n";
    }
    return 0;
  };
}

}  // namespace softsight
