// `softsight track --camera`'s end summary: the latency from capture to the result, to the CSV
// row and to every output; and a camera's recording keeps every frame of its CSV while its
// encoder is held. A camera's stand-in and a held encoder (TrackSeams) make the encoder fall
// behind without any timing.
#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/scene_markers_test_util.h"
#include "app/track_command.h"
#include "core/test_util.h"
#include "io/encoder_gate_test_util.h"
#include "softsight/io/frame_source.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::EncoderGate;
using testing::FramesInVideo;
using testing::TempDir;

// A camera's stand-in: rendered frames handed over on the pipeline's thread, live (so the
// recording gets a camera's deeper queue). At its end it opens the gate: every frame has been
// given to the recording by then.
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

// A camera run's options: a CSV and a raw recording in `dir`, no progress or summary printed.
TrackOptions CameraRun(const TempDir& dir) {
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.csv_file = dir.file("run.csv");
  options.record_file = dir.file("rec.avi");
  options.quiet = true;
  return options;
}

TEST(TrackCamera, SummaryGivesTheLatenciesAndTheRecordingKeepsEveryFrameWhileItsEncoderIsHeld) {
  TempDir dir;
  static constexpr int kFrames = 16;
  EncoderGate gate;
  const TrackOptions options = CameraRun(dir);
  TrackSeams seams;
  seams.open_source = [&gate] { return std::make_unique<CameraStandIn>(kFrames, gate); };
  seams.before_encode = [&gate](int64_t index) { gate.wait(index); };

  const RunSummary summary = RunTrack(options, nullptr, {}, seams);
  ASSERT_EQ(summary.frames, kFrames);
  // The encoder held at frame 0 until the camera's last frame: a camera's queue (two seconds)
  // holds them all, and the video has every row's frame.
  EXPECT_EQ(FramesInVideo(dir.file("rec.avi")), kFrames);
  const std::string report = summary.FullReport();
  EXPECT_THAT(report, HasSubstr(dir.file("rec.avi") + ": all " + std::to_string(kFrames) +
                                " frames recorded (the encoder kept up)"));
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
  EncoderGate gate;
  gate.open();  // The encoder keeps up: a queue of 8 for 4 frames.
  const TrackOptions options = CameraRun(dir);
  TrackSeams seams;
  seams.open_source = [&gate] { return std::make_unique<CameraStandIn>(4, gate); };
  const RunSummary summary = RunTrack(options, nullptr, {}, seams);
  EXPECT_EQ(FramesInVideo(dir.file("rec.avi")), 4);
  EXPECT_THAT(summary.FullReport(),
              HasSubstr(dir.file("rec.avi") + ": all 4 frames recorded (the encoder kept up)"));
}

}  // namespace
}  // namespace softsight
