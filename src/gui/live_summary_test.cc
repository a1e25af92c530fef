// The live window's end summary: frames, the latency from capture to the result and to the
// recording's CSV rows, and every frame a camera recording's encoder could not take, counted
// exactly (an encoder held through its hook: no timing involved).
#include <condition_variable>
#include <filesystem>
#include <mutex>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/test_util.h"
#include "gui/live_controller.h"
#include "softsight/io/frame_source.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

MarkerSpec ColourMarker(const std::string& name, HsvRange h) {
  MarkerSpec spec;
  spec.name = name;
  ColourParams& colour = spec.params.emplace<ColourParams>();
  colour.h = h;
  colour.s = {80, 255};
  colour.v = {40, 255};
  return spec;
}

TrackingConfig SceneConfig() {
  TrackingConfig config;
  config.markers = {ColourMarker("red", {170, 10}), ColourMarker("blue", {95, 125}),
                    ColourMarker("green", {45, 75})};
  config.measure.base = "red";
  config.measure.middle = "blue";
  config.measure.tip = "green";
  config.source_file = "test config";
  return config;
}

// Holds the encoders in front of the recording's first frame (the source's frame on screen when
// recording started) until opened.
class EncoderGate {
 public:
  explicit EncoderGate(int64_t first) : first_(first) {}
  void wait(int64_t index) {
    if (index != first_) return;
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return open_; });
  }
  void open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  const int64_t first_;
  bool open_ = false;
};

int64_t FramesIn(const std::string& video) {
  std::unique_ptr<FrameSource> source = OpenFrameSource({video, {}, 30.0});
  Frame frame;
  int64_t frames = 0;
  while (source->read(frame)) ++frames;
  return frames;
}

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
  EncoderGate gate(1);  // Recording starts on frame 1.
  LiveOptions options;
  options.record_prefix = dir.file("rec");
  LiveController live(SceneConfig(), options, [&gate](int64_t index) { gate.wait(index); });
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
  const int64_t raw = FramesIn(prefix + ".raw.avi"), annotated = FramesIn(prefix + ".avi");
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
  LiveController live(SceneConfig(), options);
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
