// Each setting registered once: a table per options struct names every field's key, kind, unit,
// allowed range and one-line doc. From that table come
//   - the struct's Check() (CheckOptions below, plus the few cross-field rules it cannot express),
//   - the YAML reader and writer (config/option_yaml.h iterates the table),
//   - the documentation of the example configs (DescribeOptions, checked against examples/).
// The default is the default-constructed struct's value, so it is written once too: in the struct.
// The same problem text serves Check() and the YAML reader:
//   Check():  "blob.min_circularity: 1.5 must lie within 0..1"
//   YAML:     "markers.yaml:7: markers[0].blob.min_circularity: 1.5 must lie within 0..1"
// The idea is COLMAP's OptionManager (src/colmap/controllers/option_manager.cc) with the range
// checks of Ceres' Solver::Options (OPTION_GE in internal/ceres/solver.cc), without a dependency.
//
// Public so that a program adding its own kind of marker (softsight/track/tracker_kind.h) declares
// its keys the way the library does.
//
// A table is a std::vector<Option<T>>, built from the helpers at the end of this file:
//   IntOption<T>("window", &T::window_px).Range(8, 4096).Or(0, "search the whole frame")
//       .Unit("px").Doc("side of the square tracking window")
// Keys are dotted paths ("blob.min_area"): each dot is one nested YAML mapping.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace softsight {

enum class OptionKind {
  kBool,
  kInt,      // a whole number; every int option has both bounds, so nothing overflows
  kDouble,   // finite always: NaN and infinities are rejected whatever the range
  kEnum,     // one of `names`, held as its name
  kString,
  kInts,     // a list of whole numbers (exactly `count` of them when count > 0)
  kDoubles,  // a list of finite numbers
  kStrings,  // a list of names (marker names)
};

// One option's value, in the form shared by the checks, the YAML adapter and the tests.
// kEnum and kString hold std::string; lists hold their element vectors.
using OptionValue = std::variant<bool, int64_t, double, std::string, std::vector<int64_t>,
                                 std::vector<double>, std::vector<std::string>>;

// Everything about an option except how to reach it in the struct.
struct OptionSpec {
  std::string key;   // dotted path, e.g. "blob.min_area"
  OptionKind kind = OptionKind::kInt;
  std::string unit;  // "px", "kPa", "deg/s", ... ("" when unitless)
  std::string doc;   // one line: what it does and the trade-off
  // Inclusive bounds unless *_exclusive; for lists every element. Doubles are finite always.
  std::optional<double> min, max;
  bool min_exclusive = false, max_exclusive = false;
  // A value allowed outside [min, max] with a meaning of its own ("0: no limit").
  std::optional<double> special;
  std::string special_means;
  bool odd = false;              // ints: must be odd (kernel sides)
  std::vector<int64_t> one_of;   // ints: the only allowed values (besides `special`)
  std::vector<std::string> names;  // enums: the allowed names, in order
  size_t count = 0;              // lists: exact length (0: any)
  // The member is std::optional: absent is a valid state, written as no key at all.
  bool optional = false;
};

// The problem with `value` for this option ("1.5 must lie within 0..1"), or nullopt when it is
// allowed. The text does not name the key: callers prefix the key path (and file:line).
std::optional<std::string> OptionProblem(const OptionSpec& spec, const OptionValue& value);

// The value as a person writes it in YAML: 0.5, 12, true, median, [170, 10]. Doubles use the
// shortest text that reads back to the identical double.
std::string OptionValueText(const OptionValue& value);
// The double whose shortest text is the float's shortest text (0.1f -> 0.1).
double FloatAsDouble(float value);

// "0..1", ">= 1", "odd, 3..31", "one of: none, gaussian, median", "0 (no limit) or 8..4096".
std::string OptionRangeText(const OptionSpec& spec);

template <typename T>
struct Option : OptionSpec {
  // nullopt: an optional member that is absent.
  std::function<std::optional<OptionValue>(const T&)> get;
  // nullopt resets an optional member. Only called with values of the right kind.
  std::function<void(T&, const std::optional<OptionValue>&)> set;
  // Whether the option means anything for this struct (e.g. hsv ranges do not once auto_colour
  // is set); a writer skips options that do not apply. Empty: always applies.
  std::function<bool(const T&)> applies;
};

