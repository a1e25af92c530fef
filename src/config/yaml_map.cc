#include "config/yaml_map.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <cerrno>
#include <cstring>

#include <yaml-cpp/depthguard.h>  // YAML::DeepRecursion

#include "softsight/core/error.h"

namespace softsight {
namespace {

std::string LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.line < 0) return "";
  return std::to_string(mark.line + 1) + ":";
}

// The tag yaml-cpp gives a quoted scalar (and the Python package a str): YAML's non-specific "!".
constexpr const char* kQuotedTag = "!";

std::string Shown(const YAML::Node& node) {
  if (node.IsScalar() && node.Tag() == kQuotedTag) {
    return "the string '" + EscapeForMessage(node.Scalar(), 60) + "' (quoted)";
  }
  if (node.IsScalar()) return "'" + EscapeForMessage(node.Scalar(), 60) + "'";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

template <typename T>
std::string Range(T min, T max) {
  std::ostringstream out;
  out << min << ".." << max;
  return out.str();
}

}  // namespace

std::string ShownInMessage(const YAML::Node& node) { return Shown(node); }

bool IsValueScalar(const YAML::Node& node) { return node.IsScalar() && node.Tag() != kQuotedTag; }

YamlMap::YamlMap(const YAML::Node& node, std::string file, std::string path)
    : node_(node), file_(std::move(file)), path_(std::move(path)) {
  if (!node_.IsMap()) {
    throw InputError(file_ + ":" + LineOf(node_) + " " + (path_.empty() ? "top level" : path_) +
                     ": expected a mapping of keys, got " + Shown(node_));
  }
  // YAML parsers keep one of two equal keys silently; a config with both is a mistake.
  std::set<std::string> seen;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    if (!it->first.IsScalar()) {
      throw InputError(file_ + ":" + LineOf(it->first) + " " + (path_.empty() ? "top level" : path_) +
                       ": a key must be a plain name, got " + Shown(it->first) + " as a key");
    }
    const std::string key = it->first.Scalar();
    if (!seen.insert(key).second) {
      throw InputError(file_ + ":" + LineOf(it->first) + " " + key_path(key) +
                       ": key given twice");
    }
  }
}

std::string YamlMap::key_path(const std::string& key) const {
  // Keys in messages may come from the file (an unknown or repeated key): one escaped line.
  return EscapeForMessage(path_.empty() ? key : path_ + "." + key, 120);
}

// The line of the deepest part of the dotted `key` that `node` has ("" when none).
static std::string LineOfPath(const YAML::Node& node, const std::string& key) {
  if (key.empty() || !node.IsMap()) return "";
  const size_t dot = key.find('.');
  const YAML::Node child = node[key.substr(0, dot)];
  if (!child.IsDefined()) return "";
  if (dot == std::string::npos) return LineOf(child);
  const std::string deeper = LineOfPath(child, key.substr(dot + 1));
  return deeper.empty() ? LineOf(child) : deeper;
}

void YamlMap::fail(const std::string& key, const std::string& problem) const {
  // A dotted key ("blob.max_area", from a Check() message) points into nested mappings.
  std::string line = LineOfPath(node_, key);
  if (line.empty()) line = LineOf(node_);
  const std::string where = key.empty() ? (path_.empty() ? "top level" : path_) : key_path(key);
  throw InputError(file_ + ":" + line + " " + where + ": " + problem);
}

bool YamlMap::has(const std::string& key) const {
  known_.insert(key);
  const YAML::Node child = node_[key];
  return child.IsDefined() && !child.IsNull();
}

YAML::Node YamlMap::node(const std::string& key) {
  known_.insert(key);
  return node_[key];
}

YamlMap YamlMap::map(const std::string& key) {
  known_.insert(key);
  return YamlMap(node_[key], file_, key_path(key));
}

std::optional<double> YamlMap::number(const std::string& key, double min, double max) {
  if (!has(key)) return std::nullopt;
  const YAML::Node child = node_[key];
  double value = 0;
  if (!IsValueScalar(child) || !YAML::convert<double>::decode(child, value) || !std::isfinite(value)) {
    fail(key, "expected a number, got " + Shown(child));
  }
  if (value < min || value > max) {
    fail(key, "value " + child.Scalar() + " is outside " + Range(min, max));
  }
  return value;
}

std::optional<int> YamlMap::integer(const std::string& key, int min, int max) {
  if (!has(key)) return std::nullopt;
  const YAML::Node child = node_[key];
  int value = 0;
  if (!IsValueScalar(child) || !YAML::convert<int>::decode(child, value)) {
    fail(key, "expected a whole number, got " + Shown(child));
  }
  if (value < min || value > max) {
    fail(key, "value " + child.Scalar() + " is outside " + Range(min, max));
  }
  return value;
}

