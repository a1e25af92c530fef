#include "softsight/pipeline/tracking_session.h"

#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/test_util.h"
#include "pipeline/scene_config_test_util.h"
#include "softsight/core/error.h"
#include "softsight/geometry/triangle.h"
#include "softsight/sim/scene.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/hsv_picker.h"
#include "softsight/track/template_tracker.h"

namespace softsight {
namespace {

using testing::ColourMarker;
using testing::ThreeMarkerSceneConfig;

struct Clip {
  std::vector<Frame> frames;
  std::vector<SceneTruth> truth;
};

// The first `count` frames of a sweep over `stretch` x `count` frames: with the default the
// markers move up to ~10 px per frame, as a fast actuator filmed at 30 fps does (a sweep in
// `count` frames would move them 80-200 px from one frame to the next, which the session
// rightly calls a jump).
Clip Render(int count, SceneOptions options = {}, int stretch = 10) {
  options.frame_count = stretch * count;
  if (options.markers.size() == 3) options.max_bend_deg = 120;
  SyntheticScene scene(options);
  Clip clip;
  for (int i = 0; i < count; ++i) {
    Frame frame;
    clip.truth.push_back(scene.render(i, frame.image));
    frame.index = i;
    frame.time_s = clip.truth.back().time_s;
    clip.frames.push_back(frame);
  }
  return clip;
}

TEST(TrackingSession, TracksEveryMarkerAndMeasuresLikeTheTruth) {
  const Clip clip = Render(6);
  TrackingSession session(ThreeMarkerSceneConfig());
  for (size_t i = 0; i < clip.frames.size(); ++i) {
    const FrameResult& result = session.process(clip.frames[i]);
    EXPECT_EQ(result.frame_index, static_cast<int64_t>(i));
    EXPECT_DOUBLE_EQ(result.time_s, clip.truth[i].time_s);
    ASSERT_EQ(result.markers.size(), 3u);
    for (size_t m = 0; m < 3; ++m) {
      EXPECT_EQ(result.markers[m].name, clip.truth[i].markers[m].name);
      ASSERT_TRUE(result.markers[m].observation.found());
      EXPECT_LT(cv::norm(*result.markers[m].observation.position_px -
                         *clip.truth[i].markers[m].centroid_px),
                0.2);
    }
    ASSERT_TRUE(result.measurement.angle_deg.has_value());
    EXPECT_NEAR(*result.measurement.angle_deg, *clip.truth[i].measurement.angle_deg, 0.3);
    EXPECT_GE(result.proc_ms, 0.0);
  }
}

TEST(TrackingSession, ARepeatedLivePictureIsStaleNotAMeasurementAndTrackingGoesOnAfterIt) {
  // A frozen camera hands out its last picture again (Frame::repeated): every marker is `stale`,
  // no angle is measured, and the next new picture is tracked as before.
  const Clip clip = Render(8);
  TrackingSession session(ThreeMarkerSceneConfig());
  for (size_t i = 0; i < clip.frames.size(); ++i) {
    Frame frame = clip.frames[i];
    const bool frozen = i == 3 || i == 4;
    if (frozen) {
      frame = clip.frames[2];
      frame.index = static_cast<int64_t>(i);
      frame.repeated = true;
    }
    const FrameResult& result = session.process(frame);
    for (const MarkerObservation& m : result.markers) {
      if (frozen) {
        EXPECT_EQ(m.observation.status(), MarkerStatus::kStale) << "frame " << i;
      } else {
        EXPECT_TRUE(m.observation.found()) << m.name << " in frame " << i;
      }
    }
    EXPECT_EQ(result.measurement.angle_deg.has_value(), !frozen) << "frame " << i;
  }
  EXPECT_STREQ(MarkerStatusName(MarkerStatus::kStale), "stale");
}

TEST(TrackingSession, FramesMissingFromTheSourceAreTimeThatPassedForTheMarkers) {
  // A camera that dropped frames, an image sequence with numbers missing: the frame indices
  // skip, and the markers moved meanwhile as far as they move in that many frames (here the tip
  // ~70 px in 10 frames of a bend, where one frame's steady step taught its motion a tight
  // gate). Each is found where it is, never `implausible` (before: blue and the tip were, for
  // up to 26 frames after the gap).
  SceneOptions options;
  options.frame_count = 400;
  options.oscillate = true;
  options.oscillate_cycles = 2;
  SyntheticScene scene(options);
  TrackingSession session(ThreeMarkerSceneConfig());
  int processed = 0;
  for (int i = 0; i < 80; ++i) {
    if (i >= 39 && i < 49) continue;  // Dropped by the source.
    Frame frame;
    const SceneTruth truth = scene.render(i, frame.image);
    frame.index = i;
    frame.time_s = truth.time_s;
    const FrameResult& result = session.process(frame);
    ++processed;
    for (size_t m = 0; m < 3; ++m) {
      const Observation& o = result.markers[m].observation;
      ASSERT_TRUE(o.found()) << result.markers[m].name << " in frame " << i << ": "
                             << MarkerStatusName(o.status());
      EXPECT_LT(cv::norm(*o.position_px - *truth.markers[m].centroid_px), 0.2)
          << result.markers[m].name << " in frame " << i;
    }
  }
  EXPECT_EQ(processed, 70);
}

TEST(TrackingSession, TemplateMarkerIsNotFoundBeforeItsTemplateFrame) {
  const Clip clip = Render(5);
  TrackingConfig config = ThreeMarkerSceneConfig();
  const cv::Point2d blue = *clip.truth[2].markers[1].centroid_px;
  config.markers[1].params = ParamsForMethod("zncc", {});
  config.markers[1].params.get<TemplateParams>().template_frame = 2;
  config.markers[1].params.get<TemplateParams>().rect = cv::Rect(static_cast<int>(blue.x) - 12,
                                          static_cast<int>(blue.y) - 12, 25, 25);
  TrackingSession session(config);
  for (int i = 0; i < 5; ++i) {
    const FrameResult& result = session.process(clip.frames[i]);
    EXPECT_EQ(result.markers[1].observation.found(), i >= 2) << "frame " << i;
    EXPECT_EQ(result.measurement.angle_deg.has_value(), i >= 2) << "frame " << i;
  }
}

TEST(TrackingSession, ReselectIsRecordedInTheConfigSoASavedConfigReproducesIt) {
  const Clip clip = Render(1);
  TrackingSession session(ThreeMarkerSceneConfig());
  session.process(clip.frames[0]);
  session.reselect("blue", clip.frames[0], cv::Rect(10, 20, 30, 40));
  EXPECT_EQ(session.config().markers[1].params.get<ColourParams>().roi, cv::Rect(10, 20, 30, 40));
  EXPECT_THROW(session.reselect("yellow", clip.frames[0], cv::Rect(0, 0, 5, 5)),
               InputError);
}

// Whoever keeps live edits (a recording) hears of each edit once, after it is made, with the
// frame it follows; a failed edit is not reported; a config's own changes replayed are edits too.
TEST(TrackingSession, TellsItsEditListenerOfEachEditWithTheFrameItFollows) {
  const Clip clip = Render(4);
  TrackingConfig config = ThreeMarkerSceneConfig();
  ConfigChange replayed = ConfigChange::ResetTipReference();
  replayed.after_frame = 3;
  config.changes.push_back(replayed);
  TrackingSession session(config);
  std::vector<ConfigChange> heard;
  session.set_edit_listener([&heard](const ConfigChange& change) { heard.push_back(change); });
  session.process(clip.frames[0]);
  session.process(clip.frames[1]);
  MarkerSpec spec = session.config().markers[0];
  spec.params.get<ColourParams>().h = {5, 25};
  session.respec(spec);
  session.reselect("blue", clip.frames[1], cv::Rect(10, 20, 30, 40));
  EXPECT_THROW(session.reselect("yellow", clip.frames[1], cv::Rect(0, 0, 5, 5)), InputError);
  session.process(clip.frames[2]);
  session.retrack("green", clip.frames[2]);
  session.reset_tip_reference();
  session.process(clip.frames[3]);  // Replays the config's change after frame 3.

  ASSERT_EQ(heard.size(), 5u);
  EXPECT_EQ(heard[0].kind, ConfigChange::Kind::kRespec);
  EXPECT_EQ(heard[0].spec.name, spec.name);
  EXPECT_EQ(heard[0].spec.params.get<ColourParams>().h.hi, 25);
  EXPECT_EQ(heard[0].after_frame, 1);
  EXPECT_EQ(heard[1].kind, ConfigChange::Kind::kReselect);
  EXPECT_EQ(heard[1].marker, "blue");
  EXPECT_EQ(heard[1].rect, cv::Rect(10, 20, 30, 40));
  EXPECT_EQ(heard[1].after_frame, 1);
  EXPECT_EQ(heard[2].kind, ConfigChange::Kind::kRetrack);
  EXPECT_EQ(heard[2].marker, "green");
  EXPECT_EQ(heard[2].after_frame, 2);
  EXPECT_EQ(heard[3].kind, ConfigChange::Kind::kResetTipReference);
  EXPECT_EQ(heard[3].after_frame, 2);
  EXPECT_EQ(heard[4].kind, ConfigChange::Kind::kResetTipReference);
  EXPECT_EQ(heard[4].after_frame, 3);
}

// What the live window does when a person clicks a colour marker at frame N > 0 and saves (`s`):
// the pick's ranges and search box go to the session, which tracks frame N with them and records
// the roi with its frame; `track` with the saved config must then give the same positions from
// frame N on, and before N nothing (at frame 0 the marker was ~40 px from the pick's box).
TEST(TrackingSession, AColourPickAtALaterFrameIsSavedWithItsFrameAndTrackReproducesIt) {
  constexpr int kPickFrame = 10;
  const Clip clip = Render(14, {}, /*stretch=*/3);
  TrackingConfig config = ThreeMarkerSceneConfig();
  config.markers[2].params.get<ColourParams>().h = {20, 30};  // green's ranges are wrong (yellow) until the pick
  TrackingSession live(config);
  std::vector<std::optional<cv::Point2d>> live_green(clip.frames.size());
  for (int i = 0; i < static_cast<int>(clip.frames.size()); ++i) {
    const FrameResult* result = &live.process(clip.frames[i]);
    if (i == kPickFrame) {
      const cv::Point2d at = *clip.truth[i].markers[2].centroid_px;
      const auto pick = PickMarkerColourAt(clip.frames[i].image, at, HsvPickOptions{}, 32);
      ASSERT_TRUE(pick.has_value());
      MarkerSpec spec = live.config().markers[2];
      ApplyColourPick(*pick, &spec.params.get<ColourParams>());
      live.respec(spec);
      result = &live.reselect("green", clip.frames[i], pick->roi);
    }
    live_green[i] = result->markers[2].observation.position_px;
  }
  EXPECT_EQ(live.config().markers[2].params.get<ColourParams>().roi_frame, kPickFrame);
  const cv::Point2d at_pick = *clip.truth[kPickFrame].markers[2].centroid_px;
  ASSERT_GT(cv::norm(at_pick - *clip.truth[0].markers[2].centroid_px), 30.0);

  testing::TempDir dir;
  SaveTrackingConfig(live.config(), dir.file("live.yaml"));
  const TrackingConfig saved = LoadTrackingConfig(dir.file("live.yaml"));
  EXPECT_EQ(saved.markers[2].params.get<ColourParams>().roi_frame, kPickFrame);
  TrackingSession track(saved);
  for (int i = 0; i < static_cast<int>(clip.frames.size()); ++i) {
    const Observation& green = track.process(clip.frames[i]).markers[2].observation;
    if (i < kPickFrame) {
      EXPECT_EQ(green.status(), MarkerStatus::kNotStarted) << "frame " << i;
      continue;
    }
    ASSERT_TRUE(green.found()) << "frame " << i;
    ASSERT_TRUE(live_green[i].has_value()) << "frame " << i;
    EXPECT_LT(cv::norm(*green.position_px - *live_green[i]), 1e-3) << "frame " << i;
    EXPECT_LT(cv::norm(*green.position_px - *clip.truth[i].markers[2].centroid_px), 0.3)
        << "frame " << i;
  }
}

TEST(TrackingSession, CameraModelMeasuresUndistortedPositionsButReportsRecordedOnes) {
  const Clip clip = Render(1);
  TrackingConfig config = ThreeMarkerSceneConfig();
  CameraIntrinsics camera;
  camera.image_size = clip.frames[0].image.size();
  camera.camera_matrix = cv::Matx33d(500, 0, 320, 0, 500, 240, 0, 0, 1);
  camera.distortion = {-0.3, 0.1, 0, 0, 0};
  config.camera = camera;
  TrackingSession plain(ThreeMarkerSceneConfig());
  TrackingSession corrected(config);
  const FrameResult raw = plain.process(clip.frames[0]);
  const FrameResult& result = corrected.process(clip.frames[0]);
  // Positions are where the markers are in the recorded image.
  for (size_t m = 0; m < 3; ++m) {
    EXPECT_EQ(*result.markers[m].observation.position_px, *raw.markers[m].observation.position_px);
  }
  // The chord is measured between the undistorted base and tip (computed independently here).
  std::vector<cv::Point2d> ends = {*raw.markers[0].observation.position_px,
                                   *raw.markers[2].observation.position_px};
  std::vector<cv::Point2d> undistorted;
  cv::undistortPoints(ends, undistorted, camera.camera_matrix, camera.distortion, cv::noArray(),
                      camera.camera_matrix);
  ASSERT_TRUE(result.measurement.chord_px.has_value());
  EXPECT_NEAR(*result.measurement.chord_px, cv::norm(undistorted[0] - undistorted[1]), 1e-3);
  EXPECT_GT(std::abs(*result.measurement.chord_px - *raw.measurement.chord_px), 0.5)
      << "this lens bends lines visibly: undistortion must change the chord";

  cv::Mat small;
  cv::resize(clip.frames[0].image, small, {320, 240});
  EXPECT_THROW(corrected.process(Frame{small, 1, 0.1}), InputError);
}

TEST(TrackingSession, SetMetricAppliesToTheNextFrameAndKeepsTheBendingReference) {
  const Clip clip = Render(4);
  TrackingSession plain(ThreeMarkerSceneConfig());
  TrackingSession session(ThreeMarkerSceneConfig());
  for (int i = 0; i < 2; ++i) {
    plain.process(clip.frames[i]);
    EXPECT_FALSE(session.process(clip.frames[i]).measurement.chord_mm.has_value());
  }
  MetricModel metric;
  metric.scale_mm_per_px = 0.25;
  session.set_metric(metric);
  EXPECT_EQ(session.config().measure.metric.scale_mm_per_px, 0.25);
  for (int i = 2; i < 4; ++i) {
    const FrameResult expected = plain.process(clip.frames[i]);
    const Measurement& m = session.process(clip.frames[i]).measurement;
    ASSERT_TRUE(m.chord_mm && m.arc_length_mm && m.tip_disp_mm);
    EXPECT_DOUBLE_EQ(*m.chord_mm, 0.25 * *m.chord_px);
    EXPECT_DOUBLE_EQ(*m.arc_length_mm, 0.25 * *m.arc_length_px);
    // The reference is still frame 0's tip: the displacement continues, it does not restart.
    EXPECT_EQ(m.tip_disp_px, expected.measurement.tip_disp_px);
    EXPECT_GT(*m.tip_disp_px, 1.0);
    EXPECT_DOUBLE_EQ(*m.tip_disp_mm, 0.25 * *m.tip_disp_px);
  }

  // An invalid model is refused and the old one stays.
  MetricModel bad;
  bad.scale_mm_per_px = 0.0;
  EXPECT_THROW(session.set_metric(bad), InputError);
  bad.scale_mm_per_px.reset();
  bad.scale_points = MetricModel::ScalePoints{{0, 0}, {10, 0}, 5};
  EXPECT_THROW(session.set_metric(bad), InputError);
  EXPECT_EQ(session.config().measure.metric.scale_mm_per_px, 0.25);
  EXPECT_DOUBLE_EQ(*session.process(clip.frames[3]).measurement.chord_mm,
                   0.25 * *session.process(clip.frames[3]).measurement.chord_px);
}

TEST(TrackingSession, MeasurementPointIsTheUndistortedPointWithACameraModel) {
  TrackingConfig config = ThreeMarkerSceneConfig();
  EXPECT_EQ(TrackingSession(config).measurement_point({12.5, 300.25}), cv::Point2d(12.5, 300.25));
  CameraIntrinsics camera;
  camera.image_size = {640, 480};
  camera.camera_matrix = cv::Matx33d(500, 0, 320, 0, 500, 240, 0, 0, 1);
  camera.distortion = {-0.3, 0.1, 0, 0, 0};
  config.camera = camera;
  const cv::Point2d raw(40, 60);
  const cv::Point2d p = TrackingSession(config).measurement_point(raw);
  EXPECT_GT(cv::norm(p - raw), 1.0);  // This lens moves corner points visibly.
  // Truth: the lens maps the undistorted point back onto the recorded one.
  const std::vector<cv::Point3d> ray = {{(p.x - 320) / 500, (p.y - 240) / 500, 1.0}};
  std::vector<cv::Point2d> projected;
  cv::projectPoints(ray, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera.camera_matrix,
                    camera.distortion, projected);
  EXPECT_NEAR(projected[0].x, raw.x, 1e-3);
  EXPECT_NEAR(projected[0].y, raw.y, 1e-3);
}

// The angle at `at` between the rays to `a` and `b`, in degrees: the test's own eq. 7.
double AngleDeg(cv::Point2d a, cv::Point2d at, cv::Point2d b) {
  const cv::Point2d u = a - at, v = b - at;
  return std::acos(u.dot(v) / (cv::norm(u) * cv::norm(v))) * 180.0 / CV_PI;
}

TEST(TrackingSession, OneMarkerConfigFileTracksAndHasNoMeasurements) {
  testing::TempDir dir;
  testing::WriteTextFile(dir.file("ball.yaml"),
                         "markers:\n  - name: ball\n    hsv: {h: [100, 130], s: [80, 255], "
                         "v: [40, 255]}\n");
  const TrackingConfig config = LoadTrackingConfig(dir.file("ball.yaml"));
  SceneOptions scene;
  scene.markers = {{"ball", {220, 90, 40}, 0.7}};
  const Clip clip = Render(4, scene);
  TrackingSession session(config);
  for (size_t i = 0; i < clip.frames.size(); ++i) {
    const FrameResult& result = session.process(clip.frames[i]);
    ASSERT_EQ(result.markers.size(), 1u);
    ASSERT_TRUE(result.markers[0].observation.found()) << "frame " << i;
    EXPECT_LT(cv::norm(*result.markers[0].observation.position_px -
                       *clip.truth[i].markers[0].centroid_px),
              0.2);
    EXPECT_FALSE(result.measurement.angle_deg || result.measurement.chord_px ||
                 result.measurement.tip_disp_px);
    EXPECT_TRUE(result.measurement.inner_angle_deg.empty());
  }
}

TEST(TrackingSession, TwoMarkersTrackWithoutATriple) {
  SceneOptions scene;
  scene.markers = {{"red", {40, 40, 220}, 0.2}, {"green", {60, 200, 60}, 0.9}};
  scene.max_bend_deg = 90;
  const Clip clip = Render(4, scene);
  TrackingConfig config;
  config.markers = {ColourMarker("red", {170, 10}), ColourMarker("green", {45, 85})};
  TrackingSession session(config);
  for (size_t i = 0; i < clip.frames.size(); ++i) {
    const FrameResult& result = session.process(clip.frames[i]);
    for (size_t m = 0; m < 2; ++m) {
      ASSERT_TRUE(result.markers[m].observation.found()) << "frame " << i;
      EXPECT_LT(cv::norm(*result.markers[m].observation.position_px -
                         *clip.truth[i].markers[m].centroid_px),
                0.2);
    }
    EXPECT_FALSE(result.measurement.angle_deg.has_value());
  }
}

// The paper's 4-segment actuator has a marker on each of its five hinges and ends.
SceneOptions FiveMarkerChain() {
  SceneOptions scene;
  scene.markers = {{"red", {40, 40, 220}, 0.05},    {"yellow", {40, 210, 220}, 0.3},
                   {"green", {60, 200, 60}, 0.5},   {"blue", {220, 90, 40}, 0.7},
                   {"magenta", {200, 50, 200}, 0.95}};
  scene.max_bend_deg = 200;
  return scene;
}

TrackingConfig FiveMarkerConfig() {
  TrackingConfig config;
  config.markers = {ColourMarker("red", {170, 10}), ColourMarker("yellow", {20, 35}),
                    ColourMarker("green", {45, 85}), ColourMarker("blue", {100, 130}),
                    ColourMarker("magenta", {140, 165})};
  config.measure.base = "red";
  config.measure.middle = "green";
  config.measure.tip = "magenta";
  config.measure.chain = {"red", "yellow", "green", "blue", "magenta"};
  return config;
}

TEST(TrackingSession, FiveMarkerChainMeasuresTheAngleAtEveryInnerMarkerLikeTheTruth) {
  const Clip clip = Render(8, FiveMarkerChain(), /*stretch=*/2);
  TrackingSession session(FiveMarkerConfig());
  for (size_t i = 0; i < clip.frames.size(); ++i) {
    const FrameResult& result = session.process(clip.frames[i]);
    const std::vector<MarkerTruth>& truth = clip.truth[i].markers;
    ASSERT_EQ(result.measurement.inner_angle_deg.size(), 3u);
    for (size_t k = 0; k < 3; ++k) {
      const double expected =
          AngleDeg(*truth[k].centroid_px, *truth[k + 1].centroid_px, *truth[k + 2].centroid_px);
      ASSERT_TRUE(result.measurement.inner_angle_deg[k].has_value()) << "frame " << i;
      EXPECT_NEAR(*result.measurement.inner_angle_deg[k], expected, 0.5)
          << "frame " << i << ", inner marker " << k;
    }
    ASSERT_TRUE(result.measurement.angle_deg.has_value());
    EXPECT_NEAR(*result.measurement.angle_deg, *clip.truth[i].measurement.angle_deg, 0.3);
  }
  // The profile bends: the last frame's angles are well away from straight.
  EXPECT_LT(*session.process(clip.frames.back()).measurement.inner_angle_deg[1], 170.0);
}

TEST(TrackingSession, ConfigErrorsOfTheTripleAndChainNameTheFileAndKey) {
  testing::TempDir dir;
  const std::string markers =
      "markers:\n  - name: a\n  - name: b\n  - name: c\n";
  auto error_of = [&](const std::string& text) {
    testing::WriteTextFile(dir.file("m.yaml"), markers + text);
    try {
      TrackingSession session(LoadTrackingConfig(dir.file("m.yaml")));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of(""), "");
  EXPECT_EQ(error_of("chain: [a, b, c]\n"), "");
  for (const char* bad : {"triple: [a, b]\n", "triple: [a, b, a]\n",
                                 "chain: [a, b, a]\n", "chain: [a, b]\n", "chain: [a, b, x]\n"}) {
    const std::string error = error_of(bad);
    const std::string key = std::string(bad).substr(0, std::string(bad).find(':'));
    EXPECT_THAT(error, ::testing::HasSubstr(dir.file("m.yaml"))) << bad;
    EXPECT_THAT(error, ::testing::HasSubstr(key)) << bad;
  }
}

}  // namespace
}  // namespace softsight
