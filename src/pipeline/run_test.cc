// RunPipeline: every frame of a file reaches every sink with the source's index, the summary's
// counts match the renderer's truth, and a stop request or an error ends the run with a summary.
#include "softsight/pipeline/run.h"

#include <algorithm>

#include <gmock/gmock.h>
#include <opencv2/imgproc.hpp>
#include <gtest/gtest.h>

#include "core/test_util.h"
#include "io/frame_grabber.h"
#include "io/read_ahead_source.h"
#include "pipeline/scene_config_test_util.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/core/error.h"
#include "softsight/io/frame_writer.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/stereo_session.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using testing::ThreeMarkerSceneConfig;

using ::testing::HasSubstr;
using testing::SmallScene;
using testing::TempDir;

// Remembers what it was given, and can ask the run to stop or fail after some frames.
class RecordingSink : public FrameSink {
 public:
  void begin(const RunInfo& info) override {
    ++begins;
    this->info = info;
  }
  void consume(const Frame& frame, const FrameResult& result) override {
    indices.push_back(frame.index);
    times.push_back(frame.time_s);
    result_indices.push_back(result.frame_index);
    std::vector<bool> flags;
    for (const MarkerObservation& m : result.markers) flags.push_back(m.observation.found());
    found.push_back(flags);
    if (fail_at && static_cast<int64_t>(indices.size()) == *fail_at) {
      throw InputError("disk full at frame " + std::to_string(frame.index));
    }
  }
  void end(const RunSummary& summary) override {
    ++ends;
    ended_with = summary;
  }

  int begins = 0, ends = 0;
  RunInfo info;
  std::vector<int64_t> indices, result_indices;
  std::vector<double> times;
  std::vector<std::vector<bool>> found;
  std::optional<int64_t> fail_at;
  RunSummary ended_with;
};

TEST(RunPipeline, VideoFileNeverDropsAFrameAndEveryRowCarriesTheSourceIndex) {
  TempDir dir;
  const SceneOptions options = SmallScene(12);
  SyntheticScene scene(options);
  {
    FrameWriter writer({dir.file("clip.avi"), "", options.fps});
    cv::Mat image;
    for (int i = 0; i < options.frame_count; ++i) {
      scene.render(i, image);
      writer.write(image, i);
    }
  }
  FrameSourceSpec spec;
  spec.input = dir.file("clip.avi");
  std::unique_ptr<FrameSource> source = OpenFrameSource(spec);
  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink sink;
  const RunSummary summary = RunPipeline(*source, session, {&sink});

  EXPECT_EQ(summary.stop_reason, StopReason::kEndOfInput);
  EXPECT_EQ(summary.frames, 12);
  EXPECT_EQ(summary.dropped, 0);
  EXPECT_EQ(summary.first_index, 0);
  EXPECT_EQ(summary.last_index, 11);
  ASSERT_EQ(sink.indices.size(), 12u);
  for (size_t i = 0; i < sink.indices.size(); ++i) {
    EXPECT_EQ(sink.indices[i], static_cast<int64_t>(i));
    EXPECT_EQ(sink.result_indices[i], sink.indices[i]) << "the row names the source's frame";
    EXPECT_NEAR(sink.times[i], static_cast<double>(i) / options.fps, 1e-6);
  }
  EXPECT_EQ(sink.begins, 1);
  EXPECT_EQ(sink.ends, 1);
  EXPECT_EQ(sink.info.frame_size, options.size);
  EXPECT_EQ(sink.info.frame_count, 12);
  EXPECT_THAT(sink.info.marker_names, ::testing::ElementsAre("red", "blue", "green"));
  // A sink joining late is told the same.
  const RunInfo late = DescribeRun(*source, session);
  EXPECT_EQ(late.marker_names, sink.info.marker_names);
  EXPECT_EQ(late.frame_count, sink.info.frame_count);
  EXPECT_EQ(late.source, sink.info.source);
  EXPECT_EQ(late.metric, sink.info.metric);
}

