// The live window's end summary: frames, the latency from capture to the result and to the
// recording's CSV rows, and every frame a camera recording's encoder could not take, counted
// exactly (an encoder held through its hook: no timing involved).
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

SceneOptions SmallScene() {
  SceneOptions scene;
  scene.size = {320, 240};
  scene.frame_count = 40;
  scene.length_px = 150;
  scene.marker_radius_px = 6;
  return scene;
}

TEST(LiveSummary, ACameraRecordingCountsEveryFrameItsEncoderCouldNotTake) {
  TempDir dir;
  testing::EncoderGate gate(1);  // Recording starts on frame 1.
  LiveOptions options;
  options.record_prefix = dir.file("rec");
  LiveController live(testing::ThreeMarkerSceneConfig(), options, [&gate](int64_t index) { gate.wait(index); });
  live.set_live_source(true);
  SyntheticScene scene(SmallScene());
  Feed(live, scene, 0, 2);
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  // Both encoders held at their first frame, queues of 8: the frames after them are dropped.
  Feed(live, scene, 2, 20);
  gate.open();
  live.on_event(UiEvent::Key('r'));
  ASSERT_FALSE(live.recording());
  const std::string prefix = live.last_recording();

  const LiveRunSummary summary = live.run_summary();
  EXPECT_EQ(summary.frames, 22);
  EXPECT_EQ(summary.recorded_frames, 21) << "the frame on screen, then 2..21";
  const int64_t raw = FramesInVideo(prefix + ".raw.avi"), annotated = FramesInVideo(prefix + ".avi");
  EXPECT_EQ(summary.raw_video_dropped, 21 - raw);
  EXPECT_EQ(summary.annotated_video_dropped, 21 - annotated);
  EXPECT_GE(summary.raw_video_dropped, 21 - 9);
  EXPECT_GT(summary.latency_result_ms_median, 0.0);
  EXPECT_LE(summary.latency_result_ms_median, summary.latency_result_ms_p99);
  EXPECT_GT(summary.latency_row_ms_median, 0.0);
  EXPECT_LE(summary.latency_row_ms_median, summary.latency_row_ms_p99);
  const std::string report = summary.Report();
  EXPECT_THAT(report, HasSubstr("live: 22 frames tracked, 0 dropped by the source"));
  EXPECT_THAT(report, HasSubstr("latency from capture to the result median"));
  EXPECT_THAT(report, HasSubstr("recorded 21 frames; latency from capture to the CSV row median"));
  EXPECT_THAT(report, HasSubstr(std::to_string(21 - raw) + " in the raw video, " +
                                std::to_string(21 - annotated) + " in the annotated video"));
}

TEST(LiveSummary, AFileRecordingWaitsForItsEncoderAndARecordingStillOpenIsCounted) {
  TempDir dir;
  LiveOptions options;
  options.record_prefix = dir.file("rec");
  LiveController live(testing::ThreeMarkerSceneConfig(), options);
  SyntheticScene scene(SmallScene());
  Feed(live, scene, 0, 3);
  EXPECT_THAT(live.run_summary().Report(), HasSubstr("live: nothing recorded"));
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  Feed(live, scene, 3, 12);
  const LiveRunSummary summary = live.run_summary();  // Still recording, as when the window closes.
  EXPECT_EQ(summary.frames, 15);
  EXPECT_EQ(summary.recorded_frames, 13);
  EXPECT_EQ(summary.raw_video_dropped, 0);
  EXPECT_EQ(summary.annotated_video_dropped, 0);
}

}  // namespace
}  // namespace softsight
