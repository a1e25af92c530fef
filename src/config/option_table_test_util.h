// Tests generated from an option table (softsight/core/option_table.h), for every option of every table:
//   - a non-default value written to YAML reads back identical (read(write(x)) == x);
//   - a value out of range gives the same message from the YAML reader (after "file:line: path.")
//     as from Check();
//   - every int option has both bounds (no overflow from a file).
// A module's test instantiates OptionTableSuite with its table, reader and writer.
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "config/option_yaml.h"
#include "config/yaml_map.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/core/option_table.h"

namespace softsight::testing {

template <typename T>
struct OptionTableSuite {
  const OptionTable<T>& table;
  std::string path;  // key path of the mapping the reader reads ("markers[0]", "control", "")
  std::function<void(YamlMap&, T*)> read;
  std::function<void(const T&, YAML::Emitter&)> write;
  std::function<bool(const T&, std::string*)> check;
  // Files a string option may name, created beside the YAML file (e.g. a template image).
  std::string string_value = "t.png";

  std::string Prefix() const { return path.empty() ? "" : path + "."; }

  // Values to try, in order, to make `option` differ from its default.
  std::vector<OptionValue> Candidates(const Option<T>& option) const {
    const T defaults{};
    const std::optional<OptionValue> d = option.get(defaults);
    std::vector<double> numbers;
    auto around = [&](double base) {
      for (double step : {1.0, -1.0, 2.0, -2.0, 0.5, -0.5, 0.25, 10.0}) numbers.push_back(base + step);
      numbers.push_back(base * 1.5);
      numbers.push_back(base * 0.5);
    };
    if (d && (option.kind == OptionKind::kInt || option.kind == OptionKind::kDouble)) {
      around(option.kind == OptionKind::kInt ? static_cast<double>(std::get<int64_t>(*d))
                                             : std::get<double>(*d));
    }
    for (int64_t v : option.one_of) numbers.push_back(static_cast<double>(v));
    if (option.special) numbers.push_back(*option.special);
    if (option.min) around(*option.min);
    if (option.max) around(*option.max);
    if (option.min && option.max) numbers.push_back((*option.min + *option.max) / 2);
    for (double v : {1.0, 3.0, 10.0, 100.0}) numbers.push_back(v);

    std::vector<OptionValue> values;
    switch (option.kind) {
      case OptionKind::kBool: values.push_back(!(d && std::get<bool>(*d))); break;
      case OptionKind::kEnum:
        for (const std::string& n : option.names) values.push_back(n);
        break;
      case OptionKind::kString: values.push_back(string_value); break;
      case OptionKind::kStrings: {
        std::vector<std::string> names;
        for (size_t i = 0; i < (option.count > 0 ? option.count : 3); ++i) {
          std::string name = "m";  // (operator+ on a literal trips GCC 12's -Wrestrict)
          name += std::to_string(i);
          names.push_back(name);
        }
        values.push_back(names);
        break;
      }
      case OptionKind::kInt:
        for (double v : numbers) values.push_back(static_cast<int64_t>(std::llround(v)));
        break;
      case OptionKind::kDouble:
        for (double v : numbers) values.push_back(v);
        break;
      case OptionKind::kInts:
      case OptionKind::kDoubles: {
        const size_t n = option.count > 0 ? option.count : 3;
        std::vector<std::vector<double>> lists;
        if (d) {  // the default with one element changed
          std::vector<double> base;
          if (option.kind == OptionKind::kInts) {
            for (int64_t v : std::get<std::vector<int64_t>>(*d)) base.push_back(static_cast<double>(v));
          } else {
            base = std::get<std::vector<double>>(*d);
          }
          for (size_t i = 0; i < base.size(); ++i) {
            for (double step : {1.0, -1.0}) {
              std::vector<double> l = base;
              l[i] += step;
              lists.push_back(l);
            }
          }
        }
        for (double v : numbers) lists.push_back(std::vector<double>(n, v));
        if (n == 9) {  // a 3x3 matrix (a homography): equal entries are singular, try identities
          for (double v : numbers) lists.push_back({v, 0, 0, 0, v, 0, 0, 0, v});
        }
        for (const auto& l : lists) {
          if (option.kind == OptionKind::kInts) {
            std::vector<int64_t> ints;
            for (double v : l) ints.push_back(static_cast<int64_t>(std::llround(v)));
            values.push_back(ints);
          } else {
            values.push_back(l);
          }
        }
        break;
      }
    }
    return values;
  }

  // A struct with only `option` changed from the default that passes Check(), or nullopt.
  std::optional<T> NonDefault(const Option<T>& option) const {
    const T defaults{};
    for (const OptionValue& v : Candidates(option)) {
      if (OptionProblem(option, v) || v == option.get(defaults)) continue;
      T object{};
      option.set(object, v);
      if (option.get(object) != v) continue;  // not representable in the member
      if (check(object, nullptr)) return object;
    }
    return std::nullopt;
  }

  // A value just outside the option's range (nullopt when it has none or none is representable).
  std::optional<T> OutOfRange(const Option<T>& option) const {
    std::vector<double> bad;
    if (option.max) bad.push_back(*option.max + (option.kind == OptionKind::kDouble ? 0.5 : 1));
    if (option.min) bad.push_back(*option.min - (option.kind == OptionKind::kDouble ? 0.5 : 1));
    for (double b : bad) {
      if (option.special && b == *option.special) continue;
      OptionValue v;
      const size_t n = option.count > 0 ? option.count : 2;
      switch (option.kind) {
        case OptionKind::kInt: v = static_cast<int64_t>(b); break;
        case OptionKind::kDouble: v = b; break;
        case OptionKind::kInts: v = std::vector<int64_t>(n, static_cast<int64_t>(b)); break;
        case OptionKind::kDoubles: v = std::vector<double>(n, b); break;
        default: return std::nullopt;
      }
      T object{};
      option.set(object, v);
      if (option.get(object) == v) return object;
    }
    return std::nullopt;
  }