TEST(RunPipeline, ImageSequenceKeepsItsFileIndicesAndRate) {
  TempDir dir;
  const SceneOptions options = SmallScene(5);
  SyntheticScene scene(options);
  {
    FrameWriter writer({dir.file("f%03d.png"), "", options.fps});
    cv::Mat image;
    for (int i = 0; i < options.frame_count; ++i) {
      scene.render(i, image);
      writer.write(image, i);
    }
  }
  FrameSourceSpec spec;
  spec.input = dir.file("f%03d.png");
  spec.sequence_fps = 10.0;
  std::unique_ptr<FrameSource> source = OpenFrameSource(spec);
  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink sink;
  const RunSummary summary = RunPipeline(*source, session, {&sink});
  EXPECT_EQ(summary.frames, 5);
  EXPECT_EQ(summary.dropped, 0);
  ASSERT_EQ(sink.indices.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(sink.indices[i], static_cast<int64_t>(i));
    EXPECT_NEAR(sink.times[i], 0.1 * static_cast<double>(i), 1e-9);
  }
}

TEST(RunPipeline, FoundCountsMatchTheRenderersTruth) {
  // The tip marker is fully covered in frames 4..8 and fully visible otherwise, so "found" must
  // be exactly "visible" (the colour tracker reports a covered marker as not found).
  SceneOptions options = SmallScene(14);
  SyntheticScene probe(options);
  cv::Mat image;
  cv::Rect2d around_tip;  // Where the tip marker is during frames 4..8, with a margin.
  for (int i = 4; i <= 8; ++i) {
    const cv::Point2d tip = *probe.render(i, image).markers[2].centroid_px;
    const double r = options.marker_radius_px + 2;
    const cv::Rect2d box(tip.x - r, tip.y - r, 2 * r, 2 * r);
    around_tip = i == 4 ? box : (around_tip | box);
  }
  Occluder cover;
  cover.rect_px = around_tip;
  cover.first_frame = 4;
  cover.last_frame = 8;
  SyntheticScene scene(options, NoiseOptions{}, RenderOptions{}, {cover});

  std::vector<Frame> frames;
  std::vector<SceneTruth> truth;
  for (int i = 0; i < options.frame_count; ++i) {
    Frame frame;
    truth.push_back(scene.render(i, frame.image));
    frame.index = i;
    frame.time_s = truth.back().time_s;
    frames.push_back(frame);
  }
  // A source over the rendered frames.
  class Frames : public FrameSource {
   public:
    explicit Frames(const std::vector<Frame>& frames) : frames_(frames) {}
    bool read(Frame& frame) override {
      if (next_ >= frames_.size()) return false;
      frame = frames_[next_++];
      return true;
    }
    std::string description() const override { return "rendered frames"; }
    std::optional<int64_t> frame_count() const override {
      return static_cast<int64_t>(frames_.size());
    }
    std::optional<double> fps() const override { return 30.0; }

   private:
    const std::vector<Frame>& frames_;
    size_t next_ = 0;
  } source(frames);

  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink sink;
  const RunSummary summary = RunPipeline(source, session, {&sink});
  ASSERT_EQ(summary.frames, 14);
  std::vector<int64_t> visible(3, 0);
  for (size_t f = 0; f < truth.size(); ++f) {
    for (size_t m = 0; m < 3; ++m) {
      const double fraction = truth[f].markers[m].visible_fraction;
      ASSERT_TRUE(fraction == 0.0 || fraction == 1.0) << "the cover must hide all or nothing";
      visible[m] += fraction == 1.0 ? 1 : 0;
      EXPECT_EQ(sink.found[f][m], fraction == 1.0) << "frame " << f << " marker " << m;
    }
  }
  ASSERT_EQ(visible[2], 9);
  for (size_t m = 0; m < 3; ++m) {
    EXPECT_EQ(summary.markers[m].found, visible[m]) << summary.markers[m].name;
  }
  EXPECT_DOUBLE_EQ(summary.found_rate(2), 9.0 / 14.0);
  EXPECT_EQ(summary.measured, 9) << "the angle needs all three markers";
  EXPECT_THAT(summary.BriefReport(), HasSubstr("green 64.3 %"));
  EXPECT_THAT(summary.FullReport(), HasSubstr("green"));
}