std::optional<bool> YamlMap::boolean(const std::string& key) {
  if (!has(key)) return std::nullopt;
  const YAML::Node child = node_[key];
  bool value = false;
  if (!IsValueScalar(child) || !YAML::convert<bool>::decode(child, value)) {
    fail(key, "expected true or false, got " + Shown(child));
  }
  return value;
}

std::optional<std::string> YamlMap::string(const std::string& key) {
  if (!has(key)) return std::nullopt;
  const YAML::Node child = node_[key];
  if (!child.IsScalar()) fail(key, "expected text, got " + Shown(child));
  return child.Scalar();
}

std::optional<std::string> YamlMap::choice(const std::string& key,
                                           const std::vector<std::string>& choices) {
  std::optional<std::string> value = string(key);
  if (!value) return std::nullopt;
  for (const std::string& c : choices) {
    if (*value == c) return value;
  }
  std::string list;
  for (const std::string& c : choices) list += (list.empty() ? "" : ", ") + c;
  fail(key, "'" + *value + "' is not one of: " + list);
}

std::optional<std::vector<int>> YamlMap::integers(const std::string& key, size_t count, int min,
                                                  int max) {
  if (!has(key)) return std::nullopt;
  const YAML::Node child = node_[key];
  if (!child.IsSequence() || (count > 0 && child.size() != count)) {
    fail(key, "expected a list of " + (count > 0 ? std::to_string(count) + " " : std::string()) +
                  "whole numbers, got " + Shown(child));
  }
  std::vector<int> values;
  for (const YAML::Node& item : child) {
    int value = 0;
    if (!IsValueScalar(item) || !YAML::convert<int>::decode(item, value)) {
      fail(key, "expected whole numbers, got " + Shown(item));
    }
    if (value < min || value > max) {
      fail(key, "value " + item.Scalar() + " is outside " + Range(min, max));
    }
    values.push_back(value);
  }
  return values;
}

std::optional<std::vector<double>> YamlMap::numbers(const std::string& key, size_t count,
                                                    double min, double max) {
  if (!has(key)) return std::nullopt;
  const YAML::Node child = node_[key];
  if (!child.IsSequence() || (count > 0 && child.size() != count)) {
    fail(key, "expected a list of " + (count > 0 ? std::to_string(count) + " " : std::string()) +
                  "numbers, got " + Shown(child));
  }
  std::vector<double> values;
  for (const YAML::Node& item : child) {
    double value = 0;
    if (!IsValueScalar(item) || !YAML::convert<double>::decode(item, value) || !std::isfinite(value)) {
      fail(key, "expected numbers, got " + Shown(item));
    }
    if (value < min || value > max) {
      fail(key, "value " + item.Scalar() + " is outside " + Range(min, max));
    }
    values.push_back(value);
  }
  return values;
}

void YamlMap::finish() const {
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string key = it->first.Scalar();  // Checked scalar by the constructor.
    if (known_.count(key) == 0) {
      throw InputError(file_ + ":" + LineOf(it->first) + " " + key_path(key) +
                       ": unknown key (check the spelling; examples/markers.yaml lists every key)");
    }
  }
}

std::string ResolveBesideFile(const std::string& config_file, const std::string& path) {
  const std::filesystem::path p(path);
  if (p.is_absolute()) return path;
  return (std::filesystem::path(config_file).parent_path() / p).lexically_normal().string();
}

YAML::Node LoadYamlFile(const std::string& file) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(file, error);
  if (!std::filesystem::exists(status)) {
    throw InputError(file + ": cannot open config file (no such file)");
  }
  // A device or FIFO (/dev/zero, /dev/stdin) would be read for ever.
  if (!std::filesystem::is_regular_file(status)) {
    throw InputError(file + ": not a regular file (a config is a YAML text file)");
  }
  std::ifstream in(file);
  if (!in) throw InputError(file + ": cannot open config file (" + std::strerror(errno) + ")");
  try {
    return YAML::Load(in);
  } catch (const YAML::DeepRecursion& e) {
    throw InputError(file + ":" + std::to_string(e.mark.line + 1) +
                     ": invalid YAML: nested too deeply (lists or mappings inside each other "
                     "hundreds of levels deep)");
  } catch (const YAML::Exception& e) {
    throw InputError(file + ":" + std::to_string(e.mark.line + 1) +
                     ": invalid YAML: " + EscapeForMessage(e.msg, 120));
  }
}

void RethrowYamlError(const std::string& file, const YAML::Exception& e) {
  const std::string line = e.mark.line >= 0 ? std::to_string(e.mark.line + 1) + ":" : "";
  throw InputError(file + ":" + line + " cannot read this config (" +
                   EscapeForMessage(e.msg, 120) + ")");
}

}  // namespace softsight
