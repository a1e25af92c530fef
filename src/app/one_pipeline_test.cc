// `track`, `live` and `control` share one pipeline: the same video through each gives the same
// tracking columns, and each CSV's header and rows come from one column table.
#include <algorithm>
#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/control_command.h"
#include "app/scene_markers_test_util.h"
#include "app/track_command.h"
#include "core/test_util.h"
#include "gui/live_feed.h"
#include "gui/live_controller.h"
#include "softsight/config/config.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/io/frame_writer.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using testing::ReadLines;
using testing::SplitCsv;
using testing::TempDir;
using testing::WriteTextFile;

const std::string kMarkers = testing::kScaledSceneMarkersYaml;

// A CSV as columns by name; checks that every row has the header's field count.
struct Csv {
  std::vector<std::string> header;
  std::map<std::string, std::vector<std::string>> columns;
  size_t rows = 0;
};

Csv ReadCsv(const std::string& file) {
  const std::vector<std::string> lines = ReadLines(file);
  Csv csv;
  EXPECT_FALSE(lines.empty()) << file;
  if (lines.empty()) return csv;
  csv.header = SplitCsv(lines[0]);
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> row = SplitCsv(lines[i]);
    EXPECT_EQ(row.size(), csv.header.size()) << file << " row " << i;
    for (size_t c = 0; c < std::min(row.size(), csv.header.size()); ++c) {
      csv.columns[csv.header[c]].push_back(row[c]);
    }
    ++csv.rows;
  }
  return csv;
}

TEST(OnePipeline, TrackLiveAndControlGiveTheSameTrackingColumnsForTheSameVideo) {
  TempDir dir;
  SceneOptions scene;
  scene.frame_count = 12;
  scene.max_bend_deg = 150;
  SyntheticScene renderer(scene);
  const std::string video = dir.file("clip.avi");
  {
    FrameWriter writer({video, "", scene.fps});
    cv::Mat image;
    for (int i = 0; i < scene.frame_count; ++i) {
      renderer.render(i, image);
      writer.write(image, i);
    }
  }
  WriteTextFile(dir.file("markers.yaml"), kMarkers);

  TrackOptions track;
  track.config_file = dir.file("markers.yaml");
  track.source.input = video;
  track.csv_file = dir.file("track.csv");
  track.quiet = true;
  RunTrack(track);

  ControlOptions control;
  control.config_file = dir.file("markers.yaml");
  control.simulate = true;  // A simulated board; the frames are the video's.
  control.input = video;
  control.target_deg = 120.0;
  control.csv_file = dir.file("control.csv");
  control.quiet = true;
  const ControlSummary summary = RunControl(control);
  EXPECT_EQ(summary.run.frames, 12);
  EXPECT_EQ(summary.run.stop_reason, StopReason::kEndOfInput);
  EXPECT_EQ(summary.run.stop_text(), "end of input");

  // `live --no-pace`: the window's controller fed by the unpaced file, each frame's result as
  // the window shows it written through the same column table.
  {
    const TrackingConfig config = LoadTrackingConfig(dir.file("markers.yaml"));
    LiveOptions options;
    options.record_prefix = dir.file("rec");
    options.save_config_path = dir.file("saved.yaml");
    LiveController live(config, options);
    FrameSourceSpec spec;
    spec.input = video;
    std::unique_ptr<FrameSource> source = OpenFrameSource(spec);
    LiveFeed feed(*source);
    CsvSink csv(dir.file("live.csv"), TrackingColumns(config));
    Frame frame;
    while (feed.step(live)) {
      frame.index = live.last_result()->frame_index;
      csv.consume(frame, *live.last_result());
    }
    EXPECT_TRUE(feed.ended());
  }

  const Csv tracked = ReadCsv(track.csv_file);
  const Csv lived = ReadCsv(dir.file("live.csv"));
  const Csv controlled = ReadCsv(control.csv_file);
  ASSERT_EQ(lived.rows, 12u);
  EXPECT_EQ(lived.header, tracked.header);
  for (const std::string& name : tracked.header) {
    if (name == "proc_ms" || name.rfind("latency_", 0) == 0) continue;  // A timing.
    EXPECT_EQ(lived.columns.at(name), tracked.columns.at(name)) << name;
  }
  ASSERT_EQ(tracked.rows, 12u);
  ASSERT_EQ(controlled.rows, 12u);
  // The tracking columns come first, in the same order; control's own follow, by name.
  ASSERT_GT(controlled.header.size(), tracked.header.size());
  // (The timings end both: latency_result_ms, control's latency_command_ms, latency_row_ms, proc_ms.)
  EXPECT_TRUE(std::equal(tracked.header.begin(), tracked.header.end() - 3,
                         controlled.header.begin()));
  EXPECT_EQ(controlled.header.back(), "proc_ms");
  for (const char* name : {"target_deg", "setpoint_kpa", "board_pressure_kpa", "control_action"}) {
    EXPECT_TRUE(controlled.columns.count(name)) << name;
  }
  EXPECT_EQ(controlled.columns.at("target_deg").front(), "120");
  for (const std::string& name : tracked.header) {
    if (name == "proc_ms" || name.rfind("latency_", 0) == 0) continue;  // A timing.
    EXPECT_EQ(controlled.columns.at(name), tracked.columns.at(name)) << name;
  }
  // Every row names the video's frame.
  for (size_t i = 0; i < tracked.rows; ++i) {
    EXPECT_EQ(controlled.columns.at("frame")[i], std::to_string(i));
  }
}

}  // namespace
}  // namespace softsight