TEST(RunPipeline, StopRequestEndsCleanlyWithASummary) {
  std::unique_ptr<FrameSource> source = OpenSyntheticSource(SmallScene(50), NoiseOptions{});
  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink sink;
  RunOptions options;
  options.stop_requested = [&sink] { return sink.indices.size() >= 3; };
  const RunSummary summary = RunPipeline(*source, session, {&sink}, options);
  EXPECT_EQ(summary.stop_reason, StopReason::kStopRequested);
  EXPECT_TRUE(summary.ok());
  EXPECT_EQ(summary.frames, 3);
  EXPECT_EQ(sink.ends, 1);
  EXPECT_EQ(sink.ended_with.frames, 3);
  EXPECT_EQ(sink.ended_with.stop_reason, StopReason::kStopRequested);
  EXPECT_THAT(summary.FullReport(), HasSubstr("stop requested"));
}

// One stop reason everywhere: the command's words (RunOptions::describe_stop) are in both
// reports and in what the sinks' end() gets (the stream's end record is made from it), where
// the one-line report used to say "stop requested" and the full one "duration reached".
TEST(RunPipeline, TheCommandsStopReasonIsTheSameInEveryReportAndEveryEnd) {
  std::unique_ptr<FrameSource> source = OpenSyntheticSource(SmallScene(50), NoiseOptions{});
  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink sink;
  RunOptions options;
  options.stop_requested = [&sink] { return sink.indices.size() >= 3; };
  options.describe_stop = [](StopReason reason) {
    return reason == StopReason::kStopRequested ? std::string("duration reached") : std::string();
  };
  const RunSummary summary = RunPipeline(*source, session, {&sink}, options);
  ASSERT_EQ(summary.stop_reason, StopReason::kStopRequested);
  EXPECT_EQ(summary.stop_text(), "duration reached");
  EXPECT_EQ(sink.ended_with.stop_text(), "duration reached") << "the stream's end record";
  EXPECT_THAT(summary.BriefReport(), HasSubstr("3 frames (duration reached)"));
  EXPECT_THAT(summary.FullReport(), HasSubstr("(duration reached)"));
  EXPECT_THAT(summary.FullReport(), ::testing::Not(HasSubstr("stop requested")));
}

TEST(RunPipeline, MaxFramesAndTheKnownCountReachTheSinks) {
  std::unique_ptr<FrameSource> source = OpenSyntheticSource(SmallScene(50), NoiseOptions{});
  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink sink;
  RunOptions options;
  options.max_frames = 4;
  const RunSummary summary = RunPipeline(*source, session, {&sink}, options);
  EXPECT_EQ(summary.stop_reason, StopReason::kMaxFrames);
  EXPECT_EQ(summary.frames, 4);
  EXPECT_EQ(sink.info.frame_count, 4);
}

TEST(RunPipeline, AnErrorInASinkEndsTheRunWithItsMessage) {
  std::unique_ptr<FrameSource> source = OpenSyntheticSource(SmallScene(50), NoiseOptions{});
  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink first, failing;
  failing.fail_at = 3;
  const RunSummary summary = RunPipeline(*source, session, {&first, &failing});
  EXPECT_EQ(summary.stop_reason, StopReason::kError);
  EXPECT_FALSE(summary.ok());
  EXPECT_THAT(summary.error, HasSubstr("disk full at frame 2"));
  EXPECT_EQ(summary.frames, 2) << "the failing frame did not reach every sink";
  EXPECT_EQ(first.ends, 1);
  EXPECT_EQ(failing.ends, 1);
}

TEST(RunPipeline, ARunOfNoFramesStillBeginsAndEndsEverySink) {
  std::unique_ptr<FrameSource> source = OpenSyntheticSource(SmallScene(5), NoiseOptions{});
  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink sink;
  RunOptions options;
  options.max_frames = 0;
  const RunSummary summary = RunPipeline(*source, session, {&sink}, options);
  EXPECT_EQ(summary.frames, 0);
  EXPECT_EQ(sink.begins, 1);
  EXPECT_TRUE(sink.info.frame_size.empty());
  EXPECT_EQ(sink.ends, 1);
  EXPECT_FALSE(summary.first_index);
}