template <typename T>
using OptionTable = std::vector<Option<T>>;

// The first option of `table` whose value in `object` is not allowed, as "key: problem";
// nullopt when all are. Check() functions start with this.
template <typename T>
std::optional<std::string> CheckOptions(const OptionTable<T>& table, const T& object) {
  for (const Option<T>& option : table) {
    const std::optional<OptionValue> value = option.get(object);
    if (!value) continue;
    if (std::optional<std::string> problem = OptionProblem(option, *value)) {
      return option.key + ": " + *problem;
    }
  }
  return std::nullopt;
}

// Convenience for the bool Check(std::string* error) convention: fills `error` (if given).
inline bool Fail(std::string* error, const std::string& problem) {
  if (error) *error = problem;
  return false;
}

// Commented YAML describing every option of `table`, one line each, with its default:
//   blob:
//     min_area: 12        # px; >= 1. Smaller blobs are specks.
// `indent` spaces precede every line (to nest a table under a parent key).
// `defaults` gives each option's default (for a T whose default-constructed value is not its
// defaults: a MarkerParams holds one kind's, given by the kind).
template <typename T>
std::string DescribeOptions(const OptionTable<T>& table, int indent = 0);
template <typename T>
std::string DescribeOptions(const OptionTable<T>& table, int indent, const T& defaults);

// Moves an option table of a part (e.g. BoardConfig) under `prefix` of its owner (RigOptions),
// reached through `part` (a member pointer or a T& -> Part& function).
template <typename T, typename Part, typename Access>
void AppendOptions(OptionTable<T>* table, const std::string& prefix, Access part,
                   const OptionTable<Part>& part_table);

// ---- Builders ------------------------------------------------------------------------------------

template <typename T>
class OptionBuilder {
 public:
  explicit OptionBuilder(Option<T> option) : option_(std::move(option)) {}
  OptionBuilder& Unit(std::string unit) { option_.unit = std::move(unit); return *this; }
  OptionBuilder& Doc(std::string doc) { option_.doc = std::move(doc); return *this; }
  OptionBuilder& Range(double min, double max) {
    option_.min = min;
    option_.max = max;
    return *this;
  }
  OptionBuilder& AtLeast(double min) { option_.min = min; return *this; }
  OptionBuilder& Above(double min) {
    option_.min = min;
    option_.min_exclusive = true;
    return *this;
  }
  OptionBuilder& Below(double max) {
    option_.max = max;
    option_.max_exclusive = true;
    return *this;
  }
  OptionBuilder& AtMost(double max) { option_.max = max; return *this; }
  OptionBuilder& Odd() { option_.odd = true; return *this; }
  OptionBuilder& OneOf(std::vector<int64_t> values) {
    option_.one_of = std::move(values);
    option_.min = static_cast<double>(*std::min_element(option_.one_of.begin(), option_.one_of.end()));
    option_.max = static_cast<double>(*std::max_element(option_.one_of.begin(), option_.one_of.end()));
    return *this;
  }
  // `value` is allowed outside the range and means `meaning` (usually 0: "no limit").
  OptionBuilder& Or(double value, std::string meaning) {
    option_.special = value;
    option_.special_means = std::move(meaning);
    return *this;
  }
  OptionBuilder& Count(size_t count) { option_.count = count; return *this; }
  OptionBuilder& AppliesIf(std::function<bool(const T&)> applies) {
    option_.applies = std::move(applies);
    return *this;
  }
  operator Option<T>() const { return option_; }  // NOLINT: builders read as table rows

 private:
  Option<T> option_;
};

namespace option_detail {

// A member pointer or a function T& -> M& (for members of members), as one callable.
template <typename T, typename Access>
auto Accessor(Access access) {
  if constexpr (std::is_member_object_pointer_v<Access>) {
    return [access](T& object) -> auto& { return object.*access; };
  } else {
    return access;
  }
}

template <typename T, typename Access>
using MemberOf = std::remove_reference_t<std::invoke_result_t<Access, T&>>;

template <typename T>
Option<T> Base(std::string key, OptionKind kind) {
  Option<T> option;
  option.key = std::move(key);
  option.kind = kind;
  return option;
}

template <typename M>
struct IsOptional : std::false_type {};
template <typename M>
struct IsOptional<std::optional<M>> : std::true_type {};

}  // namespace option_detail