  // `object` written to YAML (through the writer, or `node` when given), read back.
  T RoundTrip(const T& object, const TempDir& dir) const {
    YAML::Emitter out;
    out << YAML::BeginMap;
    write(object, out);
    out << YAML::EndMap;
    return ReadText(out.c_str(), dir);
  }

  T ReadText(const std::string& text, const TempDir& dir) const {
    const std::string file = dir.file("options.yaml");
    WriteTextFile(file, text + "\n");
    const YAML::Node root = LoadYamlFile(file);
    YamlMap map(root.IsNull() ? YAML::Node(YAML::NodeType::Map) : root, file, path);
    T object{};
    read(map, &object);
    map.finish();
    return object;
  }

  // The reader's error for the YAML of `object`'s value of `option`, without "file:line: ".
  std::string ReadError(const Option<T>& option, const T& object, const TempDir& dir) const {
    YAML::Node root(YAML::NodeType::Map);
    PutOptionValue(root, option.key, *option.get(object));
    YAML::Emitter out;
    out << root;
    try {
      ReadText(out.c_str(), dir);
    } catch (const InputError& e) {
      const std::string what = e.what();
      const size_t at = what.find(": ");  // after "file:line:"
      return at == std::string::npos ? what : what.substr(at + 2);
    }
    return "(read without error)";
  }

  void Run() const {
    TempDir dir;
    cv::imwrite(dir.file(string_value), cv::Mat(8, 8, CV_8UC3, cv::Scalar(10, 200, 30)));
    ASSERT_FALSE(table.empty());
    const T defaults{};
    std::string problem;
    ASSERT_TRUE(check(defaults, &problem)) << "defaults fail Check(): " << problem;
    auto equal = [&](const T& a, const T& b, const std::string& what) {
      for (const Option<T>& o : table) {
        if (o.applies && !o.applies(a)) continue;
        EXPECT_EQ(o.get(a), o.get(b)) << what << ": " << o.key << " differs after the round trip";
      }
    };
    for (const Option<T>& option : table) {
      SCOPED_TRACE(Prefix() + option.key);
      if (option.kind == OptionKind::kInt || option.kind == OptionKind::kInts) {
        EXPECT_TRUE(option.min && option.max) << "an int option needs both bounds";
        if (option.min && option.max) {
          // Within 2^30, so the sum of two values still fits an int.
          EXPECT_LE(std::fabs(*option.min), 1 << 30) << "an int option needs a sane range";
          EXPECT_LE(std::fabs(*option.max), 1 << 30) << "an int option needs a sane range";
        }
      }
      // Round trip of a non-default value.
      const std::optional<T> x = NonDefault(option);
      ASSERT_TRUE(x) << "no non-default value passes Check()";
      equal(*x, RoundTrip(*x, dir), option.key);
      EXPECT_EQ(option.get(RoundTrip(*x, dir)), option.get(*x));
      // Out of range: the same text from Check() and from the file.
      if (const std::optional<T> bad = OutOfRange(option)) {
        std::string from_check;
        EXPECT_FALSE(check(*bad, &from_check));
        EXPECT_EQ(from_check.rfind(option.key + ": ", 0), 0u) << from_check;
        EXPECT_EQ(ReadError(option, *bad, dir), Prefix() + from_check);
      }
      if (option.kind == OptionKind::kDouble) {  // NaN and infinities, whatever the range
        for (double v : {std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity()}) {
          T bad{};
          option.set(bad, OptionValue(v));
          // A member that cannot hold it (kPa kept as integer Pa): only the file can say NaN.
          if (std::isfinite(std::get<double>(*option.get(bad)))) continue;
          std::string from_check;
          EXPECT_FALSE(check(bad, &from_check)) << v;
          EXPECT_EQ(ReadError(option, bad, dir), Prefix() + from_check);
        }
      }
      if (option.kind == OptionKind::kEnum) {
        const std::string bogus = "no_such_" + option.names.front();
        YAML::Node root(YAML::NodeType::Map);
        PutOptionValue(root, option.key, OptionValue(bogus));
        YAML::Emitter out;
        out << root;
        try {
          ReadText(out.c_str(), dir);
          ADD_FAILURE() << "an unknown name was accepted";
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find(Prefix() + option.key + ": '" + bogus +
                                               "' is not one of"),
                    std::string::npos)
              << e.what();
        }
      }
    }
    // Every option changed at once (as far as Check() allows), round trip.
    T all{};
    for (const Option<T>& option : table) {
      if (const std::optional<T> x = NonDefault(option)) {
        T trial = all;
        option.set(trial, option.get(*x));
        if (check(trial, nullptr)) all = trial;
      }
    }
    equal(all, RoundTrip(all, dir), "all options at once");
    // Defaults write nothing.
    YAML::Emitter out;
    out << YAML::BeginMap;
    write(defaults, out);
    out << YAML::EndMap;
    EXPECT_EQ(std::string(out.c_str()), "{}");
  }
};

// Every leaf key of `table` appears as "key:" in the text of `example` (commented out or not), so
// the documented example cannot drift from the table.
template <typename T>
std::vector<std::string> KeysMissingFrom(const OptionTable<T>& table, const std::string& example) {
  std::vector<std::string> missing;
  for (const Option<T>& option : table) {
    const size_t dot = option.key.rfind('.');
    const std::string leaf = dot == std::string::npos ? option.key : option.key.substr(dot + 1);
    if (example.find(leaf + ":") == std::string::npos) missing.push_back(option.key);
  }
  return missing;
}

}  // namespace softsight::testing
