// The stream's messages (docs/stream.md, format version kStreamFormatVersion): one ZeroMQ
// message per record, "<topic> <JSON object>". A frame's record is the CSV row of that frame:
// the same column table (io/csv_columns.h) writes both, so the stream and the CSV cannot
// disagree on a column or a value. A field's text becomes a JSON value by one rule: empty ->
// null, a JSON number -> that number (the CSV's digits), anything else (a status word) -> a
// string.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "softsight/core/types.h"
#include "softsight/io/csv_columns.h"

namespace softsight {

// Bumped when a record's meaning changes; new keys in a record or new topics keep the version.
inline constexpr int kStreamFormatVersion = 1;
inline constexpr char kStreamFormatName[] = "softsight-stream";

// Topics (the message's first word). A subscriber takes exactly one topic by subscribing to
// "<topic> " (with the space): ZeroMQ matches prefixes, and "marker/tip" would take "marker/tip2".
inline constexpr char kHelloTopic[] = "hello";      // The run's description (HelloRecord).
inline constexpr char kFrameTopic[] = "frame";      // Every column of the CSV row.
inline constexpr char kMeasureTopic[] = "measure";  // frame, time_s and every column not a marker's.
inline constexpr char kMarkerTopicPrefix[] = "marker/";  // marker/<name>: frame, time_s, <name>_*.
inline constexpr char kEndTopic[] = "end";          // Once, when the run ends (its summary).
inline constexpr char kTargetTopic[] = "target";    // control --target-from: {"angle_deg": x}.

// One topic's record: its name and the columns (indices into the table) it carries.
struct TopicColumns {
  std::string topic;
  std::vector<size_t> columns;
};

// The topics of a run: frame, measure, then marker/<name> per marker (in `marker_names` order).
// A marker's columns are the table's "<name>_x", "_y", "_sigma_px", "_found", "_score", "_status",
// "_track".
std::vector<TopicColumns> StreamTopics(const CsvColumnTable& table,
                                       const std::vector<std::string>& marker_names);
// The same for any table's column names, a marker's columns being "<name><suffix>" for each of
// `marker_suffixes` (track-stereo's: "_X", "_Y", "_Z", "_sigma_mm", "_epipolar_px", "_status").
std::vector<TopicColumns> StreamTopics(const std::vector<std::string>& column_names,
                                       const std::vector<std::string>& marker_names,
                                       const std::vector<std::string>& marker_suffixes);

// Appends `field` (a CSV field's text) as a JSON value by the rule above.
void AppendJsonValue(std::string_view field, std::string& out);
// Appends `text` as a JSON string (quoted, escaped).
void AppendJsonString(std::string_view text, std::string& out);

// Formats frame records; keeps its buffers, so a record costs no allocation once they have grown.
class RecordFormatter {
 public:
  explicit RecordFormatter(const CsvColumnTable& table) : table_(table) {}
  // Sets `message` to "<topic> {"<column>": value, ...}" for `topic`'s columns of `result`.
  void format(const TopicColumns& topic, const FrameResult& result, std::string& message);

 private:
  const CsvColumnTable& table_;
  std::string field_;
};

// Sets `message` to "<topic> {"<column>": value, ...}" for `topic`'s columns, from a row's field
// texts (`fields[i]` is column `names[i]`'s, as the CSV has it).
void FormatRecord(const TopicColumns& topic, const std::vector<std::string>& names,
                  const std::vector<std::string_view>& fields, std::string& message);

// The 64-bit FNV-1a digest of `bytes` as 16 hex digits: the hello's config_digest (the config
// file's bytes), so a subscriber can tell two runs' configs apart. Not a cryptographic hash.
std::string Fnv1a64Hex(std::string_view bytes);

}  // namespace softsight
