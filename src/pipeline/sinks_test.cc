// The sinks' column table of a run: TrackingColumns(config) from the markers and the chain.
#include "softsight/pipeline/sinks.h"

#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/test_util.h"

namespace softsight {
namespace {

TEST(CsvColumnTable, AChainHasAnAngleColumnPerInnerMarker) {
  TrackingConfig config;
  for (const char* name : {"a", "b", "c", "d"}) {
    config.markers.emplace_back();
    config.markers.back().name = name;
  }
  config.measure.chain = {"a", "c", "b", "d"};  // Body order, not config order.
  const CsvColumnTable table = TrackingColumns(config);
  ASSERT_TRUE(table.find("angle_c_deg") && table.find("angle_b_deg"));
  EXPECT_EQ(*table.find("angle_c_deg") + 1, *table.find("angle_b_deg"));
  EXPECT_FALSE(table.find("angle_a_deg") || table.find("angle_d_deg")) << "ends have no angle";
  EXPECT_LT(*table.find("tip_disp_px"), *table.find("angle_c_deg"));
  FrameResult result;
  for (const char* name : {"a", "b", "c", "d"}) result.markers.push_back({name, Observation{}});
  result.measurement.inner_angle_deg = {150.25, std::nullopt};
  std::string row;
  table.append_row(result, row);
  const std::vector<std::string> fields = testing::SplitCsv(row + ",");
  EXPECT_EQ(fields.at(*table.find("angle_c_deg")), "150.2500");
  EXPECT_EQ(fields.at(*table.find("angle_b_deg")), "");
  EXPECT_FALSE(TrackingColumns(TrackingConfig{}).find("angle_deg_deg"));
}

}  // namespace
}  // namespace softsight
