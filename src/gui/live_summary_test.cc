// The live window's end summary: frames, the latency from capture to the result and to the
// recording's CSV rows; and a camera's recording keeps every frame of its CSV in both videos
// while its encoder is held (through its hook: no timing involved).
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/test_util.h"
#include "io/encoder_gate_test_util.h"
#include "pipeline/scene_config_test_util.h"
#include "gui/live_controller.h"
#include "softsight/io/frame_source.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::FramesInVideo;
using testing::TempDir;

// Feeds `frames` rendered frames, as the window's feed does (capture stamped at the read).
void Feed(LiveController& live, SyntheticScene& scene, int first, int count) {
  for (int i = first; i < first + count; ++i) {
    Frame frame;
    scene.render(i, frame.image);
    frame.index = i;
    frame.time_s = i / 30.0;
    frame.captured = SteadyClock::now();
    live.on_frame(frame, frame.captured);
  }
}

// A camera as the window's source sees it: live, no frame count (frames come from Feed).
class CameraStandIn : public FrameSource {
 public:
  bool read(Frame&) override { return false; }
  std::string description() const override { return "camera 3"; }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override { return 30.0; }
  bool is_live() const override { return true; }
};

SceneOptions SmallScene() {
  SceneOptions scene;
  scene.size = {320, 240};
  scene.frame_count = 40;
  scene.length_px = 150;
  scene.marker_radius_px = 6;
  return scene;
}

TEST(LiveSummary, ACameraRecordingKeepsEveryFrameWhileItsEncoderIsHeld) {
  TempDir dir;
  testing::EncoderGate gate(1);  // Recording starts on frame 1.
  LiveOptions options;
  options.record_prefix = dir.file("rec");
  LiveController live(testing::ThreeMarkerSceneConfig(), options, [&gate](int64_t index) { gate.wait(index); });
  live.describe_source(CameraStandIn());
  SyntheticScene scene(SmallScene());
  Feed(live, scene, 0, 2);
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  // Both encoders held at their first frame: a camera's queue (two seconds of frames) takes the
  // 20 frames that follow without holding up the window.
  Feed(live, scene, 2, 20);
  gate.open();
  live.on_event(UiEvent::Key('r'));
  ASSERT_FALSE(live.recording());
  const std::string prefix = live.last_recording();

  const LiveRunSummary summary = live.run_summary();
  EXPECT_EQ(summary.run.frames, 22);
  EXPECT_EQ(summary.recorded_frames, 21) << "the frame on screen, then 2..21";
  EXPECT_EQ(FramesInVideo(prefix + ".raw.avi"), 21);
  EXPECT_EQ(FramesInVideo(prefix + ".avi"), 21);
  EXPECT_EQ(summary.encoder_waits, 0);
  // The summary every command gives (PipelineRun): found rates, latencies, the source.
  ASSERT_EQ(summary.run.markers.size(), 3u);
  for (const MarkerRunSummary& marker : summary.run.markers) {
    EXPECT_EQ(marker.found, 22) << marker.name;
  }
  EXPECT_EQ(summary.run.first_index, 0);
  EXPECT_EQ(summary.run.last_index, 21);
  EXPECT_GT(summary.run.latency_result_ms_median, 0.0);
  EXPECT_LE(summary.run.latency_result_ms_median, summary.run.latency_result_ms_p99);
  ASSERT_TRUE(summary.run.latency_row_ms_median && summary.run.latency_row_ms_p99);
  EXPECT_GT(*summary.run.latency_row_ms_median, 0.0);
  EXPECT_LE(*summary.run.latency_row_ms_median, *summary.run.latency_row_ms_p99);
  const std::string report = summary.Report();
  EXPECT_THAT(report, HasSubstr("frames: 22 from camera 3 in"));
  EXPECT_THAT(report, HasSubstr("(the window was closed)"));
  EXPECT_THAT(report, HasSubstr("source frames 0..21, 0 dropped by the source"));
  EXPECT_THAT(report, HasSubstr("to the result median"));
  EXPECT_THAT(report, HasSubstr("to the CSV row median"));
  EXPECT_THAT(report, HasSubstr("note: " + prefix + ".*: recorded 21 frames, each in the CSV and "
                                "both videos (the encoders kept up)"));
}

TEST(LiveSummary, AFileRecordingWaitsForItsEncoderAndARecordingStillOpenIsCounted) {
  TempDir dir;
  LiveOptions options;
  options.record_prefix = dir.file("rec");
  LiveController live(testing::ThreeMarkerSceneConfig(), options);
  SyntheticScene scene(SmallScene());
  Feed(live, scene, 0, 3);
  EXPECT_THAT(live.run_summary().Report(), HasSubstr("note: nothing recorded"));
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  Feed(live, scene, 3, 12);
  const LiveRunSummary summary = live.run_summary();  // Still recording, as when the window closes.
  EXPECT_EQ(summary.run.frames, 15);
  EXPECT_EQ(summary.recorded_frames, 13);
  EXPECT_EQ(summary.encoder_waits, 0);
  // The recording is still open: its videos are closed by the window, then hold every frame.
  live.on_event(UiEvent::Key('r'));
  EXPECT_EQ(FramesInVideo(live.last_recording() + ".raw.avi"), 13);
  EXPECT_EQ(FramesInVideo(live.last_recording() + ".avi"), 13);
}

// What `live --publish` hands its stream: a program's sink in LiveOptions::sinks sees every frame
// the window tracks, from the first, with the session's results.
class CountingSink : public FrameSink {
 public:
  void begin(const RunInfo& info) override { markers = info.marker_names; }
  void consume(const Frame& frame, const FrameResult& result) override {
    indices.push_back(frame.index);
    found += result.markers.at(0).observation.found() ? 1 : 0;
  }
  std::vector<std::string> markers;
  std::vector<int64_t> indices;
  int found = 0;
};

TEST(LiveSummary, AProgramsSinkSeesEveryTrackedFrame) {
  CountingSink sink;
  LiveOptions options;
  options.sinks = {&sink};
  LiveController live(testing::ThreeMarkerSceneConfig(), options);
  live.describe_source(CameraStandIn());
  SyntheticScene scene(SmallScene());
  Feed(live, scene, 0, 12);
  EXPECT_EQ(sink.markers, (std::vector<std::string>{"red", "blue", "green"}));
  std::vector<int64_t> expected(12);
  for (int i = 0; i < 12; ++i) expected[static_cast<size_t>(i)] = i;
  EXPECT_EQ(sink.indices, expected);
  EXPECT_EQ(sink.found, 12);
  EXPECT_EQ(live.run_summary().run.frames, 12);
}

}  // namespace
}  // namespace softsight
