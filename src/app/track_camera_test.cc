// `softsight track --camera`'s end summary: the latency from capture to the result, to the CSV
// row and to every output, and the frames a recording could not take, counted exactly. A camera's
// stand-in and a held encoder (TrackSeams) make the encoder fall behind without any timing.
#include <condition_variable>
#include <memory>
#include <mutex>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/scene_markers_test_util.h"
#include "app/track_command.h"
#include "core/test_util.h"
#include "softsight/io/frame_source.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

// Holds a recording's encoder in front of its first frame until opened.
class EncoderGate {
 public:
  void wait(int64_t index) {
    if (index != 0) return;
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
  bool open_ = false;
};

// A camera's stand-in: rendered frames handed over on the pipeline's thread, live (so the
// recording drops what its encoder cannot take, as for a camera). At its end it opens the gate:
// every frame has been offered to the recording by then.
class CameraStandIn : public FrameSource {
 public:
  CameraStandIn(int frames, EncoderGate& gate) : gate_(gate) {
    SceneOptions scene;
    scene.frame_count = frames;
    scene.size = {320, 240};
    scene.length_px = 150;
    scene.marker_radius_px = 6;
    scene_ = OpenSyntheticSource(scene, NoiseOptions{});
  }
  bool read(Frame& frame) override {
    if (scene_->read(frame)) return true;
    gate_.open();
    return false;
  }
  std::string description() const override { return "camera 7"; }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override { return 30.0; }
  bool is_live() const override { return true; }

 private:
  EncoderGate& gate_;
  std::unique_ptr<FrameSource> scene_;
};

int64_t FramesIn(const std::string& video) {
  std::unique_ptr<FrameSource> source = OpenFrameSource({video, {}, 30.0});
  Frame frame;
  int64_t frames = 0;
  while (source->read(frame)) ++frames;
  return frames;
}

TEST(TrackCamera, SummaryGivesTheLatenciesAndCountsEveryFrameTheRecordingDropped) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  static constexpr int kFrames = 16;
  EncoderGate gate;
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.csv_file = dir.file("run.csv");
  options.record_file = dir.file("rec.avi");
  options.quiet = true;
  TrackSeams seams;
  seams.open_source = [&gate] { return std::make_unique<CameraStandIn>(kFrames, gate); };
  seams.before_encode = [&gate](int64_t index) { gate.wait(index); };

  const RunSummary summary = RunTrack(options, nullptr, {}, seams);
  ASSERT_EQ(summary.frames, kFrames);
  // The encoder held at frame 0 and its queue of 8 full: at least the frames after the queue
  // were dropped, and the count is exactly what is missing from the video.
  const int64_t recorded = FramesIn(dir.file("rec.avi"));
  const int64_t dropped = kFrames - recorded;
  EXPECT_GE(dropped, kFrames - 9);
  EXPECT_GE(recorded, 1);
  const std::string report = summary.FullReport();
  EXPECT_THAT(report, HasSubstr(dir.file("rec.avi") + ": " + std::to_string(dropped) + " of " +
                                std::to_string(kFrames) + " frames not recorded"));
  // Capture -> result -> CSV row -> every output, per frame, so the medians keep that order.
  EXPECT_THAT(report, HasSubstr("to the result median"));
  EXPECT_THAT(report, HasSubstr("to the CSV row median"));
  EXPECT_THAT(report, HasSubstr("to every output written median"));
  ASSERT_TRUE(summary.latency_row_ms_median.has_value());
  ASSERT_TRUE(summary.latency_row_ms_p99.has_value());
  EXPECT_GT(summary.latency_result_ms_median, 0.0);
  EXPECT_LE(summary.latency_result_ms_median, *summary.latency_row_ms_median);
  EXPECT_LE(*summary.latency_row_ms_median, summary.latency_done_ms_median);
  EXPECT_LE(*summary.latency_row_ms_median, *summary.latency_row_ms_p99);
  EXPECT_LE(summary.latency_result_ms_p99, *summary.latency_row_ms_p99);
}

TEST(TrackCamera, ACameraRunSaysSoAlsoWhenTheRecordingLostNothing) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  EncoderGate gate;
  gate.open();  // The encoder keeps up: a queue of 8 for 4 frames.
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.csv_file = dir.file("run.csv");
  options.record_file = dir.file("rec.avi");
  options.quiet = true;
  TrackSeams seams;
  seams.open_source = [&gate] { return std::make_unique<CameraStandIn>(4, gate); };
  const RunSummary summary = RunTrack(options, nullptr, {}, seams);
  EXPECT_EQ(FramesIn(dir.file("rec.avi")), 4);
  EXPECT_THAT(summary.FullReport(), HasSubstr(dir.file("rec.avi") + ": 0 of 4 frames not recorded (the encoder kept up)"));
}

}  // namespace
}  // namespace softsight
