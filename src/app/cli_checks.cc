#include "app/cli_checks.h"

#include <cmath>
#include <cstdlib>
#include <optional>

#include "softsight/core/error.h"
#include "softsight/core/format.h"

namespace softsight {
namespace {

// The value as a double when the whole text is a number (strtod spells inf and nan too).
std::optional<double> ParseNumber(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return std::nullopt;
  return value;
}

}  // namespace

CLI::Validator NumberIn(double min, double max) {
  const bool any = min == 0 && max == 0;
  const std::string description =
      any ? "a finite number" : "a number in " + ShortNumber(min) + ".." + ShortNumber(max);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const std::optional<double> value = ParseNumber(text);
        if (!value) return "";  // Not a number at all: CLI11's own conversion says so.
        if (!std::isfinite(*value)) return "'" + text + "' is not " + description;
        if (!any && (*value < min || *value > max)) return "'" + text + "' is not " + description;
        return "";
      },
      any ? "FINITE" : "[" + ShortNumber(min) + ".." + ShortNumber(max) + "]");
}

void RequireFiniteNumbers(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (type.find("FLOAT") != std::string::npos || type.find("INT") != std::string::npos ||
        type.find("UINT") != std::string::npos) {
      // A nameless validator keeps --help unchanged.
      CLI::Validator finite = NumberIn(0, 0);
      finite.description("");
      option->check(finite);
    }
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    RequireFiniteNumbers(*sub);
  }
}

}  // namespace softsight