// A loop of the caller's own (the live window) drives a PipelineRun frame by frame: the same
// counts and summary as RunPipeline gives for the same frames; a sink joining mid-run gets only
// the frames after it joined and is begun and ended by its owner, not by the run.
TEST(PipelineRun, FrameByFrameGivesRunPipelinesSummaryAndAJoinedSinkOnlyItsFrames) {
  std::unique_ptr<FrameSource> reference = OpenSyntheticSource(SmallScene(8), NoiseOptions{});
  TrackingSession reference_session(ThreeMarkerSceneConfig());
  const RunSummary expected = RunPipeline(*reference, reference_session, {});

  std::unique_ptr<FrameSource> source = OpenSyntheticSource(SmallScene(8), NoiseOptions{});
  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink fixed, joined;
  PipelineRun run(session, DescribeRun(*source, session), {&fixed});
  Frame frame;
  for (int i = 0; source->read(frame); ++i) {
    if (i == 3) run.join(joined);
    if (i == 6) run.leave(joined);
    const FrameResult& result = run.process(frame);
    EXPECT_EQ(result.frame_index, i);
  }
  EXPECT_EQ(run.frames(), 8);
  EXPECT_EQ(fixed.begins, 1);
  EXPECT_EQ(fixed.info.frame_size, cv::Size(320, 240)) << "begun at the first frame";
  EXPECT_EQ(fixed.indices.size(), 8u);
  EXPECT_EQ(joined.indices, (std::vector<int64_t>{3, 4, 5}));
  const RunSummary summary = run.finish(StopReason::kEndOfInput, 0);
  EXPECT_EQ(fixed.ends, 1);
  EXPECT_EQ(fixed.ended_with.frames, 8);
  EXPECT_EQ(joined.begins, 0);
  EXPECT_EQ(joined.ends, 0);
  EXPECT_EQ(summary.frames, expected.frames);
  EXPECT_EQ(summary.first_index, expected.first_index);
  EXPECT_EQ(summary.last_index, expected.last_index);
  EXPECT_EQ(summary.measured, expected.measured);
  ASSERT_EQ(summary.markers.size(), expected.markers.size());
  for (size_t i = 0; i < summary.markers.size(); ++i) {
    EXPECT_EQ(summary.markers[i].found, expected.markers[i].found) << summary.markers[i].name;
  }
  EXPECT_EQ(summary.source, expected.source);
}

TEST(RunPipeline, GrayFramesForColourTrackingAreAnErrorNamingTheSource) {
  class GraySource : public FrameSource {
   public:
    bool read(Frame& frame) override {
      frame.image = cv::Mat(48, 64, CV_8UC3, cv::Scalar(90, 90, 90));
      frame.index = index_++;
      return true;
    }
    std::string description() const override { return "video gray.avi"; }
    std::optional<int64_t> frame_count() const override { return std::nullopt; }
    std::optional<double> fps() const override { return std::nullopt; }

   private:
    int64_t index_ = 0;
  } source;
  TrackingSession session(ThreeMarkerSceneConfig());
  RecordingSink sink;
  const RunSummary summary = RunPipeline(source, session, {&sink});
  EXPECT_EQ(summary.stop_reason, StopReason::kError);
  EXPECT_THAT(summary.error, HasSubstr("video gray.avi"));
  EXPECT_THAT(summary.error, HasSubstr("grayscale"));
  EXPECT_TRUE(sink.indices.empty());
}

