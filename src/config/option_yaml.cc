#include "config/option_yaml.h"

#include <cmath>
#include <cstdint>

#include "softsight/core/format.h"

namespace softsight {
namespace {

bool DecodeInt(const YAML::Node& node, int64_t* value) {
  return IsValueScalar(node) && YAML::convert<int64_t>::decode(node, *value);
}

bool DecodeDouble(const YAML::Node& node, double* value) {
  return IsValueScalar(node) && YAML::convert<double>::decode(node, *value);
}

// YAML's spelling of a double (.nan and .inf are YAML's; Check() rejects them anyway).
std::string Number(double d) {
  if (std::isnan(d)) return ".nan";
  if (std::isinf(d)) return d > 0 ? ".inf" : "-.inf";
  return RoundTripNumber(d);
}

}  // namespace

std::optional<OptionValue> ReadOptionValue(YamlMap& map, const std::string& leaf,
                                           const OptionSpec& spec) {
  if (!map.has(leaf)) return std::nullopt;
  const YAML::Node node = map.node(leaf);
  OptionValue value;
  switch (spec.kind) {
    case OptionKind::kBool: {
      bool b = false;
      if (!IsValueScalar(node) || !YAML::convert<bool>::decode(node, b)) {
        map.fail(leaf, "expected true or false, got " + ShownInMessage(node));
      }
      value = b;
      break;
    }
    case OptionKind::kInt: {
      int64_t i = 0;
      if (!DecodeInt(node, &i)) map.fail(leaf, "expected a whole number, got " + ShownInMessage(node));
      value = i;
      break;
    }
    case OptionKind::kDouble: {
      double d = 0;
      if (!DecodeDouble(node, &d)) map.fail(leaf, "expected a number, got " + ShownInMessage(node));
      value = d;
      break;
    }
    case OptionKind::kEnum:
    case OptionKind::kString:
      if (!node.IsScalar()) map.fail(leaf, "expected text, got " + ShownInMessage(node));
      value = node.Scalar();
      break;
    case OptionKind::kStrings: {
      if (!node.IsSequence() || (spec.count > 0 && node.size() != spec.count)) {
        map.fail(leaf, "expected a list of " +
                           (spec.count > 0 ? std::to_string(spec.count) + " " : std::string()) +
                           "names, got " + ShownInMessage(node));
      }
      std::vector<std::string> names;
      for (const YAML::Node& item : node) {
        if (!item.IsScalar()) map.fail(leaf, "expected names, got " + Shown(item));
        names.push_back(item.Scalar());
      }
      value = names;
      break;
    }
    case OptionKind::kInts:
    case OptionKind::kDoubles: {
      const bool ints = spec.kind == OptionKind::kInts;
      const std::string what = ints ? "whole numbers" : "numbers";
      if (!node.IsSequence() || (spec.count > 0 && node.size() != spec.count)) {
        map.fail(leaf, "expected a list of " +
                           (spec.count > 0 ? std::to_string(spec.count) + " " : std::string()) +
                           what + ", got " + ShownInMessage(node));
      }
      std::vector<int64_t> int_list;
      std::vector<double> double_list;
      for (const YAML::Node& item : node) {
        int64_t i = 0;
        double d = 0;
        if (ints ? !DecodeInt(item, &i) : !DecodeDouble(item, &d)) {
          map.fail(leaf, "expected " + what + ", got " + Shown(item));
        }
        int_list.push_back(i);
        double_list.push_back(d);
      }
      if (ints) {
        value = int_list;
      } else {
        value = double_list;
      }
      break;
    }
  }
  if (std::optional<std::string> problem = OptionProblem(spec, value)) map.fail(leaf, *problem);
  return value;
}

void PutOptionValue(YAML::Node& root, const std::string& key, const OptionValue& value) {
  const size_t dot = key.find('.');
  if (dot != std::string::npos) {
    const std::string head = key.substr(0, dot);
    if (!root[head].IsMap()) {
      YAML::Node section(YAML::NodeType::Map);
      section.SetStyle(YAML::EmitterStyle::Flow);
      root[head] = section;
    }
    YAML::Node child = root[head];  // a handle: what is put into it lands in `root`
    PutOptionValue(child, key.substr(dot + 1), value);
    return;
  }
  struct Visitor {
    YAML::Node operator()(bool b) const { return YAML::Node(b); }
    YAML::Node operator()(int64_t i) const { return YAML::Node(std::to_string(i)); }
    YAML::Node operator()(double d) const { return YAML::Node(Number(d)); }
    YAML::Node operator()(const std::string& s) const { return YAML::Node(s); }
    YAML::Node operator()(const std::vector<int64_t>& list) const {
      YAML::Node n(YAML::NodeType::Sequence);
      for (int64_t i : list) n.push_back(std::to_string(i));
      n.SetStyle(YAML::EmitterStyle::Flow);
      return n;
    }
    YAML::Node operator()(const std::vector<std::string>& list) const {
      YAML::Node n(YAML::NodeType::Sequence);
      for (const std::string& name : list) n.push_back(name);
      n.SetStyle(YAML::EmitterStyle::Flow);
      return n;
    }
    YAML::Node operator()(const std::vector<double>& list) const {
      YAML::Node n(YAML::NodeType::Sequence);
      for (double d : list) n.push_back(Number(d));
      n.SetStyle(YAML::EmitterStyle::Flow);
      return n;
    }
  };
  root[key] = std::visit(Visitor{}, value);
}

void FailAtKey(const YamlMap& map, const std::string& check_problem) {
  const size_t colon = check_problem.find(": ");
  if (colon == std::string::npos) map.fail("", check_problem);
  map.fail(check_problem.substr(0, colon), check_problem.substr(colon + 2));
}

}  // namespace softsight
