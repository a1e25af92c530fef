#include "app/cli_checks.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>

#include "io/sequence_pattern.h"
#include "softsight/core/error.h"

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

std::string Shown(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

struct FileId {
  dev_t device;
  ino_t inode;
};

std::optional<FileId> IdOf(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return std::nullopt;
  return FileId{info.st_dev, info.st_ino};
}

// The input file an image-pattern output (frames/%04d.png) would write over: one in the
// pattern's folder whose name the pattern writes. Nothing for other outputs, or a pattern the
// writer will refuse anyway.
const PathRole* InputAPatternWouldWrite(const std::string& output,
                                        const std::vector<PathRole>& inputs) {
  namespace fs = std::filesystem;
  if (output.find('%') == std::string::npos || IdOf(output)) return nullptr;
  SequencePattern pattern;
  try {
    pattern = ParseSequencePattern(output);
  } catch (const InputError&) {
    return nullptr;
  }
  const fs::path folder = fs::path(pattern.prefix).parent_path();
  const SequencePattern names{fs::path(pattern.prefix).filename().string(), pattern.suffix,
                              pattern.width};
  for (const PathRole& input : inputs) {
    const fs::path path(input.path);
    if (!names.Match(path.filename().string())) continue;
    std::error_code error;
    if (fs::equivalent(folder.empty() ? fs::path(".") : folder,
                       path.parent_path().empty() ? fs::path(".") : path.parent_path(), error)) {
      return &input;
    }
  }
  return nullptr;
}

}  // namespace

CLI::Validator NumberIn(double min, double max) {
  const bool any = min == 0 && max == 0;
  const std::string description =
      any ? "a finite number" : "a number in " + Shown(min) + ".." + Shown(max);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const std::optional<double> value = ParseNumber(text);
        if (!value) return "";  // Not a number at all: CLI11's own conversion says so.
        if (!std::isfinite(*value)) return "'" + text + "' is not " + description;
        if (!any && (*value < min || *value > max)) return "'" + text + "' is not " + description;
        return "";
      },
      any ? "FINITE" : "[" + Shown(min) + ".." + Shown(max) + "]");
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

void CheckOutputsAreNotInputs(const std::vector<PathRole>& outputs,
                              const std::vector<PathRole>& inputs) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (const PathRole* input = InputAPatternWouldWrite(outputs[i].path, inputs)) {
      throw InputError(outputs[i].role + " " + outputs[i].path + " would write " + input->role +
                       " " + input->path + ": refusing to overwrite an input (choose another name)");
    }
    const std::optional<FileId> out = IdOf(outputs[i].path);
    if (!out) continue;
    auto same = [&](const PathRole& other) {
      const std::optional<FileId> id = IdOf(other.path);
      return id && id->device == out->device && id->inode == out->inode;
    };
    for (const PathRole& input : inputs) {
      if (same(input)) {
        throw InputError(outputs[i].role + " " + outputs[i].path + " is " + input.role + " " +
                         input.path + ": refusing to overwrite an input (choose another name)");
      }
    }
    for (size_t j = 0; j < i; ++j) {
      if (same(outputs[j])) {
        throw InputError(outputs[i].role + " " + outputs[i].path + " and " + outputs[j].role +
                         " " + outputs[j].path + " are the same file: give each output its own name");
      }
    }
  }
}

}  // namespace softsight
