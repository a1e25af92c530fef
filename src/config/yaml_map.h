// Strict reading of one YAML mapping: every value is type- and range-checked, every key must be
// known, and every error is one line naming the file, the key path, the line and the bad value:
//   markers.yaml:7: markers[0].hsv.h: hue 200 is outside 0..179
#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace softsight {

class YamlMap {
 public:
  // `node` must be a mapping (else InputError). `path` is the key path shown in errors ("" at top).
  YamlMap(const YAML::Node& node, std::string file, std::string path);

  bool has(const std::string& key) const;
  // The raw child (marks the key as known); absent -> undefined node.
  YAML::Node node(const std::string& key);
  // A child mapping, for nested sections.
  YamlMap map(const std::string& key);

  std::optional<double> number(const std::string& key, double min, double max);
  std::optional<int> integer(const std::string& key, int min, int max);
  std::optional<bool> boolean(const std::string& key);
  std::optional<std::string> string(const std::string& key);
  // A string that must be one of `choices`.
  std::optional<std::string> choice(const std::string& key, const std::vector<std::string>& choices);
  // A sequence of exactly `count` integers (count 0: any length), each within [min, max].
  std::optional<std::vector<int>> integers(const std::string& key, size_t count, int min, int max);
  std::optional<std::vector<double>> numbers(const std::string& key, size_t count, double min,
                                             double max);

  // Throws InputError for the first key that no getter asked for (a typo or an unknown option).
  void finish() const;

  // Throws InputError "file:line: path.key: problem".
  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;

  const std::string& file() const { return file_; }
  std::string key_path(const std::string& key) const;

 private:
  YAML::Node node_;
  std::string file_;
  std::string path_;
  mutable std::set<std::string> known_;
};

// How an error message shows a value from the file: 'text' for a scalar, "a list", "a mapping".
std::string ShownInMessage(const YAML::Node& node);
// True for a scalar that may be read as a number or true/false: one not quoted. A quoted "0.25"
// is a string in YAML (and a Python str in a config dict): taking it for a number would accept a
// value its writer typed as text.
bool IsValueScalar(const YAML::Node& node);

// A path written in a config file, relative to that file's folder unless absolute.
std::string ResolveBesideFile(const std::string& config_file, const std::string& path);

// Loads a YAML file; throws InputError naming the file (and line) when it is missing or invalid.
YAML::Node LoadYamlFile(const std::string& file);

// The reader boundary: a yaml-cpp exception that escaped the checks above (a conversion of an
// unexpected node, say) becomes one InputError line naming the file and line, never an abort.
[[noreturn]] void RethrowYamlError(const std::string& file, const YAML::Exception& e);

}  // namespace softsight
