#include "stream/stream_format.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <optional>

namespace softsight {
namespace {

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// JSON's number grammar: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?. printf's "%.4f" and
// "%g" write such numbers; "nan", "inf" and anything else are not.
bool IsJsonNumber(std::string_view s) {
  size_t i = 0;
  if (i < s.size() && s[i] == '-') ++i;
  if (i >= s.size() || !IsDigit(s[i])) return false;
  if (s[i] == '0') {
    ++i;
  } else {
    while (i < s.size() && IsDigit(s[i])) ++i;
  }
  if (i < s.size() && s[i] == '.') {
    ++i;
    if (i >= s.size() || !IsDigit(s[i])) return false;
    while (i < s.size() && IsDigit(s[i])) ++i;
  }
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    if (i >= s.size() || !IsDigit(s[i])) return false;
    while (i < s.size() && IsDigit(s[i])) ++i;
  }
  return i == s.size();
}

}  // namespace

std::vector<TopicColumns> StreamTopics(const CsvColumnTable& table,
                                       const std::vector<std::string>& marker_names) {
  return StreamTopics(table.names(), marker_names, {"_x", "_y", "_sigma_px", "_found", "_score", "_status", "_track"});
}

std::vector<TopicColumns> StreamTopics(const std::vector<std::string>& names,
                                       const std::vector<std::string>& marker_names,
                                       const std::vector<std::string>& marker_suffixes) {
  const auto find = [&names](const std::string& name) -> std::optional<size_t> {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) return std::nullopt;
    return static_cast<size_t>(it - names.begin());
  };
  std::vector<bool> of_a_marker(names.size(), false);
  std::vector<TopicColumns> markers;
  for (const std::string& marker : marker_names) {
    TopicColumns topic{kMarkerTopicPrefix + marker, {}};
    for (const std::string& suffix : marker_suffixes) {
      if (const auto at = find(marker + suffix)) {
        topic.columns.push_back(*at);
        of_a_marker[*at] = true;
      }
    }
    markers.push_back(std::move(topic));
  }
  // Every record says which frame it is: frame and time_s lead the partial ones.
  std::vector<size_t> when;
  for (const char* key : {"frame", "time_s"}) {
    if (const auto at = find(key)) when.push_back(*at);
  }
  TopicColumns frame{kFrameTopic, {}};
  TopicColumns measure{kMeasureTopic, when};
  for (size_t i = 0; i < names.size(); ++i) {
    frame.columns.push_back(i);
    const bool leading = names[i] == "frame" || names[i] == "time_s";
    if (!of_a_marker[i] && !leading) measure.columns.push_back(i);
  }
  for (TopicColumns& topic : markers) topic.columns.insert(topic.columns.begin(), when.begin(), when.end());
  std::vector<TopicColumns> topics{std::move(frame), std::move(measure)};
  for (TopicColumns& topic : markers) topics.push_back(std::move(topic));
  return topics;
}

void AppendJsonString(std::string_view text, std::string& out) {
  out += '"';
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof(escaped), "\\u%04x", static_cast<unsigned>(c));
          out += escaped;
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

void AppendJsonValue(std::string_view field, std::string& out) {
  if (field.empty()) {
    out += "null";
  } else if (IsJsonNumber(field)) {
    out += field;
  } else {
    AppendJsonString(field, out);
  }
}

void RecordFormatter::format(const TopicColumns& topic, const FrameResult& result,
                             std::string& message) {
  message.clear();
  message += topic.topic;
  message += " {";
  bool first = true;
  for (const size_t i : topic.columns) {
    const CsvColumn& column = table_.column(i);
    if (!first) message += ',';
    first = false;
    AppendJsonString(column.name, message);
    message += ':';
    field_.clear();
    column.append(result, field_);
    AppendJsonValue(field_, message);
  }
  message += '}';
}

void FormatRecord(const TopicColumns& topic, const std::vector<std::string>& names,
                  const std::vector<std::string_view>& fields, std::string& message) {
  message.clear();
  message += topic.topic;
  message += " {";
  bool first = true;
  for (const size_t i : topic.columns) {
    if (!first) message += ',';
    first = false;
    AppendJsonString(names[i], message);
    message += ':';
    AppendJsonValue(i < fields.size() ? fields[i] : std::string_view(), message);
  }
  message += '}';
}

std::string Fnv1a64Hex(std::string_view bytes) {
  uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;
  }
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

}  // namespace softsight
