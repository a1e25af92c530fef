// The YAML side of the option tables (softsight/core/option_table.h): one reader and one writer for every
// options struct, so a key, its range and its message are written once, in the struct's table.
#pragma once

#include <map>
#include <optional>
#include <string>

#include <yaml-cpp/yaml.h>

#include "config/yaml_map.h"
#include "softsight/core/option_table.h"

namespace softsight {

// Reads `leaf` of `map` as the kind `spec` names, rejecting a wrong type, a NaN or infinity, or a
// value out of range with the table's message ("file:line: path.key: 1.5 must lie within 0..1").
// nullopt when the key is absent.
std::optional<OptionValue> ReadOptionValue(YamlMap& map, const std::string& leaf,
                                           const OptionSpec& spec);

// Puts `value` at the dotted `key` of the mapping `root`, creating nested (flow) mappings.
void PutOptionValue(YAML::Node& root, const std::string& key, const OptionValue& value);

// A Check() message "key: problem" reported as "file:line: path.key: problem" at that key.
[[noreturn]] void FailAtKey(const YamlMap& map, const std::string& check_problem);

// Reads every option of `table` that `map` holds into `object`; options absent from the file keep
// their value. Nested keys are read through their sub-mappings, which are finished here (an
// unknown key inside them is an error); `map` itself is left for the caller to finish.
template <typename T>
void ReadOptions(YamlMap& map, const OptionTable<T>& table, T* object) {
  std::map<std::string, YamlMap> sections;  // dotted prefix -> its mapping in the file
  // The mapping for `prefix`, or nullptr when the file does not have it.
  std::function<YamlMap*(const std::string&)> section = [&](const std::string& prefix) -> YamlMap* {
    if (prefix.empty()) return &map;
    if (auto it = sections.find(prefix); it != sections.end()) return &it->second;
    const size_t dot = prefix.rfind('.');
    YamlMap* parent = section(dot == std::string::npos ? "" : prefix.substr(0, dot));
    const std::string name = dot == std::string::npos ? prefix : prefix.substr(dot + 1);
    if (parent == nullptr || !parent->has(name)) return nullptr;
    return &sections.emplace(prefix, parent->map(name)).first->second;
  };
  for (const Option<T>& option : table) {
    const size_t dot = option.key.rfind('.');
    YamlMap* m = section(dot == std::string::npos ? "" : option.key.substr(0, dot));
    if (m == nullptr) continue;
    const std::string leaf = dot == std::string::npos ? option.key : option.key.substr(dot + 1);
    if (std::optional<OptionValue> value = ReadOptionValue(*m, leaf, option)) {
      option.set(*object, value);
    }
  }
  for (const auto& [prefix, m] : sections) m.finish();
}

// The options of `object` that differ from `defaults` (a default-constructed T unless given) and
// apply to it, as a YAML mapping: what a saved config needs to read back to the same struct.
template <typename T>
YAML::Node OptionsToYaml(const OptionTable<T>& table, const T& object, const T& defaults = T{}) {
  YAML::Node root(YAML::NodeType::Map);
  for (const Option<T>& option : table) {
    if (option.applies && !option.applies(object)) continue;
    const std::optional<OptionValue> value = option.get(object);
    if (!value || value == option.get(defaults)) continue;
    PutOptionValue(root, option.key, *value);
  }
  return root;
}

// Emits each key of OptionsToYaml into the mapping `out` is writing.
template <typename T>
void WriteOptions(const OptionTable<T>& table, const T& object, YAML::Emitter& out,
                  const T& defaults = T{}) {
  const YAML::Node node = OptionsToYaml(table, object, defaults);
  for (auto it = node.begin(); it != node.end(); ++it) {
    out << YAML::Key << it->first.Scalar() << YAML::Value << it->second;
  }
}

}  // namespace softsight