// A predicted video (a key frame every 12th) whose frames 28-35 the decoder silently slid 16 px
// to the left (a macroblock), as a flipped bit does; frame 40 does not decode.
class SlidPredictedFrames : public FrameSource {
 public:
  explicit SlidPredictedFrames(int frames) : scene_(SmallScene(frames)) {}
  bool read(Frame& frame) override {
    if (next_ == 40) throw InputError("clip.mp4: frame 40 cannot be decoded");
    if (next_ >= scene_.options().frame_count) return false;
    truth_.push_back(scene_.render(next_, frame.image));
    if (next_ >= 28 && next_ < 36) {
      const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -16, 0, 1, 0);
      cv::warpAffine(frame.image.clone(), frame.image, shift, frame.image.size(),
                     cv::INTER_NEAREST, cv::BORDER_REPLICATE);
    }
    frame.index = next_;
    frame.time_s = next_ / 30.0;
    frame.key_frame = next_ % 12 == 0;
    ++next_;
    return true;
  }
  std::string description() const override { return "clip.mp4"; }
  std::optional<int64_t> frame_count() const override { return scene_.options().frame_count; }
  std::optional<double> fps() const override { return 30.0; }
  const std::vector<SceneTruth>& truth() const { return truth_; }

 private:
  SyntheticScene scene_;
  int next_ = 0;
  std::vector<SceneTruth> truth_;
};

TEST(RunStream, PullsRunPipelinesCheckedResultsThenItsError) {
  SlidPredictedFrames pushed_source(60);
  TrackingSession pushed_session(ThreeMarkerSceneConfig());
  RecordingSink sink;
  const RunSummary pushed = RunPipeline(pushed_source, pushed_session, {&sink});
  ASSERT_EQ(pushed.stop_reason, StopReason::kError);

  SlidPredictedFrames source(60);
  TrackingSession session(ThreeMarkerSceneConfig());
  RunStream stream(source, session);
  std::vector<FrameResult> pulled;
  std::string error;
  try {
    while (std::optional<FrameResult> result = stream.next()) pulled.push_back(*result);
  } catch (const InputError& e) {
    error = e.what();
  }
  EXPECT_EQ(error, pushed.error) << "the error comes after every result before it";
  EXPECT_EQ(error, "clip.mp4: frame 40 cannot be decoded");
  EXPECT_TRUE(stream.ended());
  EXPECT_FALSE(stream.next()) << "the error is thrown once";
  ASSERT_EQ(pulled.size(), sink.indices.size());
  ASSERT_EQ(pulled.size(), 40u);
  EXPECT_EQ(stream.returned(), 40);
  EXPECT_EQ(stream.summary().frames, pushed.frames);
  EXPECT_EQ(stream.summary().notes, pushed.notes);
  // Frames 28-35 (three markers each) were refused by the key frame's check, not the tracker;
  // so were 36-39: the run ended with damage, the frame before them was not believed, and no
  // key frame follows to vouch for them.
  EXPECT_THAT(pushed.notes, ::testing::Contains(HasSubstr("36 marker-frames not believed")));
  int slid_found = 0;
  for (size_t f = 0; f < pulled.size(); ++f) {
    EXPECT_EQ(pulled[f].frame_index, sink.indices[f]);
    for (size_t m = 0; m < 3; ++m) {
      const Observation& o = pulled[f].markers[m].observation;
      EXPECT_EQ(o.found(), sink.found[f][m]) << "frame " << f << " marker " << m;
      if (!o.found()) continue;
      // Found means at the true place: the slid frames' markers are not believed.
      const cv::Point2d truth = *source.truth()[f].markers[m].centroid_px;
      EXPECT_LT(cv::norm(*o.position_px - truth), 3.0) << "frame " << f << " marker " << m;
      slid_found += f >= 28 && f < 36;
    }
  }
  EXPECT_EQ(slid_found, 0);
  int clean_found = 0;
  for (size_t f = 0; f < 28; ++f) {
    for (size_t m = 0; m < 3; ++m) clean_found += pulled[f].markers[m].observation.found();
  }
  EXPECT_EQ(clean_found, 28 * 3) << "the frames before the damage are tracked";
}

