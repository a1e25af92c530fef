#include "stream/stream_format.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace softsight {
namespace {

std::string Value(std::string_view field) {
  std::string out;
  AppendJsonValue(field, out);
  return out;
}

TEST(StreamFormat, AFieldBecomesNullANumberOrAString) {
  EXPECT_EQ(Value(""), "null");
  EXPECT_EQ(Value("12.3400"), "12.3400");  // The CSV's digits, a JSON number.
  EXPECT_EQ(Value("-0.5"), "-0.5");
  EXPECT_EQ(Value("1e+06"), "1e+06");
  EXPECT_EQ(Value("0"), "0");
  EXPECT_EQ(Value("found"), "\"found\"");
  // Not JSON numbers, though printf or a person might write them: strings, never bad JSON.
  EXPECT_EQ(Value("nan"), "\"nan\"");
  EXPECT_EQ(Value("-inf"), "\"-inf\"");
  EXPECT_EQ(Value("007"), "\"007\"");
  EXPECT_EQ(Value("1."), "\"1.\"");
  EXPECT_EQ(Value(".5"), "\".5\"");
  EXPECT_EQ(Value("a\"b\\c\n"), "\"a\\\"b\\\\c\\n\"");
  for (const char* field : {"", "12.3400", "nan", "a\"b\\c\n\x01"}) {
    EXPECT_TRUE(nlohmann::json::accept(Value(field))) << field;
  }
}

TEST(StreamFormat, TopicsSplitTheColumnsByMarkerAndMeasurement) {
  const CsvColumnTable table = TrackingColumns({"base", "tip"}, /*metric=*/false);
  const std::vector<TopicColumns> topics = StreamTopics(table, {"base", "tip"});
  ASSERT_EQ(topics.size(), 4u);
  const auto names = [&](const TopicColumns& topic) {
    std::vector<std::string> out;
    for (size_t i : topic.columns) out.push_back(table.column(i).name);
    return out;
  };
  EXPECT_EQ(topics[0].topic, "frame");
  EXPECT_EQ(names(topics[0]), table.names());
  EXPECT_EQ(topics[1].topic, "measure");
  EXPECT_EQ(names(topics[1]),
            (std::vector<std::string>{"frame", "time_s", "angle_deg", "chord_px", "sagitta_px",
                                      "radius_px", "arc_length_px", "tip_disp_px",
                                      "latency_result_ms", "latency_row_ms", "proc_ms"}));
  EXPECT_EQ(topics[3].topic, "marker/tip");
  EXPECT_EQ(names(topics[3]),
            (std::vector<std::string>{"frame", "time_s", "tip_x", "tip_y", "tip_sigma_px",
                                      "tip_found", "tip_score", "tip_status", "tip_track"}));
}

TEST(StreamFormat, ARecordIsTheTopicAndAJsonObjectOfTheRowsFields) {
  const CsvColumnTable table = TrackingColumns({"tip"}, /*metric=*/false);
  FrameResult result;
  result.frame_index = 7;
  result.time_s = 0.25;
  MarkerObservation marker;
  marker.name = "tip";
  result.markers.push_back(marker);  // Not found: no position, a status word.
  result.measurement.angle_deg = 123.456789;
  RecordFormatter formatter(table);
  std::string message;
  formatter.format(StreamTopics(table, {"tip"})[0], result, message);
  ASSERT_EQ(message.rfind("frame {", 0), 0u) << message;
  const nlohmann::ordered_json record = nlohmann::ordered_json::parse(message.substr(6));
  EXPECT_EQ(record["frame"], 7);
  EXPECT_DOUBLE_EQ(record["time_s"].get<double>(), 0.25);
  EXPECT_TRUE(record["tip_x"].is_null());
  EXPECT_EQ(record["tip_found"], 0);
  EXPECT_TRUE(record["tip_status"].is_string());
  EXPECT_DOUBLE_EQ(record["angle_deg"].get<double>(), 123.4568);  // The CSV's 4 decimals.
  std::string row;
  table.append_row(result, row);
  EXPECT_EQ(record.size(), table.size());
}

TEST(StreamFormat, AnyTablesRowBecomesRecordsByColumnNameAndMarkerSuffix) {
  // track-stereo's kind of table: its own marker columns, rows given as the CSV's field texts.
  const std::vector<std::string> names = {"frame", "right_frame", "time_s", "tip_X", "tip_Z",
                                          "tip_status", "angle_deg", "proc_ms"};
  const std::vector<TopicColumns> topics =
      StreamTopics(names, {"tip"}, {"_X", "_Y", "_Z", "_status"});
  ASSERT_EQ(topics.size(), 3u);
  EXPECT_EQ(topics[1].topic, "measure");
  EXPECT_EQ(topics[1].columns, (std::vector<size_t>{0, 2, 1, 6, 7}));
  EXPECT_EQ(topics[2].topic, "marker/tip");
  EXPECT_EQ(topics[2].columns, (std::vector<size_t>{0, 2, 3, 4, 5}));
  const std::vector<std::string_view> fields = {"4", "9", "0.133333", "-1.2500", "",
                                                "right_lost", "", "0.250"};
  std::string message;
  FormatRecord(topics[2], names, fields, message);
  EXPECT_EQ(message, "marker/tip {\"frame\":4,\"time_s\":0.133333,\"tip_X\":-1.2500,"
                     "\"tip_Z\":null,\"tip_status\":\"right_lost\"}");
  FormatRecord(topics[0], names, fields, message);
  EXPECT_EQ(nlohmann::ordered_json::parse(message.substr(6)).size(), names.size());
}

TEST(StreamFormat, DigestIsFnv1a64) {
  EXPECT_EQ(Fnv1a64Hex(""), "cbf29ce484222325");
  EXPECT_EQ(Fnv1a64Hex("a"), "af63dc4c8601ec8c");
}

}  // namespace
}  // namespace softsight