// bool, or std::optional<bool>.
template <typename T, typename Access>
OptionBuilder<T> BoolOption(std::string key, Access access) {
  auto get_ref = option_detail::Accessor<T>(access);
  Option<T> o = option_detail::Base<T>(std::move(key), OptionKind::kBool);
  o.get = [get_ref](const T& t) -> std::optional<OptionValue> {
    return OptionValue(static_cast<bool>(get_ref(const_cast<T&>(t))));
  };
  o.set = [get_ref](T& t, const std::optional<OptionValue>& v) {
    if (v) get_ref(t) = std::get<bool>(*v);
  };
  return OptionBuilder<T>(std::move(o));
}

// Any integer member (int, uint16_t, uint64_t, ...). The range must fit the member's type.
template <typename T, typename Access>
OptionBuilder<T> IntOption(std::string key, Access access) {
  auto get_ref = option_detail::Accessor<T>(access);
  using M = option_detail::MemberOf<T, decltype(get_ref)>;
  static_assert(std::is_integral_v<M>, "IntOption needs an integer member");
  Option<T> o = option_detail::Base<T>(std::move(key), OptionKind::kInt);
  o.get = [get_ref](const T& t) -> std::optional<OptionValue> {
    return OptionValue(static_cast<int64_t>(get_ref(const_cast<T&>(t))));
  };
  o.set = [get_ref](T& t, const std::optional<OptionValue>& v) {
    if (v) get_ref(t) = static_cast<M>(std::get<int64_t>(*v));
  };
  // Bounds default to the member type's, so nothing read can overflow it; tables narrow them.
  o.min = static_cast<double>(std::numeric_limits<M>::lowest());
  o.max = static_cast<double>(std::numeric_limits<M>::max());
  return OptionBuilder<T>(std::move(o));
}

// double or float, or std::optional<double>.
template <typename T, typename Access>
OptionBuilder<T> DoubleOption(std::string key, Access access) {
  auto get_ref = option_detail::Accessor<T>(access);
  using M = option_detail::MemberOf<T, decltype(get_ref)>;
  Option<T> o = option_detail::Base<T>(std::move(key), OptionKind::kDouble);
  if constexpr (option_detail::IsOptional<M>::value) {
    o.optional = true;
    o.get = [get_ref](const T& t) -> std::optional<OptionValue> {
      const M& m = get_ref(const_cast<T&>(t));
      if (!m) return std::nullopt;
      return OptionValue(static_cast<double>(*m));
    };
    o.set = [get_ref](T& t, const std::optional<OptionValue>& v) {
      if (v) {
        get_ref(t) = static_cast<typename M::value_type>(std::get<double>(*v));
      } else {
        get_ref(t).reset();
      }
    };
  } else if constexpr (std::is_same_v<M, float>) {
    // Through the float's shortest text, so 0.1f is 0.1 in a file, not 0.10000000149011612.
    o.get = [get_ref](const T& t) -> std::optional<OptionValue> {
      return OptionValue(FloatAsDouble(get_ref(const_cast<T&>(t))));
    };
    o.set = [get_ref](T& t, const std::optional<OptionValue>& v) {
      if (v) get_ref(t) = static_cast<float>(std::get<double>(*v));
    };
  } else {
    o.get = [get_ref](const T& t) -> std::optional<OptionValue> {
      return OptionValue(static_cast<double>(get_ref(const_cast<T&>(t))));
    };
    o.set = [get_ref](T& t, const std::optional<OptionValue>& v) {
      if (v) get_ref(t) = static_cast<M>(std::get<double>(*v));
    };
  }
  return OptionBuilder<T>(std::move(o));
}