// A pair of predicted videos (two cameras, two encoders: the left's key frames every 12th, the
// right's every 10th) of one rendered scene, through a rig that sees every pixel the two views
// share at Z = 300 mm (the right camera 100 mm to the right, its principal point 100 px further
// right, f = 300 px). The left decoder silently slid frames 28-35 by 16 px (a flipped bit), which
// the epipolar check cannot see (the slide is along the epipolar line): without the key-frame
// check those markers are found in 3D, 48 mm too far.
class SlidPredictedPairs : public StereoInput {
 public:
  explicit SlidPredictedPairs(int frames) : scene_(SmallScene(frames)) {}
  bool read(FramePair& pair) override {
    if (next_ >= scene_.options().frame_count) return false;
    scene_.render(next_, pair.left.image);
    pair.left.image.copyTo(pair.right.image);
    if (next_ >= 28 && next_ < 36) {
      const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -16, 0, 1, 0);
      cv::warpAffine(pair.left.image.clone(), pair.left.image, shift, pair.left.image.size(),
                     cv::INTER_NEAREST, cv::BORDER_REPLICATE);
    }
    for (Frame* view : {&pair.left, &pair.right}) {
      view->index = next_;
      view->time_s = next_ / 30.0;
    }
    pair.left.key_frame = next_ % 12 == 0;
    pair.right.key_frame = next_ % 10 == 0;
    ++next_;
    return true;
  }
  std::string description() const override { return "left.mp4 + right.mp4"; }
  std::optional<double> fps() const override { return 30.0; }
  std::vector<std::string> files() const override { return {}; }

 private:
  SyntheticScene scene_;
  int next_ = 0;
};

StereoCalibration RigSeeingThePictureAt300Mm() {
  StereoCalibration stereo;
  stereo.left = {cv::Size(320, 240), cv::Matx33d(300, 0, 160, 0, 300, 120, 0, 0, 1), {0, 0, 0, 0, 0}};
  stereo.right = {cv::Size(320, 240), cv::Matx33d(300, 0, 260, 0, 300, 120, 0, 0, 1), {0, 0, 0, 0, 0}};
  stereo.T = cv::Vec3d(-100, 0, 0);
  CompleteStereoCalibration(stereo);
  return stereo;
}

// Every pair's row as the sinks get it.
class PairRows : public PairSink {
 public:
  void consume(const FramePair& pair, const StereoFrameResult& result) override {
    EXPECT_EQ(pair.left.index, result.frame_index);
    ASSERT_NE(result.left_view, nullptr);  // The views' own results, as checked, for a window.
    EXPECT_EQ(result.left_view->frame_index, result.frame_index);
    EXPECT_EQ(result.right_view->frame_index, result.right_frame_index);
    rows.push_back(result);
  }
  std::vector<StereoFrameResult> rows;
};

TEST(RunPipeline, APairMarkerTheLeftDecoderSilentlyMovedIsNotFoundIn3DInThoseRows) {
  const StereoCalibration rig = RigSeeingThePictureAt300Mm();
  RunOptions unchecked;
  unchecked.check_key_frame_groups = false;
  SlidPredictedPairs believed_input(48);
  StereoSession believed_session(ThreeMarkerSceneConfig(), ThreeMarkerSceneConfig(), rig);
  PairRows believed;
  RunPipeline(believed_input, believed_session, {&believed}, unchecked);
  ASSERT_EQ(believed.rows.size(), 48u);
  for (int f = 28; f < 36; ++f) {
    for (const StereoMarkerResult& m : believed.rows[f].markers) {
      ASSERT_TRUE(m.point.found()) << "the damage this check is for: frame " << f << " " << m.name;
      EXPECT_GT(m.point.position_mm->z, 340.0) << "frame " << f << " " << m.name;
    }
  }

  SlidPredictedPairs input(48);
  StereoSession session(ThreeMarkerSceneConfig(), ThreeMarkerSceneConfig(), rig);
  PairRows sink;
  const RunSummary summary = RunPipeline(input, session, {&sink});
  ASSERT_EQ(summary.stop_reason, StopReason::kEndOfInput) << summary.error;
  ASSERT_EQ(sink.rows.size(), 48u);
  for (int f = 0; f < 48; ++f) {
    const StereoFrameResult& row = sink.rows[f];
    EXPECT_EQ(row.frame_index, f) << "in source order";
    const bool slid = f >= 28 && f < 36;
    for (const StereoMarkerResult& m : row.markers) {
      if (slid) {
        EXPECT_FALSE(m.point.found()) << "frame " << f << " " << m.name;
        EXPECT_EQ(m.status, "left_implausible") << "frame " << f << " " << m.name;
        EXPECT_TRUE(m.right.found()) << "the right view was not damaged";
      } else {
        ASSERT_TRUE(m.point.found()) << "frame " << f << " " << m.name << ": " << m.status;
        EXPECT_NEAR(m.point.position_mm->z, 300.0, 1e-6) << "frame " << f << " " << m.name;
      }
    }
    // Measured with the damaged markers: absent there, as one view's row's measurements are.
    EXPECT_EQ(row.shape.angle_deg.has_value(), !slid) << "frame " << f;
    EXPECT_EQ(row.left_angle_deg.has_value(), !slid) << "frame " << f;
    EXPECT_TRUE(row.right_angle_deg.has_value()) << "frame " << f;
  }
  for (const MarkerRunSummary& marker : summary.markers) EXPECT_EQ(marker.found, 40) << marker.name;
  EXPECT_THAT(summary.notes, ::testing::Contains(HasSubstr("24 marker-frames not believed")));
}

