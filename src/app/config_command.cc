// softsight config: the documentation of every config key, generated from the option tables, and
// a check of a config file without running anything.
#include <iostream>
#include <memory>
#include <string>

#include "app/commands.h"
#include "config/config_sections.h"
#include "softsight/core/error.h"
#include "softsight/config/config.h"

namespace softsight {

CommandRunner SetupConfigCommand(CLI::App& sub) {
  struct Args {
    bool doc = false;
    std::string check;
  };
  auto args = std::make_shared<Args>();
  sub.footer(
      "--doc prints every key with its default, unit, range and meaning, as a commented config\n"
      "that loads as it is. --check reads a config as `track` would and reports the first\n"
      "problem (file:line: key: what is wrong), exit code 2, or prints 'ok'.\n"
      "Example: softsight config --doc > all_keys.yaml; softsight config --check markers.yaml");
  sub.add_flag("--doc", args->doc, "Print every config key as commented YAML");
  sub.add_option("--check", args->check, "Read this config and report its first problem");
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
