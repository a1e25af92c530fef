// The live window's logic, driven through the same event interface the highgui adapter uses, on
// rendered scenes with exact truth.
#include "softsight/gui/live_controller.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/videoio.hpp>

#include "softsight/core/error.h"
#include "softsight/io/config.h"
#include "softsight/io/plot.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;
using Type = UiEvent::Type;

MarkerSpec ColourMarker(const std::string& name, HsvRange h) {
  MarkerSpec spec;
  spec.name = name;
  spec.method = "colour";
  spec.colour.h = h;
  spec.colour.s = {80, 255};
  spec.colour.v = {40, 255};
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

class LiveControllerTest : public ::testing::Test {
 protected:
  LiveControllerTest() {
    SceneOptions scene;
    scene.size = cv::Size(320, 240);
    scene.length_px = 160;
    scene.width_px = 24;
    scene.marker_radius_px = 8;
    scene.frame_count = 60;
    scene.max_bend_deg = 120;
    scene_ = std::make_unique<SyntheticScene>(scene);
    dir_ = fs::temp_directory_path() /
           ("softsight_live_test_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~LiveControllerTest() override { fs::remove_all(dir_); }

  // Renders frame `index`, feeds it to the controller and returns its truth.
  SceneTruth Feed(LiveController& live, int index) {
    Frame frame;
    SceneTruth truth = scene_->render(index, frame.image);
    frame.index = index;
    frame.time_s = truth.time_s;
    live.on_frame(frame, SteadyClock::now());
    return truth;
  }

  static void Click(LiveController& live, cv::Point2d p) {
    live.on_event(UiEvent::Mouse(Type::kMouseDown, p.x, p.y));
    live.on_event(UiEvent::Mouse(Type::kMouseUp, p.x + 1, p.y));  // Within the click slop.
  }
  static void Drag(LiveController& live, cv::Point2d from, cv::Point2d to) {
    live.on_event(UiEvent::Mouse(Type::kMouseDown, from.x, from.y));
    live.on_event(UiEvent::Mouse(Type::kMouseMove, (from.x + to.x) / 2, (from.y + to.y) / 2));
    live.on_event(UiEvent::Mouse(Type::kMouseUp, to.x, to.y));
  }

  LiveOptions Options() const {
    LiveOptions options;
    options.record_prefix = (dir_ / "rec").string();
    options.save_config_path = (dir_ / "saved.yaml").string();
    return options;
  }

  static void ExpectAt(const LiveController& live, int marker, const SceneTruth& truth,
                       double tolerance_px) {
    ASSERT_TRUE(live.last_result());
    const auto& observed = live.last_result()->markers[marker].observation;
    const auto& expected = truth.markers[marker].centroid_px;
    ASSERT_TRUE(expected);
    ASSERT_TRUE(observed.found()) << truth.markers[marker].name << " not found";
    EXPECT_NEAR(observed.position_px->x, expected->x, tolerance_px) << truth.markers[marker].name;
    EXPECT_NEAR(observed.position_px->y, expected->y, tolerance_px) << truth.markers[marker].name;
  }

  std::unique_ptr<SyntheticScene> scene_;
  fs::path dir_;
};

TEST_F(LiveControllerTest, TracksAndShowsTheOverlayAboveTheStripChart) {
  LiveController live(SceneConfig(), Options());
  SceneTruth truth;
  for (int i = 0; i < 5; ++i) truth = Feed(live, i);
  for (int m = 0; m < 3; ++m) ExpectAt(live, m, truth, 0.3);
  const cv::Mat& canvas = live.canvas();
  EXPECT_EQ(canvas.size(), cv::Size(320, 240 + StripChartOptions{}.height_px));
  for (const MarkerTruth& marker : truth.markers) {
    // The overlay's ring around each marker, in canvas coordinates (= image coordinates).
    int ring = 0;
    for (int deg = 0; deg < 360; deg += 15) {
      const cv::Point p(cvRound(marker.centroid_px->x + 12 * std::cos(deg * CV_PI / 180)),
                        cvRound(marker.centroid_px->y + 12 * std::sin(deg * CV_PI / 180)));
      bool yellow = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const cv::Vec3b px = canvas.at<cv::Vec3b>(p + cv::Point(dx, dy));
          yellow |= px[0] < 80 && px[1] > 200 && px[2] > 200;
        }
      }
      ring += yellow;
    }
    EXPECT_GE(ring, 20) << marker.name;
  }
  ASSERT_TRUE(live.latency_ms());
  EXPECT_GE(*live.latency_ms(), 0.0);
  EXPECT_TRUE(live.fps());
}

TEST_F(LiveControllerTest, ClickCalibratesTheActiveMarkersColour) {
  TrackingConfig config = SceneConfig();
  config.markers[1].colour.h = {140, 160};  // Wrong: nothing in the scene has this hue.
  LiveController live(config, Options());
  SceneTruth truth = Feed(live, 0);
  ASSERT_FALSE(live.last_result()->markers[1].observation.found());

  live.on_event(UiEvent::Key('2'));
  EXPECT_EQ(live.active_marker(), 1);
  const int revision = live.hsv_revision();
  Click(live, *truth.markers[1].centroid_px);
  const HsvRange h = live.config().markers[1].colour.h;
  EXPECT_LT(h.lo, h.hi);
  EXPECT_LE(h.lo, 105);  // The blue marker's hue is about 107.
  EXPECT_GE(h.hi, 109);
  EXPECT_NE(live.hsv_revision(), revision);  // The adapter will move the trackbars.
  EXPECT_NE(live.message().find("blue: h "), std::string::npos) << live.message();
  EXPECT_EQ(live.active_hsv()[0], h.lo);

  truth = Feed(live, 1);
  ExpectAt(live, 1, truth, 0.3);

  // Saving writes what the click did; loading it gives the same ranges.
  live.on_event(UiEvent::Key('s'));
  const TrackingConfig saved = LoadTrackingConfig((dir_ / "saved.yaml").string());
  EXPECT_EQ(saved.markers[1].colour.h.lo, h.lo);
  EXPECT_EQ(saved.markers[1].colour.h.hi, h.hi);
  EXPECT_EQ(saved.markers[1].colour.s.lo, live.config().markers[1].colour.s.lo);
}

TEST_F(LiveControllerTest, ClickOnAFoundMarkerPicksThatMarker) {
  LiveController live(SceneConfig(), Options());
  const SceneTruth truth = Feed(live, 0);
  Click(live, *truth.markers[2].centroid_px);  // Green, while red is active.
  EXPECT_EQ(live.active_marker(), 2);
  const HsvRange h = live.config().markers[2].colour.h;
  EXPECT_LE(h.lo, 60);
  EXPECT_GE(h.hi, 60);
  // A click on the grey background changes nothing and says why.
  const HsvRange before = live.config().markers[2].colour.h;
  Click(live, {5, 5});
  EXPECT_NE(live.message().find("not a coloured marker"), std::string::npos) << live.message();
  EXPECT_EQ(live.config().markers[2].colour.h.lo, before.lo);
}

TEST_F(LiveControllerTest, DragSelectsATemplateForTheMarkerInTheBox) {
  TrackingConfig config = SceneConfig();
  for (MarkerSpec& spec : config.markers) spec.method = "zncc";  // No templates yet.
  LiveController live(config, Options());
  SceneTruth truth = Feed(live, 0);
  for (int m = 0; m < 3; ++m) EXPECT_FALSE(live.last_result()->markers[m].observation.found());

  // Nothing tracked yet: the box goes to the active marker (red).
  const cv::Point2d red = *truth.markers[0].centroid_px;
  Drag(live, red - cv::Point2d(14, 14), red + cv::Point2d(14, 14));
  EXPECT_NE(live.message().find("red: reselected"), std::string::npos) << live.message();
  ASSERT_TRUE(live.config().markers[0].templ.rect);
  EXPECT_EQ(live.config().markers[0].templ.rect->width, 28);
  live.on_event(UiEvent::Key('3'));
  const cv::Point2d green = *truth.markers[2].centroid_px;
  Drag(live, green + cv::Point2d(14, 14), green - cv::Point2d(14, 14));  // Any direction.
  for (int i = 1; i <= 3; ++i) truth = Feed(live, i);
  ExpectAt(live, 0, truth, 0.5);
  ExpectAt(live, 2, truth, 0.5);
  EXPECT_FALSE(live.last_result()->markers[1].observation.found());

  // Now red is tracked: a box around it reselects red even though green is active.
  const cv::Point2d red_now = *truth.markers[0].centroid_px;
  Drag(live, red_now - cv::Point2d(12, 12), red_now + cv::Point2d(12, 12));
  EXPECT_EQ(live.active_marker(), 0);
}

TEST_F(LiveControllerTest, KeysPauseHelpSelectAndQuit) {
  LiveController live(SceneConfig(), Options());
  Feed(live, 0);
  live.on_event(UiEvent::Key(' '));
  EXPECT_TRUE(live.paused());
  Feed(live, 1);  // Ignored while paused.
  EXPECT_EQ(live.last_result()->frame_index, 0);
  live.on_event(UiEvent::Key(' '));
  Feed(live, 2);
  EXPECT_EQ(live.last_result()->frame_index, 2);

  const cv::Mat without_help = live.canvas().clone();
  live.on_event(UiEvent::Key('h'));
  EXPECT_TRUE(live.help_shown());
  EXPECT_GT(cv::norm(live.canvas(), without_help, cv::NORM_L1), 0);  // The help is drawn.

  live.on_event(UiEvent::Key('9'));
  EXPECT_EQ(live.active_marker(), 0);
  EXPECT_NE(live.message().find("no marker 9"), std::string::npos);

  // Trackbars edit the active marker's ranges; moving one to its current value is a no-op.
  live.on_event(UiEvent::Key('3'));
  const int revision = live.hsv_revision();
  live.on_event(UiEvent::Trackbar(0, 45));  // H lo of green: unchanged.
  EXPECT_EQ(live.hsv_revision(), revision);
  live.on_event(UiEvent::Trackbar(5, 200));  // V hi.
  EXPECT_EQ(live.config().markers[2].colour.v.hi, 200);
  EXPECT_EQ(live.active_hsv()[5], 200);

  EXPECT_FALSE(live.quit_requested());
  live.on_event(UiEvent::Key('q'));
  EXPECT_TRUE(live.quit_requested());
}

TEST_F(LiveControllerTest, ResetBendingReferenceZeroesTheTipDisplacement) {
  LiveController live(SceneConfig(), Options());
  for (int i = 0; i < 20; ++i) Feed(live, i);
  ASSERT_TRUE(live.last_result()->measurement.tip_disp_px);
  EXPECT_GT(*live.last_result()->measurement.tip_disp_px, 5.0);
  live.on_event(UiEvent::Key('b'));
  Feed(live, 20);
  ASSERT_TRUE(live.last_result()->measurement.tip_disp_px);
  EXPECT_EQ(*live.last_result()->measurement.tip_disp_px, 0.0);
  Feed(live, 24);
  EXPECT_GT(*live.last_result()->measurement.tip_disp_px, 1.0);
}

TEST_F(LiveControllerTest, SwitchingMethodKeepsTrackingWithTemplatesCutWhereMarkersAre) {
  LiveController live(SceneConfig(), Options());
  SceneTruth truth;
  for (int i = 0; i < 3; ++i) truth = Feed(live, i);
  live.on_event(UiEvent::Key('m'));
  const std::string method = live.config().markers[0].method;
  EXPECT_NE(method, "colour");
  for (const MarkerSpec& spec : live.config().markers) EXPECT_EQ(spec.method, method);
  EXPECT_NE(live.message().find("method: " + method), std::string::npos);
  for (int i = 3; i < 8; ++i) truth = Feed(live, i);
  // The template trackers' own accuracy on a bending body (their templates include the band
  // behind the marker) is the template tests' business; here: every marker is still followed.
  for (int m = 0; m < 3; ++m) ExpectAt(live, m, truth, 1.5);
}

TEST_F(LiveControllerTest, RecordingIsReproducedByTrackingTheRawVideoWithItsConfig) {
  LiveController live(SceneConfig(), Options());
  for (int i = 0; i < 3; ++i) Feed(live, i);
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  for (int i = 3; i < 9; ++i) Feed(live, i);
  live.on_event(UiEvent::Key('r'));
  EXPECT_FALSE(live.recording());
  const std::string prefix = (dir_ / "rec-001").string();
  EXPECT_EQ(live.last_recording(), prefix);
  for (const char* ext : {".csv", ".avi", ".raw.avi", ".yaml"}) {
    EXPECT_TRUE(fs::exists(prefix + ext)) << ext;
  }

  // 7 rows: the frame on screen when recording started (2), then frames 3..8, numbered from 0.
  const CsvTable table = ReadCsvTable(prefix + ".csv");
  ASSERT_EQ(table.row_count(), 7u);
  EXPECT_EQ(*table.values[*table.find("frame")][0], 0);
  EXPECT_EQ(*table.values[*table.find("frame")][6], 6);
  EXPECT_EQ(*table.values[*table.find("tip_disp_px")][0], 0.0);  // Reference restarts.

  // `softsight track` on the raw video with the saved config gives the same rows.
  const TrackingConfig config = LoadTrackingConfig(prefix + ".yaml");
  TrackingSession session(config);
  cv::VideoCapture raw(prefix + ".raw.avi");
  ASSERT_TRUE(raw.isOpened());
  Frame frame;
  for (size_t row = 0; row < 7; ++row) {
    ASSERT_TRUE(raw.read(frame.image)) << row;
    frame.index = static_cast<int64_t>(row);
    const FrameResult& result = session.process(frame);
    for (const MarkerObservation& m : result.markers) {
      ASSERT_TRUE(m.observation.found()) << m.name << " row " << row;
      EXPECT_NEAR(m.observation.position_px->x, *table.values[*table.find(m.name + "_x")][row],
                  1e-3);
      EXPECT_NEAR(m.observation.position_px->y, *table.values[*table.find(m.name + "_y")][row],
                  1e-3);
    }
    EXPECT_NEAR(*result.measurement.angle_deg, *table.values[*table.find("angle_deg")][row], 1e-3);
  }
  EXPECT_FALSE(raw.read(frame.image));
  // A second recording gets the next number.
  live.on_event(UiEvent::Key('r'));
  live.on_event(UiEvent::Key('r'));
  EXPECT_EQ(live.last_recording(), (dir_ / "rec-002").string());
}

TEST_F(LiveControllerTest, BadOptionsOrConfigAreInputErrors) {
  LiveOptions options = Options();
  options.select_box_px = 1;
  EXPECT_THROW(LiveController(SceneConfig(), options), InputError);
  TrackingConfig empty;
  EXPECT_THROW(LiveController(empty, Options()), InputError);
}

}  // namespace
}  // namespace softsight