// RunStream over pairs: the same run, pulled; the same rows as RunPipeline pushes.
TEST(RunStream, PullsAPairRunsCheckedRows) {
  const StereoCalibration rig = RigSeeingThePictureAt300Mm();
  SlidPredictedPairs pushed_input(40);
  StereoSession pushed_session(ThreeMarkerSceneConfig(), ThreeMarkerSceneConfig(), rig);
  PairRows pushed;
  const RunSummary summary = RunPipeline(pushed_input, pushed_session, {&pushed});

  SlidPredictedPairs input(40);
  StereoSession session(ThreeMarkerSceneConfig(), ThreeMarkerSceneConfig(), rig);
  StereoRunStream stream(input, session);
  std::vector<StereoFrameResult> pulled;
  while (std::optional<StereoFrameResult> result = stream.next()) {
    EXPECT_EQ(result->left_view, nullptr) << "a kept result does not point into the session";
    pulled.push_back(*result);
  }
  ASSERT_TRUE(stream.ended());
  ASSERT_EQ(pulled.size(), pushed.rows.size());
  ASSERT_EQ(pulled.size(), 40u);
  for (size_t f = 0; f < pulled.size(); ++f) {
    EXPECT_EQ(pulled[f].frame_index, pushed.rows[f].frame_index);
    for (size_t m = 0; m < 3; ++m) {
      EXPECT_EQ(pulled[f].markers[m].status, pushed.rows[f].markers[m].status) << f;
      EXPECT_EQ(pulled[f].markers[m].point.position_mm, pushed.rows[f].markers[m].point.position_mm);
    }
  }
  EXPECT_EQ(pulled[30].markers[0].status, "left_implausible");
  EXPECT_EQ(stream.summary().frames, summary.frames);
  EXPECT_EQ(stream.summary().notes, summary.notes);
}

TEST(RunStream, AnInputWithoutFramesIsAnErrorAndMaxFramesEndsIt) {
  class NoFrames : public FrameSource {
   public:
    bool read(Frame&) override { return false; }
    std::string description() const override { return "empty.avi"; }
    std::optional<int64_t> frame_count() const override { return 0; }
    std::optional<double> fps() const override { return std::nullopt; }
  } empty;
  TrackingSession session(ThreeMarkerSceneConfig());
  RunStream stream(empty, session);
  try {
    stream.next();
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("empty.avi: no frames to read"));
  }
  std::unique_ptr<FrameSource> source = OpenSyntheticSource(SmallScene(50), NoiseOptions{});
  TrackingSession again(ThreeMarkerSceneConfig());
  RunOptions options;
  options.max_frames = 4;
  RunStream four(*source, again, options);
  int count = 0;
  while (four.next()) ++count;
  EXPECT_EQ(count, 4);
  EXPECT_EQ(four.summary().stop_reason, StopReason::kMaxFrames);
  EXPECT_EQ(four.info().frame_count, 4);
}