// std::string (empty: not given), written as text.
template <typename T, typename Access>
OptionBuilder<T> StringOption(std::string key, Access access) {
  auto get_ref = option_detail::Accessor<T>(access);
  Option<T> o = option_detail::Base<T>(std::move(key), OptionKind::kString);
  o.optional = true;
  o.get = [get_ref](const T& t) -> std::optional<OptionValue> {
    const std::string& s = get_ref(const_cast<T&>(t));
    if (s.empty()) return std::nullopt;
    return OptionValue(s);
  };
  o.set = [get_ref](T& t, const std::optional<OptionValue>& v) {
    get_ref(t) = v ? std::get<std::string>(*v) : std::string();
  };
  return OptionBuilder<T>(std::move(o));
}

// An enum member with its names: EnumOption<T>("filter.type", &T::filter,
//     {{"none", Filter::kNone}, {"gaussian", Filter::kGaussian}}).
template <typename T, typename Access, typename E>
OptionBuilder<T> EnumOption(std::string key, Access access,
                            std::vector<std::pair<std::string, E>> names) {
  auto get_ref = option_detail::Accessor<T>(access);
  Option<T> o = option_detail::Base<T>(std::move(key), OptionKind::kEnum);
  for (const auto& [name, value] : names) o.names.push_back(name);
  o.get = [get_ref, names](const T& t) -> std::optional<OptionValue> {
    const E e = get_ref(const_cast<T&>(t));
    for (const auto& [name, value] : names) {
      if (value == e) return OptionValue(name);
    }
    return OptionValue(std::string("?"));  // Not a named value: Check() reports it.
  };
  o.set = [get_ref, names](T& t, const std::optional<OptionValue>& v) {
    if (!v) return;
    for (const auto& [name, value] : names) {
      if (name == std::get<std::string>(*v)) get_ref(t) = value;
    }
  };
  return OptionBuilder<T>(std::move(o));
}

// Anything else (a pair, a rectangle, a colour, a unit conversion): the caller converts.
// `get` returns nullopt when an optional member is absent.
template <typename T>
OptionBuilder<T> CustomOption(std::string key, OptionKind kind,
                              std::function<std::optional<OptionValue>(const T&)> get,
                              std::function<void(T&, const std::optional<OptionValue>&)> set,
                              bool optional = false) {
  Option<T> o = option_detail::Base<T>(std::move(key), kind);
  o.get = std::move(get);
  o.set = std::move(set);
  o.optional = optional;
  if (kind == OptionKind::kInt || kind == OptionKind::kInts) {
    o.min = std::numeric_limits<int>::lowest();
    o.max = std::numeric_limits<int>::max();
  }
  return OptionBuilder<T>(std::move(o));
}

// ---- Template definitions --------------------------------------------------------------------------

template <typename T, typename Part, typename Access>
void AppendOptions(OptionTable<T>* table, const std::string& prefix, Access part,
                   const OptionTable<Part>& part_table) {
  auto get_part = option_detail::Accessor<T>(part);
  for (const Option<Part>& p : part_table) {
    Option<T> o;
    static_cast<OptionSpec&>(o) = p;
    o.key = prefix.empty() ? p.key : prefix + "." + p.key;  // "": the part's keys at this level
    o.get = [get_part, g = p.get](const T& t) { return g(get_part(const_cast<T&>(t))); };
    o.set = [get_part, s = p.set](T& t, const std::optional<OptionValue>& v) {
      s(get_part(t), v);
    };
    if (p.applies) {
      o.applies = [get_part, a = p.applies](const T& t) { return a(get_part(const_cast<T&>(t))); };
    }
    table->push_back(std::move(o));
  }
}

// One line per option, nested mappings as in the YAML (defined in option_table.cc for specs).
std::string DescribeOptionSpecs(const std::vector<const OptionSpec*>& specs,
                                const std::vector<std::optional<OptionValue>>& defaults,
                                int indent);

template <typename T>
std::string DescribeOptions(const OptionTable<T>& table, int indent) {
  return DescribeOptions(table, indent, T{});
}

template <typename T>
std::string DescribeOptions(const OptionTable<T>& table, int indent, const T& defaults) {
  std::vector<const OptionSpec*> specs;
  std::vector<std::optional<OptionValue>> values;
  for (const Option<T>& option : table) {
    specs.push_back(&option);
    values.push_back(option.get(defaults));
  }
  return DescribeOptionSpecs(specs, values, indent);
}

}  // namespace softsight
