#include "softsight/core/option_table.h"

#include "softsight/core/format.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "softsight/core/format.h"

namespace softsight {
namespace {

std::string Bound(double value) {
  if (std::floor(value) == value && std::fabs(value) < 1e7) {
    return std::to_string(static_cast<int64_t>(value));
  }
  return RoundTripNumber(value);
}

// What a value must satisfy, as the end of "x must ...": "lie within 0..1", "be at least 1".
std::string Requirement(const OptionSpec& spec) {
  std::string range;
  if (!spec.one_of.empty()) {
    std::vector<std::string> values;
    if (spec.special) values.push_back(Bound(*spec.special) + " (" + spec.special_means + ")");
    for (int64_t v : spec.one_of) values.push_back(std::to_string(v));
    range = "be ";
    for (size_t i = 0; i < values.size(); ++i) {
      range += (i == 0 ? "" : i + 1 == values.size() ? " or " : ", ") + values[i];
    }
    return range;  // "be 0 (automatic), 1, 2, 4 or 8"
  } else if (spec.min && spec.max && !spec.min_exclusive && !spec.max_exclusive) {
    range = "lie within " + Bound(*spec.min) + ".." + Bound(*spec.max);
  } else {
    std::string lower, upper;
    if (spec.min) lower = (spec.min_exclusive ? "be above " : "be at least ") + Bound(*spec.min);
    if (spec.max) upper = (spec.max_exclusive ? "be below " : "be at most ") + Bound(*spec.max);
    range = lower.empty() ? upper : upper.empty() ? lower : lower + " and " + upper.substr(3);
  }
  if (spec.odd) range = range.empty() ? "be odd" : "be odd and " + range;
  if (spec.special) {
    // "be 0 (no limit) or lie within 8..4096", "be 0 (no limit) or at least 1"
    if (range.rfind("be ", 0) == 0) range = range.substr(3);
    range = "be " + Bound(*spec.special) + " (" + spec.special_means + ")" +
            (range.empty() ? "" : " or " + range);
  }
  return range;
}

bool Allowed(const OptionSpec& spec, double value) {
  if (spec.special && value == *spec.special) return true;
  if (spec.min && (spec.min_exclusive ? !(value > *spec.min) : !(value >= *spec.min))) return false;
  if (spec.max && (spec.max_exclusive ? !(value < *spec.max) : !(value <= *spec.max))) return false;
  return true;
}

bool AllowedInt(const OptionSpec& spec, int64_t value) {
  if (spec.special && static_cast<double>(value) == *spec.special) return true;
  if (!spec.one_of.empty()) {
    for (int64_t v : spec.one_of) {
      if (v == value) return true;
    }
    return false;
  }
  if (spec.odd && value % 2 == 0) return false;
  return Allowed(spec, static_cast<double>(value));
}

// A name from a file as a message shows it: on one line, printable, not too long.
std::string Printable(const std::string& text) {
  constexpr size_t kMaxShown = 60;
  std::string out;
  for (size_t i = 0; i < text.size() && i < kMaxShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static const char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (text.size() > kMaxShown) out += "...";
  return out;
}

std::string NamesText(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

}  // namespace

double FloatAsDouble(float value) {
  if (!std::isfinite(value)) return static_cast<double>(value);
  char buffer[64];
  const auto written = std::to_chars(buffer, buffer + sizeof(buffer), value);
  double result = 0.0;
  std::from_chars(buffer, written.ptr, result);
  return result;
}

std::string OptionValueText(const OptionValue& value) {
  struct Visitor {
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(int64_t i) const { return std::to_string(i); }
    std::string operator()(double d) const { return RoundTripNumber(d); }
    std::string operator()(const std::string& s) const { return Printable(s); }
    std::string operator()(const std::vector<int64_t>& list) const {
      std::string text = "[";
      for (size_t i = 0; i < list.size(); ++i) text += (i ? ", " : "") + std::to_string(list[i]);
      return text + "]";
    }
    std::string operator()(const std::vector<double>& list) const {
      std::string text = "[";
      for (size_t i = 0; i < list.size(); ++i) text += (i ? ", " : "") + RoundTripNumber(list[i]);
      return text + "]";
    }
    std::string operator()(const std::vector<std::string>& list) const {
      std::string text = "[";
      for (size_t i = 0; i < list.size(); ++i) text += (i ? ", " : "") + Printable(list[i]);
      return text + "]";
    }
  };
  return std::visit(Visitor{}, value);
}

std::optional<std::string> OptionProblem(const OptionSpec& spec, const OptionValue& value) {
  const std::string text = OptionValueText(value);
  switch (spec.kind) {
    case OptionKind::kBool:
    case OptionKind::kString:
      return std::nullopt;
    case OptionKind::kEnum: {
      const std::string& name = std::get<std::string>(value);
      for (const std::string& n : spec.names) {
        if (n == name) return std::nullopt;
      }
      std::string problem = "'";  // (literal + temporary trips GCC 12's -Wrestrict)
      problem += Printable(name);
      problem += "' is not one of: ";
      problem += NamesText(spec.names);
      return problem;
    }
    case OptionKind::kInt:
      if (AllowedInt(spec, std::get<int64_t>(value))) return std::nullopt;
      return text + " must " + Requirement(spec);
    case OptionKind::kDouble: {
      const double d = std::get<double>(value);
      if (!std::isfinite(d)) return text + " is not a finite number";
      if (Allowed(spec, d)) return std::nullopt;
      return text + " must " + Requirement(spec);
    }
    case OptionKind::kInts: {
      const auto& list = std::get<std::vector<int64_t>>(value);
      if (spec.count > 0 && list.size() != spec.count) {
        return text + " must have " + std::to_string(spec.count) + " values";
      }
      for (int64_t v : list) {
        if (!AllowedInt(spec, v)) return text + ": each value must " + Requirement(spec);
      }
      return std::nullopt;
    }
    case OptionKind::kStrings: {
      const auto& list = std::get<std::vector<std::string>>(value);
      if (spec.count > 0 && list.size() != spec.count) {
        return text + " must have " + std::to_string(spec.count) + " names";
      }
      return std::nullopt;
    }
    case OptionKind::kDoubles: {
      const auto& list = std::get<std::vector<double>>(value);
      if (spec.count > 0 && list.size() != spec.count) {
        return text + " must have " + std::to_string(spec.count) + " values";
      }
      for (double v : list) {
        if (!std::isfinite(v)) return text + ": each value must be a finite number";
        if (!Allowed(spec, v)) return text + ": each value must " + Requirement(spec);
      }
      return std::nullopt;
    }
  }
  return std::nullopt;
}

std::string OptionRangeText(const OptionSpec& spec) {
  if (spec.kind == OptionKind::kEnum) return NamesText(spec.names);
  if (spec.kind == OptionKind::kBool) return "true or false";
  if (spec.kind == OptionKind::kString) return "";
  if (spec.kind == OptionKind::kStrings) {
    return spec.count > 0 ? std::to_string(spec.count) + " names" : "names";
  }
  // The requirement without its verbs: "odd, 3..31", "0 (no limit) or 8..4096", "at least 1".
  std::string range = Requirement(spec);
  for (const auto& [from, to] : {std::pair{"be odd and lie within ", "odd, "},
                                 std::pair{"be odd and ", "odd, "}, std::pair{" or lie within ", " or "},
                                 std::pair{"lie within ", ""}, std::pair{"be ", ""}}) {
    const size_t at = range.find(from);
    if (at != std::string::npos) range.replace(at, std::string(from).size(), to);
  }
  if (spec.count > 0) range = std::to_string(spec.count) + " values, each " + range;
  return range;
}

std::string DescribeOptionSpecs(const std::vector<const OptionSpec*>& specs,
                                const std::vector<std::optional<OptionValue>>& defaults,
                                int indent) {
  std::ostringstream out;
  std::vector<std::string> open;  // the nested mappings the previous line was in
  for (size_t i = 0; i < specs.size(); ++i) {
    const OptionSpec& spec = *specs[i];
    std::vector<std::string> parts;
    std::stringstream key(spec.key);
    for (std::string part; std::getline(key, part, '.');) parts.push_back(part);
    const std::string leaf = parts.back();
    parts.pop_back();
    size_t same = 0;
    while (same < open.size() && same < parts.size() && open[same] == parts[same]) ++same;
    for (size_t level = same; level < parts.size(); ++level) {
      out << std::string(indent + 2 * level, ' ') << parts[level] << ":\n";
    }
    open = parts;
    std::string line = std::string(indent + 2 * parts.size(), ' ');
    if (defaults[i]) {
      line += leaf + ": " + OptionValueText(*defaults[i]);
    } else {
      line += "# " + leaf + ":";  // absent by default: shown commented out
    }
    std::string note;
    if (!spec.unit.empty()) note += spec.unit;
    const std::string range = OptionRangeText(spec);
    if (!range.empty()) note += (note.empty() ? "" : "; ") + range;
    if (!defaults[i]) note += std::string(note.empty() ? "" : "; ") + "not set by default";
    if (!spec.doc.empty()) note += (note.empty() ? "" : ". ") + spec.doc;
    if (line.size() < 40) line.resize(40, ' ');
    out << line << "  # " << note << "\n";
  }
  return out.str();
}

}  // namespace softsight
