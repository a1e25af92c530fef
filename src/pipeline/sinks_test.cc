// The sinks' column table of a run: TrackingColumns(config) from the markers and the chain.
#include "softsight/pipeline/sinks.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>

#include "core/test_util.h"
#include "softsight/config/config.h"
#include "softsight/core/error.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/tracking_session.h"

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


// Two runs writing one video: the second is refused before it truncates anything, and the first
// one's recording is whole. (flock locks are per open file, so this holds within one process too.)
TEST(VideoSink, ASecondWriterOfTheSameVideoIsRefusedAndTheFirstStaysWhole) {
  testing::TempDir dir;
  const std::string path = dir.file("run.avi");
  RunInfo info;
  info.frame_size = cv::Size(64, 48);
  info.fps = 30.0;
  Frame frame;
  frame.image = cv::Mat(48, 64, CV_8UC3, cv::Scalar(0, 0, 255));
  FrameResult result;
  {
    VideoSink first(path, "mjpg", 30.0);
    first.begin(info);
    for (int i = 0; i < 5; ++i) {
      frame.index = i;
      first.consume(frame, result);
    }
    try {
      VideoSink second(path, "mjpg", 30.0);
      ADD_FAILURE() << "a second writer opened " << path;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("another program is writing this file"),
                std::string::npos)
          << e.what();
    }
    first.end(RunSummary{});
    EXPECT_FALSE(first.error());
  }
  cv::VideoCapture video(path);
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  cv::Mat image;
  while (video.read(image)) ++frames;
  EXPECT_EQ(frames, 5);
  // Once the first has finished, the file may be written again.
  EXPECT_NO_THROW(VideoSink(path, "mjpg", 30.0));
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

FrameSourceSpec BendingScene() {
  FrameSourceSpec spec;
  spec.input = "synth:bending";
  return spec;
}

// A sink's own figures reach the run's summary through FrameSink::report, for every caller of
// RunPipeline: the CSV's capture-to-row latency (which comes after capture-to-result), and a
// sink that reports nothing leaves it absent.
TEST(FrameSink, ReportAddsTheCsvRowLatencyToTheRunsSummary) {
  testing::TempDir dir;
  const TrackingConfig config =
      LoadTrackingConfig(std::string(SOFTSIGHT_TEST_SOURCE_DIR) + "/examples/markers.yaml");
  {
    TrackingSession session(config);
    std::unique_ptr<FrameSource> source = OpenFrameSource(BendingScene());
    CsvSink csv(dir.file("run.csv"), TrackingColumns(config));
    RunOptions options;
    options.max_frames = 6;
    const RunSummary summary = RunPipeline(*source, session, {&csv}, options);
    ASSERT_EQ(summary.frames, 6);
    ASSERT_TRUE(summary.latency_row_ms_median.has_value());
    ASSERT_TRUE(summary.latency_row_ms_p99.has_value());
    EXPECT_GE(*summary.latency_row_ms_median, summary.latency_result_ms_median);
    EXPECT_GE(*summary.latency_row_ms_p99, *summary.latency_row_ms_median);
  }
  TrackingSession session(config);
  std::unique_ptr<FrameSource> source = OpenFrameSource(BendingScene());
  RunOptions options;
  options.max_frames = 3;
  const RunSummary summary = RunPipeline(*source, session, {}, options);
  EXPECT_FALSE(summary.latency_row_ms_median.has_value());
}

}  // namespace
}  // namespace softsight