TEST(CsvSink, WritesOneCompleteRowPerFrameWithTheSourceIndex) {
  TempDir dir;
  std::unique_ptr<FrameSource> source = OpenSyntheticSource(SmallScene(6), NoiseOptions{});
  TrackingSession session(ThreeMarkerSceneConfig());
  CsvSink csv(dir.file("run.csv"), TrackingColumns({"red", "blue", "green"}, false));
  const RunSummary summary = RunPipeline(*source, session, {&csv});
  ASSERT_EQ(summary.frames, 6);
  const std::vector<std::string> lines = testing::ReadLines(dir.file("run.csv"));
  ASSERT_EQ(lines.size(), 7u);
  const size_t columns = testing::SplitCsv(lines[0]).size();
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> row = testing::SplitCsv(lines[i]);
    ASSERT_EQ(row.size(), columns);
    EXPECT_EQ(row[0], std::to_string(i - 1));
  }
}


// The latency columns of a CSV row, by name: capture -> result, -> row (and -> command).
struct RowLatency {
  double result_ms, row_ms;
};

std::vector<RowLatency> LatencyRows(const std::string& csv) {
  const std::vector<std::string> lines = testing::ReadLines(csv);
  const std::vector<std::string> header = testing::SplitCsv(lines.at(0));
  const auto column = [&](const std::string& name) {
    const auto at = std::find(header.begin(), header.end(), name);
    EXPECT_NE(at, header.end()) << name;
    return static_cast<size_t>(at - header.begin());
  };
  const size_t result = column("latency_result_ms"), row = column("latency_row_ms");
  EXPECT_LT(result, row);
  EXPECT_EQ(row + 1, column("proc_ms")) << "the timings end the row";
  std::vector<RowLatency> rows;
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> fields = testing::SplitCsv(lines[i]);
    rows.push_back({std::stod(fields.at(result)), std::stod(fields.at(row))});
  }
  return rows;
}

// A live source's stand-in: frames rendered on demand, as a camera would hand them over.
class LiveScene : public FrameSource {
 public:
  explicit LiveScene(int frames) : scene_(OpenSyntheticSource(SmallScene(frames), NoiseOptions{})) {}
  bool read(Frame& frame) override { return scene_->read(frame); }
  std::string description() const override { return "camera 7"; }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override { return 30.0; }
  bool is_live() const override { return true; }

 private:
  std::unique_ptr<FrameSource> scene_;
};

TEST(CsvSink, LatencyColumnsArePresentAndOrderedFromCaptureToResultToRow) {
  TempDir dir;
  // A file (its capture is its decoding, on the read-ahead thread) and a camera (its capture
  // thread, newest frame wins).
  for (bool live : {false, true}) {
    std::unique_ptr<FrameSource> source;
    if (live) {
      source = std::make_unique<NewestFrameSource>(std::make_unique<LiveScene>(8));
    } else {
      source = std::make_unique<ReadAheadSource>(OpenSyntheticSource(SmallScene(8), NoiseOptions{}));
    }
    TrackingSession session(ThreeMarkerSceneConfig());
    CsvSink csv(dir.file("run.csv"), TrackingColumns({"red", "blue", "green"}, false));
    const RunSummary summary = RunPipeline(*source, session, {&csv});
    ASSERT_GT(summary.frames, 0);
    const std::vector<RowLatency> rows = LatencyRows(dir.file("run.csv"));
    ASSERT_EQ(rows.size(), static_cast<size_t>(summary.frames));
    for (const RowLatency& row : rows) {
      EXPECT_GE(row.result_ms, 0.0) << (live ? "camera" : "file");
      EXPECT_LE(row.result_ms, row.row_ms) << (live ? "camera" : "file");
    }
    EXPECT_GT(summary.latency_result_ms_median, 0.0);
    EXPECT_LE(summary.latency_result_ms_median, summary.latency_result_ms_p99);
    EXPECT_LE(summary.latency_result_ms_median, summary.latency_done_ms_median);
    EXPECT_LE(summary.latency_done_ms_median, summary.latency_done_ms_p99);
    EXPECT_THAT(summary.FullReport(), HasSubstr("latency from capture"));
  }
}

}  // namespace
}  // namespace softsight
