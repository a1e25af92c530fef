// Tests of a run's stream (track, track-stereo, control --stereo): what a subscriber received
// until the run's end record, and whether a record is its CSV row.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "stream/subscriber.h"

namespace softsight::testing {

// Every record `subscriber` receives, by topic, in order, until the "end" record (its topic's
// single entry) or a minute of silence in all (then there is no "end" entry).
inline std::map<std::string, std::vector<nlohmann::ordered_json>> ReceiveUntilEnd(
    StreamSubscriber& subscriber) {
  std::map<std::string, std::vector<nlohmann::ordered_json>> received;
  for (int waits = 0; received.count("end") == 0 && waits < 600;) {
    const std::optional<StreamMessage> message = subscriber.receive(100);
    if (!message) {
      ++waits;
      continue;
    }
    received[message->topic].push_back(nlohmann::ordered_json::parse(message->body));
  }
  return received;
}

// A frame record has the CSV's columns in order and the values of its row `fields` (an empty
// field is null, a word the same word, a number the same number).
inline void ExpectRecordIsRow(const nlohmann::ordered_json& record,
                              const std::vector<std::string>& header,
                              const std::vector<std::string>& fields, const std::string& where) {
  std::vector<std::string> keys;
  for (const auto& item : record.items()) keys.push_back(item.key());
  ASSERT_EQ(keys, header) << where;
  ASSERT_EQ(fields.size(), header.size()) << where;
  for (size_t c = 0; c < header.size(); ++c) {
    const nlohmann::ordered_json& value = record[header[c]];
    if (fields[c].empty()) {
      EXPECT_TRUE(value.is_null()) << header[c] << ", " << where;
    } else if (value.is_string()) {
      EXPECT_EQ(value.get<std::string>(), fields[c]) << header[c] << ", " << where;
    } else {
      EXPECT_EQ(value.get<double>(), std::stod(fields[c])) << header[c] << ", " << where;
    }
  }
}

}  // namespace softsight::testing
