// The live window's logic, driven through the same event interface the highgui adapter uses, on
// rendered scenes with exact truth.
#include "gui/live_controller.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/test_util.h"
#include "gui/live_feed.h"
#include "gui/live_layout.h"
#include "gui/live_pointer.h"
#include "gui/live_test_util.h"
#include "gui/range_edit.h"
#include "gui/seekable_source.h"
#include "io/paced_source.h"
#include "softsight/core/error.h"
#include "softsight/io/csv_columns.h"
#include "softsight/io/frame_writer.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sinks.h"
#include <fstream>
#include "softsight/config/config.h"
#include "softsight/io/plot.h"
#include "softsight/sim/scene.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;
using Type = UiEvent::Type;

using testing::CsvRowsWithoutTiming;
using testing::RingPoints;

TrackingConfig SceneConfig() { return testing::LiveTestConfig(); }

class LiveControllerTest : public ::testing::Test {
 protected:
  LiveControllerTest() {
    scene_ = std::make_unique<SyntheticScene>(testing::LiveTestScene(60, 120));
  }

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

  // Feeds frames 0..3, switching every marker to SAD after frame 2, and clicks blue on frame 3:
  // the ranges picked, kept for blue's colour method.
  std::array<int, 6> PickBlueWhileMatchingSad(LiveController& live) {
    for (int i = 0; i < 3; ++i) Feed(live, i);
    live.on_event(UiEvent::Key('m'));  // colour -> sad
    const SceneTruth truth = Feed(live, 3);
    live.on_event(UiEvent::Key('2'));
    Click(live, *truth.markers[1].centroid_px);
    return live.active_hsv();
  }
  static std::array<int, 6> RangesOf(const ColourParams& c) {
    return {c.h.lo, c.h.hi, c.s.lo, c.s.hi, c.v.lo, c.v.hi};
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
  const testing::TempDir temp_;
  const fs::path dir_ = temp_.path();
};

TEST_F(LiveControllerTest, TracksAndShowsTheOverlayAboveTheStripChart) {
  LiveController live(SceneConfig(), Options());
  SceneTruth truth;
  for (int i = 0; i < 5; ++i) truth = Feed(live, i);
  for (int m = 0; m < 3; ++m) ExpectAt(live, m, truth, 0.3);
  const cv::Mat& canvas = live.canvas();
  EXPECT_EQ(canvas.size(), cv::Size(320, 240 + StatusBandHeight() + StripChartOptions{}.height_px));
  for (const MarkerTruth& marker : truth.markers) {
    // The overlay's ring around each marker, in canvas coordinates (= image coordinates).
    EXPECT_GE(RingPoints(canvas, *marker.centroid_px), 20) << marker.name;
  }
  ASSERT_TRUE(live.latency_ms());
  EXPECT_GE(*live.latency_ms(), 0.0);
  EXPECT_TRUE(live.fps());
}

TEST_F(LiveControllerTest, ClickCalibratesTheActiveMarkersColour) {
  TrackingConfig config = SceneConfig();
  config.markers[1].params.get<ColourParams>().h = {140, 160};  // Wrong: nothing in the scene has this hue.
  LiveController live(config, Options());
  SceneTruth truth = Feed(live, 0);
  ASSERT_FALSE(live.last_result()->markers[1].observation.found());

  live.on_event(UiEvent::Key('2'));
  EXPECT_EQ(live.active_marker(), 1);
  const int revision = live.hsv_revision();
  Click(live, *truth.markers[1].centroid_px);
  const HsvRange h = live.config().markers[1].params.get<ColourParams>().h;
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
  EXPECT_EQ(saved.markers[1].params.get<ColourParams>().h.lo, h.lo);
  EXPECT_EQ(saved.markers[1].params.get<ColourParams>().h.hi, h.hi);
  EXPECT_EQ(saved.markers[1].params.get<ColourParams>().s.lo, live.config().markers[1].params.get<ColourParams>().s.lo);
}

TEST_F(LiveControllerTest, ClickOnAFoundMarkerPicksThatMarker) {
  LiveController live(SceneConfig(), Options());
  const SceneTruth truth = Feed(live, 0);
  Click(live, *truth.markers[2].centroid_px);  // Green, while red is active.
  EXPECT_EQ(live.active_marker(), 2);
  const HsvRange h = live.config().markers[2].params.get<ColourParams>().h;
  EXPECT_LE(h.lo, 60);
  EXPECT_GE(h.hi, 60);
  // A click on the grey background changes nothing and says why.
  const HsvRange before = live.config().markers[2].params.get<ColourParams>().h;
  Click(live, {5, 5});
  EXPECT_NE(live.message().find("not a coloured marker"), std::string::npos) << live.message();
  EXPECT_EQ(live.config().markers[2].params.get<ColourParams>().h.lo, before.lo);
}

// The calls a front end in image pixels makes (the web page, src/web): the edits of the mouse.
TEST_F(LiveControllerTest, ImagePixelCallsEditAsTheMouseAndTheTimelineDo) {
  TrackingConfig config = SceneConfig();
  config.markers[1].params.get<ColourParams>().h = {140, 160};  // Wrong: blue is not found.
  LiveController by_mouse(config, Options());
  LiveController by_call(config, Options());
  const SceneTruth first = Feed(by_mouse, 0);
  Feed(by_call, 0);
  for (LiveController* live : {&by_mouse, &by_call}) live->on_event(UiEvent::Key('2'));
  Click(by_mouse, *first.markers[1].centroid_px);
  by_call.pick_colour_at(*first.markers[1].centroid_px);
  EXPECT_EQ(RangesOf(by_call.config().markers[1].params.get<ColourParams>()),
            RangesOf(by_mouse.config().markers[1].params.get<ColourParams>()));
  EXPECT_NE(by_call.config().markers[1].params.get<ColourParams>().h.lo, 140);
  Feed(by_mouse, 1);
  const SceneTruth second = Feed(by_call, 1);
  ExpectAt(by_call, 1, second, 0.3);

  // A box around green reselects green (the marker in it), one more edit to undo.
  const cv::Point2d green = *second.markers[2].centroid_px;
  by_call.reselect(cv::Rect(cvRound(green.x) - 12, cvRound(green.y) - 12, 24, 24));
  EXPECT_EQ(by_call.active_marker(), 2);
  EXPECT_EQ(by_call.undo_depth(), 2u);
  ExpectAt(by_call, 2, second, 0.3);

  // The speed closest to the one asked for among the keys' steps.
  by_call.set_speed(0.3);
  EXPECT_DOUBLE_EQ(by_call.speed(), 0.25);
  by_call.set_speed(100);
  EXPECT_DOUBLE_EQ(by_call.speed(), 4.0);
  // A seek is queued as a timeline click's, for the feed to carry out.
  by_call.seek_to(7);
  const std::optional<PlaybackRequest> request = by_call.take_playback_request();
  ASSERT_TRUE(request);
  EXPECT_EQ(request->kind, PlaybackRequest::Kind::kSeekTo);
  EXPECT_EQ(request->position, 7);
  // Saved where the caller says, as `s` saves.
  by_call.save_config_to((dir_ / "web.yaml").string());
  const TrackingConfig saved = LoadTrackingConfig((dir_ / "web.yaml").string());
  EXPECT_EQ(RangesOf(saved.markers[1].params.get<ColourParams>()),
            RangesOf(by_call.config().markers[1].params.get<ColourParams>()));
}

TEST_F(LiveControllerTest, DragSelectsATemplateForTheMarkerInTheBox) {
  TrackingConfig config = SceneConfig();
  for (MarkerSpec& spec : config.markers) spec.params = ParamsForMethod("zncc", {});  // No templates yet.
  LiveController live(config, Options());
  SceneTruth truth = Feed(live, 0);
  for (int m = 0; m < 3; ++m) EXPECT_FALSE(live.last_result()->markers[m].observation.found());

  // Nothing tracked yet: the box goes to the active marker (red).
  const cv::Point2d red = *truth.markers[0].centroid_px;
  Drag(live, red - cv::Point2d(14, 14), red + cv::Point2d(14, 14));
  EXPECT_NE(live.message().find("red: reselected"), std::string::npos) << live.message();
  ASSERT_TRUE(live.config().markers[0].params.get<TemplateParams>().rect);
  EXPECT_EQ(live.config().markers[0].params.get<TemplateParams>().rect->width, 28);
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
  // The help is a panel beside the image and chart: the image (and every marker on it) stays
  // as it was, the panel holds text.
  const cv::Mat& with_help = live.canvas();
  ASSERT_EQ(with_help.rows, without_help.rows);
  ASSERT_GT(with_help.cols, without_help.cols + 150);
  EXPECT_EQ(cv::norm(with_help(cv::Rect(0, 0, 320, 240)), without_help(cv::Rect(0, 0, 320, 240)),
                     cv::NORM_L1),
            0);
  cv::Mat panel_gray;
  cv::cvtColor(with_help(cv::Rect(without_help.cols, 0, with_help.cols - without_help.cols,
                                  with_help.rows)),
               panel_gray, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::countNonZero(panel_gray > 200), 300);  // The key list's text.

  live.on_event(UiEvent::Key('9'));
  EXPECT_EQ(live.active_marker(), 0);
  EXPECT_NE(live.message().find("no marker 9"), std::string::npos);

  // Trackbars edit the active marker's ranges; moving one to its current value is a no-op.
  live.on_event(UiEvent::Key('3'));
  const int revision = live.hsv_revision();
  live.on_event(UiEvent::Trackbar(0, 45));  // H lo of green: unchanged.
  EXPECT_EQ(live.hsv_revision(), revision);
  live.on_event(UiEvent::Trackbar(5, 200));  // V hi.
  EXPECT_EQ(live.config().markers[2].params.get<ColourParams>().v.hi, 200);
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
  const std::string method = TrackerMethodName(live.config().markers[0].params);
  EXPECT_NE(method, "colour");
  for (const MarkerSpec& spec : live.config().markers) EXPECT_EQ(TrackerMethodName(spec.params), method);
  EXPECT_NE(live.message().find("method: " + method), std::string::npos);
  for (int i = 3; i < 8; ++i) truth = Feed(live, i);
  // The template trackers' own accuracy on a bending body (their templates include the band
  // behind the marker) is the template tests' business; here: every marker is still followed.
  for (int m = 0; m < 3; ++m) ExpectAt(live, m, truth, 1.5);
}

// A marker is one method's parameters; the live window keeps the other method's aside, so a
// colour pick made while a template is matched waits for the colour method, and switching through
// every method comes back to it.
TEST_F(LiveControllerTest, SwitchingBackToColourRestoresTheRangesPickedWhileMatchingTemplates) {
  LiveController live(SceneConfig(), Options());
  const std::array<int, 6> picked = PickBlueWhileMatchingSad(live);
  EXPECT_EQ(TrackerMethodName(live.config().markers[1].params), "sad") << "the template stays";
  EXPECT_NE(live.message().find("(used by the colour method)"), std::string::npos)
      << live.message();
  EXPECT_NE(picked, (std::array<int, 6>{95, 125, 80, 255, 40, 255})) << "the pick's own ranges";
  for (int k = 0; k < 3; ++k) live.on_event(UiEvent::Key('m'));  // ssd, zncc, colour
  ASSERT_EQ(TrackerMethodName(live.config().markers[1].params), "colour");
  EXPECT_EQ(RangesOf(live.config().markers[1].params.get<ColourParams>()), picked);
  const ColourParams& red = live.config().markers[0].params.get<ColourParams>();
  EXPECT_EQ(red.h.lo, 170);  // Not picked: the config's ranges.
  EXPECT_EQ(red.h.hi, 10);
  SceneTruth truth;
  for (int i = 4; i < 8; ++i) truth = Feed(live, i);
  for (int m = 0; m < 3; ++m) ExpectAt(live, m, truth, 0.5);
}

// `s` saves the colour ranges picked while a marker matched templates beside its template keys;
// a window started from the saved file finds them again when it switches back to colour.
TEST_F(LiveControllerTest, RangesPickedWhileMatchingTemplatesAreSavedAndComeBackFromTheFile) {
  std::array<int, 6> picked{};
  {
    LiveController live(SceneConfig(), Options());
    picked = PickBlueWhileMatchingSad(live);
    ASSERT_NE(picked, (std::array<int, 6>{95, 125, 80, 255, 40, 255})) << "the pick's own ranges";
    live.on_event(UiEvent::Key('s'));
  }
  const TrackingConfig saved = LoadTrackingConfig((dir_ / "saved.yaml").string());
  ASSERT_EQ(TrackerMethodName(saved.markers[1].params), "sad");
  ASSERT_EQ(saved.params_aside.count("blue"), 1u);
  ASSERT_EQ(saved.params_aside.at("blue").size(), 1u);
  EXPECT_EQ(RangesOf(saved.params_aside.at("blue")[0].get<ColourParams>()), picked);
  // The same file with --method colour tracks blue with the picked ranges.
  const TrackingConfig as_colour = LoadTrackingConfig((dir_ / "saved.yaml").string(), "colour");
  EXPECT_EQ(as_colour.markers[1].params.get<ColourParams>().h.lo, picked[0]);

  LiveController again(saved, Options());
  SceneTruth truth;
  for (int i = 4; i < 6; ++i) truth = Feed(again, i);
  again.on_event(UiEvent::Key('2'));
  EXPECT_EQ(again.active_hsv(), picked) << "the trackbars show the saved colour ranges";
  for (int k = 0; k < 3; ++k) again.on_event(UiEvent::Key('m'));  // ssd, zncc, colour
  ASSERT_EQ(TrackerMethodName(again.config().markers[1].params), "colour");
  EXPECT_EQ(RangesOf(again.config().markers[1].params.get<ColourParams>()), picked);
  for (int i = 6; i < 9; ++i) truth = Feed(again, i);
  ExpectAt(again, 1, truth, 0.5);
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

  // 7 rows: the frame on screen when recording started (2), then frames 3..8, numbered as the
  // source numbers them.
  const CsvTable table = ReadCsvTable(prefix + ".csv");
  ASSERT_EQ(table.row_count(), 7u);
  EXPECT_EQ(*table.values[*table.find("frame")][0], 2);
  EXPECT_EQ(*table.values[*table.find("frame")][6], 8);
  ASSERT_TRUE(LoadTrackingConfig(prefix + ".yaml").recording);
  EXPECT_EQ(LoadTrackingConfig(prefix + ".yaml").recording->first_frame, 2);
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

// The session tells the running recording of each edit; one it cannot keep (its config cannot be
// written) stops the recording, keeps what it wrote, and says why; the window runs on.
TEST_F(LiveControllerTest, AnEditTheRecordingCannotKeepStopsItKeepsItsRowsAndSaysWhy) {
  LiveController live(SceneConfig(), Options());
  for (int i = 0; i < 3; ++i) Feed(live, i);
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  for (int i = 3; i < 6; ++i) Feed(live, i);
  const std::string prefix = (dir_ / "rec-001").string();
  // The config can no longer be written: a folder stands where the file was.
  fs::remove(prefix + ".yaml");
  fs::create_directory(prefix + ".yaml");
  live.on_event(UiEvent::Key('b'));  // An edit: the bending reference restarts.
  EXPECT_FALSE(live.recording());
  EXPECT_THAT(live.message(), ::testing::StartsWith("recorded 4 frames to " + prefix + ".*; "));
  EXPECT_THAT(live.message(), ::testing::HasSubstr(prefix + ".yaml"));
  EXPECT_EQ(live.last_recording(), prefix);
  EXPECT_EQ(ReadCsvTable(prefix + ".csv").row_count(), 4u);
  Feed(live, 6);
  EXPECT_TRUE(live.last_result()->markers[0].observation.found());
  EXPECT_EQ(live.run_summary().recorded_frames, 4);
}

// Scale mode takes the point where the button is released; press and release at one spot.
void ScaleClick(LiveController& live, cv::Point2d p) {
  live.on_event(UiEvent::Mouse(Type::kMouseDown, p.x, p.y));
  live.on_event(UiEvent::Mouse(Type::kMouseUp, p.x, p.y));
}

TEST_F(LiveControllerTest, TwoClickedPointsSetTheMillimetreScaleThatSavingAndRecordingKeep) {
  LiveOptions options = Options();
  options.scale_distance_mm = 50;
  LiveController live(SceneConfig(), options);
  for (int i = 0; i < 3; ++i) Feed(live, i);
  EXPECT_FALSE(live.last_result()->measurement.chord_mm.has_value());

  live.on_event(UiEvent::Key('c'));
  EXPECT_TRUE(live.scale_mode());
  EXPECT_NE(live.message().find("click point 1 of 2, 50 mm apart"), std::string::npos)
      << live.message();
  ScaleClick(live, {100, 120});
  EXPECT_NE(live.message().find("click point 2, 50 mm from point 1"), std::string::npos) << live.message();
  // While picking, a cyan line follows the pointer from the first point.
  live.on_event(UiEvent::Mouse(Type::kMouseMove, 200, 120));
  const cv::Vec3b on_line = live.canvas().at<cv::Vec3b>(120, 150);
  EXPECT_TRUE(on_line[0] > 200 && on_line[1] > 200 && on_line[2] < 80) << on_line;
  ScaleClick(live, {200, 120});  // 100 px from the first: 0.5 mm/px.
  EXPECT_FALSE(live.scale_mode());
  EXPECT_NE(live.message().find("scale 0.5000 mm/px"), std::string::npos) << live.message();
  EXPECT_EQ(live.config().measure.metric.scale_mm_per_px, 0.5);

  // Applied at once (the frame on screen is measured again) and to every following frame.
  ASSERT_TRUE(live.last_result()->measurement.chord_mm.has_value());
  EXPECT_EQ(live.last_result()->frame_index, 2);
  for (int i = 3; i < 5; ++i) {
    Feed(live, i);
    const Measurement& m = live.last_result()->measurement;
    ASSERT_TRUE(m.chord_px && m.chord_mm && m.arc_length_mm);
    EXPECT_DOUBLE_EQ(*m.chord_mm, 0.5 * *m.chord_px);
    EXPECT_DOUBLE_EQ(*m.arc_length_mm, 0.5 * *m.arc_length_px);
  }
  const double live_chord_mm = *live.last_result()->measurement.chord_mm;

  // `s` writes the points; the saved config loads to the same scale, and a batch session with
  // it measures the same millimetres.
  live.on_event(UiEvent::Key('s'));
  const std::string saved_path = (dir_ / "saved.yaml").string();
  const TrackingConfig saved = LoadTrackingConfig(saved_path);
  ASSERT_TRUE(saved.measure.metric.scale_points.has_value());
  EXPECT_EQ(saved.measure.metric.scale_points->a_px, cv::Point2d(100, 120));
  EXPECT_EQ(saved.measure.metric.scale_points->b_px, cv::Point2d(200, 120));
  EXPECT_EQ(saved.measure.metric.scale_mm_per_px, 0.5);
  TrackingSession batch(saved);
  for (int i = 0; i < 5; ++i) {
    Frame frame;
    scene_->render(i, frame.image);
    frame.index = i;
    const FrameResult& result = batch.process(frame);
    if (i == 4) {
      ASSERT_TRUE(result.measurement.chord_mm.has_value());
      EXPECT_NEAR(*result.measurement.chord_mm, live_chord_mm, 1e-9);
    }
  }

  // A recording started afterwards has the _mm columns.
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  // Changing the scale mid-recording would change the CSV's meaning: refused.
  live.on_event(UiEvent::Key('c'));
  EXPECT_FALSE(live.scale_mode());
  EXPECT_NE(live.message().find("stop the recording first"), std::string::npos);
  Feed(live, 5);
  live.on_event(UiEvent::Key('r'));
  const CsvTable table = ReadCsvTable(live.last_recording() + ".csv");
  ASSERT_EQ(table.row_count(), 2u);
  ASSERT_TRUE(table.find("chord_mm"));
  for (size_t row = 0; row < 2; ++row) {
    EXPECT_NEAR(*table.values[*table.find("chord_mm")][row],
                0.5 * *table.values[*table.find("chord_px")][row], 1e-3);
  }
}

// The page's two points and typed distance (serve): the same scale as the window's two clicks,
// no --scale-distance-mm needed; too close or while recording refused, nothing changed.
TEST_F(LiveControllerTest, AScaleFromTwoGivenPointsIsTheScaleOfTwoClicks) {
  LiveController live(SceneConfig(), Options());
  for (int i = 0; i < 3; ++i) Feed(live, i);
  live.set_scale_from_points({100, 120}, {105, 120}, 50);  // 5 px apart.
  EXPECT_NE(live.message().find("too close"), std::string::npos) << live.message();
  EXPECT_EQ(live.message().find("click the first point"), std::string::npos) << live.message();
  EXPECT_TRUE(live.config().measure.metric.empty());

  live.set_scale_from_points({100, 120}, {200, 120}, 50);  // 100 px: 0.5 mm/px.
  EXPECT_NE(live.message().find("scale 0.5000 mm/px (50 mm over 100.0 px)"), std::string::npos)
      << live.message();
  EXPECT_EQ(live.config().measure.metric.scale_mm_per_px, 0.5);
  ASSERT_TRUE(live.config().measure.metric.scale_points.has_value());
  EXPECT_EQ(live.config().measure.metric.scale_points->b_px, cv::Point2d(200, 120));
  // The frame on screen measured again, in mm.
  ASSERT_TRUE(live.last_result()->measurement.chord_mm.has_value());
  EXPECT_DOUBLE_EQ(*live.last_result()->measurement.chord_mm, 0.5 * *live.last_result()->measurement.chord_px);

  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  live.set_scale_from_points({100, 120}, {300, 120}, 50);
  EXPECT_NE(live.message().find("stop the recording first"), std::string::npos);
  EXPECT_EQ(live.config().measure.metric.scale_mm_per_px, 0.5);
  live.on_event(UiEvent::Key('r'));
}

TEST_F(LiveControllerTest, ScaleModeEscCancelsTooCloseRetriesAndNoDistanceOnlyHints) {
  {
    LiveController live(SceneConfig(), Options());  // No --scale-distance-mm.
    Feed(live, 0);
    live.on_event(UiEvent::Key('c'));
    EXPECT_FALSE(live.scale_mode());
    EXPECT_NE(live.message().find("--scale-distance-mm"), std::string::npos) << live.message();
    Click(live, {5, 5});  // An ordinary click: a colour pick on the background, refused.
    EXPECT_NE(live.message().find("not a coloured marker"), std::string::npos) << live.message();
    Feed(live, 1);
    EXPECT_TRUE(live.config().measure.metric.empty());
    EXPECT_FALSE(live.last_result()->measurement.chord_mm.has_value());
  }
  LiveOptions options = Options();
  options.scale_distance_mm = 50;
  LiveController live(SceneConfig(), options);
  Feed(live, 0);
  live.on_event(UiEvent::Key('c'));
  ScaleClick(live, {100, 100});
  ScaleClick(live, {105, 100});  // 5 px: no usable scale; pick again.
  EXPECT_TRUE(live.scale_mode());
  EXPECT_NE(live.message().find("too close"), std::string::npos) << live.message();
  EXPECT_TRUE(live.config().measure.metric.empty());
  ScaleClick(live, {100, 100});
  live.on_event(UiEvent::Key(27));  // Esc cancels scale mode; it does not quit.
  EXPECT_FALSE(live.scale_mode());
  EXPECT_FALSE(live.quit_requested());
  EXPECT_NE(live.message().find("cancelled"), std::string::npos) << live.message();
  Click(live, {5, 5});  // Back to normal clicks: a colour pick on the background, refused.
  EXPECT_NE(live.message().find("not a coloured marker"), std::string::npos) << live.message();
  Feed(live, 1);
  EXPECT_TRUE(live.config().measure.metric.empty());
  EXPECT_FALSE(live.last_result()->measurement.chord_mm.has_value());
  live.on_event(UiEvent::Key(27));
  EXPECT_TRUE(live.quit_requested());
}

TEST_F(LiveControllerTest, ClickedScaleIsInUndistortedPixelsWithACameraModel) {
  TrackingConfig config = SceneConfig();
  CameraIntrinsics camera;
  camera.image_size = {320, 240};
  camera.camera_matrix = cv::Matx33d(300, 0, 160, 0, 300, 120, 0, 0, 1);
  camera.distortion = {-0.3, 0.1, 0, 0, 0};
  config.camera = camera;
  LiveOptions options = Options();
  options.scale_distance_mm = 50;
  LiveController live(config, options);
  Feed(live, 0);
  live.on_event(UiEvent::Key('c'));
  const std::vector<cv::Point2d> raw = {{20, 20}, {300, 20}};
  ScaleClick(live, raw[0]);
  ScaleClick(live, raw[1]);
  const MetricModel& metric = live.config().measure.metric;
  ASSERT_TRUE(metric.scale_points && metric.scale_mm_per_px) << live.message();
  // The stored points are the undistorted clicks: the lens maps them back onto the clicks.
  const std::vector<cv::Point2d> stored = {metric.scale_points->a_px, metric.scale_points->b_px};
  for (size_t i = 0; i < 2; ++i) {
    const std::vector<cv::Point3d> ray = {
        {(stored[i].x - 160) / 300, (stored[i].y - 120) / 300, 1.0}};
    std::vector<cv::Point2d> projected;
    cv::projectPoints(ray, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera.camera_matrix,
                      camera.distortion, projected);
    EXPECT_NEAR(projected[0].x, raw[i].x, 1e-3);
    EXPECT_NEAR(projected[0].y, raw[i].y, 1e-3);
  }
  const double span_px = cv::norm(stored[0] - stored[1]);
  EXPECT_GT(std::abs(span_px - 280.0), 5.0) << "this lens must change the corner distance";
  EXPECT_DOUBLE_EQ(*metric.scale_mm_per_px, 50.0 / span_px);
}

TEST_F(LiveControllerTest, BadOptionsOrConfigAreInputErrors) {
  LiveOptions options = Options();
  options.select_box_px = 1;
  EXPECT_THROW(LiveController(SceneConfig(), options), InputError);
  options = Options();
  options.scale_distance_mm = 0.0;
  EXPECT_THROW(LiveController(SceneConfig(), options), InputError);
  TrackingConfig empty;
  EXPECT_THROW(LiveController(empty, Options()), InputError);
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

// `softsight track --config <config> --input <video> --csv <csv>`, through the same pipeline.
void Track(const std::string& config_file, const std::string& video, const std::string& csv) {
  const TrackingConfig config = LoadTrackingConfig(config_file);
  FrameSourceSpec spec;
  spec.input = video;
  std::unique_ptr<FrameSource> source = OpenFrameSource(spec);
  TrackingSession session(config);
  std::vector<std::string> names;
  for (const MarkerSpec& m : config.markers) names.push_back(m.name);
  CsvSink sink(csv, TrackingColumns(names, false));
  const RunSummary summary = RunPipeline(*source, session, {&sink});
  ASSERT_TRUE(summary.error.empty()) << summary.error;
}

// A fake clock for PacedFrameSource: waiting moves the time forward at once, so the test never
// sleeps and a loaded machine cannot change what it sees.
struct FakeClock {
  PacedFrameSource::Clock::time_point now{};
  std::vector<PacedFrameSource::Clock::time_point> waits;  // Every sleep_until target.
  PacingClock timing() {
    PacingClock timing;
    timing.now = [this] { return now; };
    timing.sleep_until = [this](PacedFrameSource::Clock::time_point t) {
      waits.push_back(t);
      if (t > now) now = t;
    };
    return timing;
  }
};

class LiveFileTest : public LiveControllerTest {
 protected:
  // The rendered scene as a lossless 30 fps video, the file a person would play in `live`.
  std::string WriteVideo(int frames) {
    const std::string path = (dir_ / "scene.avi").string();
    testing::WriteSceneVideo(*scene_, frames, path);
    return path;
  }
  std::unique_ptr<PacedFrameSource> PlayFile(const std::string& path, FakeClock& clock) {
    FrameSourceSpec spec;
    spec.input = path;
    return std::make_unique<PacedFrameSource>(OpenFrameSource(spec), clock.timing());
  }
  // The options `live` runs a 30 fps file with (recordings at the file's rate).
  LiveOptions FileOptions() const {
    LiveOptions options = Options();
    options.record_fps = 30.0;
    return options;
  }
  // `track` on the last recording's raw video with its config gives the live CSV's text (found
  // flags and positions included, timings left out): `rows` rows and the header.
  void ExpectTrackReproduces(const LiveController& live, size_t rows) {
    const std::string prefix = live.last_recording();
    Track(prefix + ".yaml", prefix + ".raw.avi", (dir_ / "again.csv").string());
    const std::vector<std::string> live_rows = CsvRowsWithoutTiming(prefix + ".csv");
    EXPECT_EQ(live_rows.size(), rows + 1);
    EXPECT_EQ(CsvRowsWithoutTiming((dir_ / "again.csv").string()), live_rows);
    fs::remove(dir_ / "again.csv");
  }
};

TEST_F(LiveFileTest, PausedFileStopsAndRecordingRowsAreTheSourcesFramesThatTrackReproduces) {
  const std::string video = WriteVideo(24);
  FakeClock clock;
  std::unique_ptr<PacedFrameSource> source = PlayFile(video, clock);
  LiveOptions options = Options();
  options.record_fps = 30.0;  // What the command takes from the source.
  LiveController live(SceneConfig(), options);
  LiveFeed feed(*source);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(feed.step(live));
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(feed.step(live));
  EXPECT_EQ(live.last_result()->frame_index, 6);

  // Pause: no frame is read however long it lasts, and the source's clock stops.
  live.on_event(UiEvent::Key(' '));
  ASSERT_TRUE(live.paused());
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(feed.step(live));
  EXPECT_TRUE(source->paused());
  const auto paused_at = clock.now;
  clock.now += std::chrono::seconds(14);  // A long pause (418 frames at 30 fps).
  live.on_event(UiEvent::Key(' '));
  ASSERT_TRUE(feed.step(live));
  // Resume: the next frame, one frame period after the resume (no jump, no burst).
  EXPECT_EQ(live.last_result()->frame_index, 7);
  EXPECT_FALSE(source->paused());
  ASSERT_FALSE(clock.waits.empty());
  EXPECT_GT(clock.waits.back(), paused_at + std::chrono::seconds(14));
  EXPECT_LE(clock.waits.back(), paused_at + std::chrono::seconds(14) + std::chrono::milliseconds(34));
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(feed.step(live));
  live.on_event(UiEvent::Key('r'));
  ASSERT_FALSE(live.recording());
  EXPECT_EQ(source->dropped_frames(), 0);

  // The CSV: consecutive frames 2..12, the source's own indices and timestamps.
  const std::string prefix = live.last_recording();
  const CsvTable table = ReadCsvTable(prefix + ".csv");
  ASSERT_EQ(table.row_count(), 11u);
  for (size_t row = 0; row < table.row_count(); ++row) {
    EXPECT_EQ(*table.values[*table.find("frame")][row], 2.0 + row);
    EXPECT_NEAR(*table.values[*table.find("time_s")][row], (2.0 + row) / 30.0, 1e-6);
  }

  // Re-tracking the raw recording with its saved config gives the same rows, frame and time_s
  // included (the config's `recording:` key says where the raw video starts).
  Track(prefix + ".yaml", prefix + ".raw.avi", (dir_ / "again.csv").string());
  const std::vector<std::string> live_rows = CsvRowsWithoutTiming(prefix + ".csv");
  const std::vector<std::string> again = CsvRowsWithoutTiming((dir_ / "again.csv").string());
  ASSERT_EQ(live_rows.size(), 12u);  // Header and 11 rows.
  EXPECT_EQ(again, live_rows);
}

// A box dragged on empty background while the active marker tracks by colour is refused: the
// marker is not lost, and keeps being found where it is.
TEST_F(LiveFileTest, AColourBoxOnBackgroundIsRefusedAndTheMarkerKeepsItsPlace) {
  const std::string video = WriteVideo(12);
  FakeClock clock;
  std::unique_ptr<PacedFrameSource> source = PlayFile(video, clock);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(feed.step(live));
  live.on_event(UiEvent::Key(' '));
  ASSERT_EQ(TrackerMethodName(live.config().markers[0].params), "colour");
  const cv::Point2d red = *live.last_result()->markers[0].observation.position_px;
  Drag(live, {20, 20}, {44, 44});
  EXPECT_NE(live.message().find("holds nothing its tracker takes"), std::string::npos)
      << live.message();
  EXPECT_FALSE(live.config().markers[0].params.get<ColourParams>().roi.has_value() &&
               *live.config().markers[0].params.get<ColourParams>().roi == cv::Rect(20, 20, 24, 24));
  ASSERT_TRUE(live.last_result()->markers[0].observation.found());
  EXPECT_EQ(*live.last_result()->markers[0].observation.position_px, red);
  // A box around the marker is taken.
  Drag(live, red - cv::Point2d(12, 12), red + cv::Point2d(12, 12));
  EXPECT_NE(live.message().find("reselected"), std::string::npos) << live.message();
  EXPECT_TRUE(live.last_result()->markers[0].observation.found());
}

// A recording started after edits made while paused (every marker switched to SAD, a box dragged
// on empty background and refused, a box dragged around a marker) reproduces under `track`: the
// recording starts from a session built afresh from its config, not one that keeps what it
// learned before (the markers' arrangement, their motion), which made live say `implausible`
// where `track` said `found`.
TEST_F(LiveFileTest, ARecordingStartedAfterPausedEditsReproducesUnderTrack) {
  const std::string video = WriteVideo(30);
  FakeClock clock;
  std::unique_ptr<PacedFrameSource> source = PlayFile(video, clock);
  LiveOptions options = Options();
  options.record_fps = 30.0;
  LiveController live(SceneConfig(), options);
  LiveFeed feed(*source);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(feed.step(live));
  live.on_event(UiEvent::Key(' '));
  ASSERT_TRUE(live.paused());
  live.on_event(UiEvent::Key('m'));  // colour -> sad
  ASSERT_EQ(TrackerMethodName(live.config().markers[0].params), "sad");
  // A box on empty background is refused, saying why; the active marker keeps its template.
  const cv::Rect before = *live.config().markers[0].params.get<TemplateParams>().rect;
  Drag(live, {20, 20}, {44, 44});
  EXPECT_NE(live.message().find("holds no marker"), std::string::npos) << live.message();
  EXPECT_EQ(*live.config().markers[0].params.get<TemplateParams>().rect, before);
  // A box around blue, off its centre: blue's template is re-cut.
  const cv::Point2d blue = *live.last_result()->markers[1].observation.position_px;
  Drag(live, blue - cv::Point2d(9, 11), blue + cv::Point2d(12, 10));
  ASSERT_NE(live.message().find("blue: reselected"), std::string::npos) << live.message();
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  live.on_event(UiEvent::Key(' '));
  for (int i = 0; i < 12; ++i) ASSERT_TRUE(feed.step(live));
  live.on_event(UiEvent::Key('r'));
  ASSERT_FALSE(live.recording());
  const std::string prefix = live.last_recording();
  Track(prefix + ".yaml", prefix + ".raw.avi", (dir_ / "again.csv").string());
  const std::vector<std::string> live_rows = CsvRowsWithoutTiming(prefix + ".csv");
  ASSERT_EQ(live_rows.size(), 14u);  // Header, the frame on screen, 12 frames.
  EXPECT_EQ(CsvRowsWithoutTiming((dir_ / "again.csv").string()), live_rows);
}

// The same edits at the end of the input, then a one-row recording: reproduced too.
TEST_F(LiveFileTest, AOneRowRecordingAtTheEndAfterEditsReproducesUnderTrack) {
  const std::string video = WriteVideo(12);
  FakeClock clock;
  std::unique_ptr<PacedFrameSource> source = PlayFile(video, clock);
  LiveController live(SceneConfig(), FileOptions());
  LiveFeed feed(*source);
  while (feed.step(live)) {
  }
  ASSERT_TRUE(live.ended());
  live.on_event(UiEvent::Key('m'));
  Drag(live, {20, 20}, {44, 44});
  live.on_event(UiEvent::Key('r'));
  ASSERT_TRUE(live.recording()) << live.message();
  live.on_event(UiEvent::Key('r'));
  ExpectTrackReproduces(live, 1);
}

TEST_F(LiveFileTest, ReselectedTemplatesAreSavedAsImagesThatTrackReproducesAfterTheReselection) {
  const std::string video = WriteVideo(30);
  FakeClock clock;
  std::unique_ptr<PacedFrameSource> source = PlayFile(video, clock);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source);
  for (int i = 0; i < 8; ++i) ASSERT_TRUE(feed.step(live));
  // `m` three times: colour -> sad -> ssd -> zncc, templates cut where the markers are on frame
  // 7; then a drag re-cuts blue's template on frame 12, off-centre (a person's box is never
  // centred to the pixel).
  for (int i = 0; i < 3; ++i) live.on_event(UiEvent::Key('m'));
  ASSERT_EQ(TrackerMethodName(live.config().markers[0].params), "zncc");
  std::vector<FrameResult> shown = {*live.last_result()};  // Frame 7 with the new templates.
  cv::Point2d dragged_around;
  while (feed.step(live)) {
    shown.push_back(*live.last_result());
    if (live.last_result()->frame_index == 12) {
      const cv::Point2d blue = *live.last_result()->markers[1].observation.position_px;
      dragged_around = blue;
      Drag(live, blue - cv::Point2d(10, 12), blue + cv::Point2d(13, 10));
      ASSERT_NE(live.message().find("blue: reselected"), std::string::npos) << live.message();
      shown.back() = *live.last_result();  // Frame 12 as shown after the drag.
    }
  }
  live.on_event(UiEvent::Key('s'));
  const std::string saved = (dir_ / "saved.yaml").string();
  ASSERT_NE(live.message().find("saved"), std::string::npos) << live.message();
  for (const char* marker : {"red", "blue", "green"}) {
    EXPECT_TRUE(fs::exists(dir_ / ("saved." + std::string(marker) + ".png"))) << marker;
  }
  const TrackingConfig reloaded = LoadTrackingConfig(saved);
  EXPECT_EQ(reloaded.markers[0].params.get<TemplateParams>().template_frame, 7);
  EXPECT_EQ(reloaded.markers[1].params.get<TemplateParams>().template_frame, 12);
  // Saved as the tracker cut it: the 23 x 22 box dragged, widened to hold the disc's
  // surroundings (its rim came within kMinSurroundPx of the box's edge), pixels and box alike.
  const TemplateParams& blue_saved = reloaded.markers[1].params.get<TemplateParams>();
  EXPECT_TRUE(blue_saved.rect->contains(cv::Point(dragged_around)));
  EXPECT_GT(blue_saved.rect->width, 23);
  EXPECT_GT(blue_saved.rect->height, 22);
  EXPECT_EQ(blue_saved.image.size(), blue_saved.rect->size());

  Track(saved, video, (dir_ / "tracked.csv").string());
  const CsvTable table = ReadCsvTable((dir_ / "tracked.csv").string());
  ASSERT_EQ(table.row_count(), 30u);
  ASSERT_EQ(shown.size(), 23u);  // Frames 7..29.
  for (const FrameResult& result : shown) {
    const size_t row = static_cast<size_t>(result.frame_index);
    // Blue's saved template is the one dragged on frame 12: track starts it there (not found
    // before), and from there on it is where live had it.
    for (const MarkerObservation& m : result.markers) {
      if (m.name == "blue" && result.frame_index < 12) {
        EXPECT_FALSE(table.values[*table.find("blue_x")][row]) << "frame " << row;
        continue;
      }
      ASSERT_TRUE(m.observation.found()) << m.name << " frame " << row;
      const auto x = table.values[*table.find(m.name + "_x")][row];
      const auto y = table.values[*table.find(m.name + "_y")][row];
      ASSERT_TRUE(x && y) << m.name << " not found by track in frame " << row;
      EXPECT_NEAR(*x, m.observation.position_px->x, 1e-3) << m.name << " frame " << row;
      EXPECT_NEAR(*y, m.observation.position_px->y, 1e-3) << m.name << " frame " << row;
    }
  }
}

// The positions `track` finds in `csv` for every marker of `shown` from frame `from` on equal
// the window's, to 1e-3 px, found flags included.
void ExpectTrackShowsTheSame(const std::string& csv, const std::vector<FrameResult>& shown,
                             int64_t from) {
  const CsvTable table = ReadCsvTable(csv);
  int compared = 0;
  for (const FrameResult& result : shown) {
    if (result.frame_index < from) continue;
    const size_t row = static_cast<size_t>(result.frame_index);
    ASSERT_LT(row, table.row_count());
    for (const MarkerObservation& m : result.markers) {
      const auto x = table.values[*table.find(m.name + "_x")][row];
      const auto y = table.values[*table.find(m.name + "_y")][row];
      ASSERT_EQ(x.has_value(), m.observation.found()) << m.name << " frame " << row;
      if (!x) continue;
      EXPECT_NEAR(*x, m.observation.position_px->x, 1e-3) << m.name << " frame " << row;
      EXPECT_NEAR(*y, m.observation.position_px->y, 1e-3) << m.name << " frame " << row;
      ++compared;
    }
  }
  EXPECT_GT(compared, 0);
}

TEST_F(LiveFileTest, HsvRangesChangedWithTrackbarsAreSavedAndTrackReproducesThem) {
  const std::string video = WriteVideo(24);
  FakeClock clock;
  std::unique_ptr<PacedFrameSource> source = PlayFile(video, clock);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source);
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(feed.step(live));
  // Blue active, its hue range moved with the trackbars on frame 5.
  live.on_event(UiEvent::Key('2'));
  live.on_event(UiEvent::Trackbar(0, 92));
  live.on_event(UiEvent::Trackbar(1, 128));
  std::vector<FrameResult> shown;
  while (feed.step(live)) shown.push_back(*live.last_result());
  live.on_event(UiEvent::Key('s'));
  const TrackingConfig saved = LoadTrackingConfig((dir_ / "saved.yaml").string());
  EXPECT_EQ(saved.markers[1].params.get<ColourParams>().h.lo, 92);
  EXPECT_EQ(saved.markers[1].params.get<ColourParams>().h.hi, 128);
  Track((dir_ / "saved.yaml").string(), video, (dir_ / "tracked.csv").string());
  ExpectTrackShowsTheSame((dir_ / "tracked.csv").string(), shown, 6);
}

// Every kind of live edit made while a recording runs reaches the recording's config: track on
// the raw video with it gives the window's rows, before and after each edit.
TEST_F(LiveFileTest, EditsWhileRecordingAreKeptInTheRecordingsConfigThatTrackReproduces) {
  const std::string video = WriteVideo(24);
  FakeClock clock;
  std::unique_ptr<PacedFrameSource> source = PlayFile(video, clock);
  LiveOptions options = Options();
  options.record_fps = 30.0;
  LiveController live(SceneConfig(), options);
  LiveFeed feed(*source);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(feed.step(live));
  live.on_event(UiEvent::Key('r'));  // Recording from frame 2.
  ASSERT_TRUE(live.recording()) << live.message();
  while (feed.step(live)) {
    const int64_t frame = live.last_result()->frame_index;
    if (frame == 4) {  // Blue's hue moved with the trackbars (a respec).
      live.on_event(UiEvent::Key('2'));
      live.on_event(UiEvent::Trackbar(0, 92));
      live.on_event(UiEvent::Trackbar(1, 128));
    } else if (frame == 6) {  // Every marker to SAD: templates cut where they are (respec, reselect).
      live.on_event(UiEvent::Key('m'));
      ASSERT_EQ(TrackerMethodName(live.config().markers[0].params), "sad") << live.message();
    } else if (frame == 8) {  // Blue's template re-cut by a drag, off-centre.
      const cv::Point2d blue = *live.last_result()->markers[1].observation.position_px;
      Drag(live, blue - cv::Point2d(10, 12), blue + cv::Point2d(13, 10));
      ASSERT_NE(live.message().find("blue: reselected"), std::string::npos) << live.message();
    } else if (frame == 10) {  // A new bending-distance reference.
      live.on_event(UiEvent::Key('b'));
    } else if (frame == 12) {  // Paused: red's colour ranges, kept aside while it matches a
                               // template, change; the session does not (no change is logged).
      live.on_event(UiEvent::Key(' '));
      live.on_event(UiEvent::Key('1'));
      live.on_event(UiEvent::Trackbar(2, 70));
      live.on_event(UiEvent::Key(' '));
    } else if (frame == 15) {
      live.on_event(UiEvent::Key('r'));
      ASSERT_FALSE(live.recording());
    }
  }
  const std::string prefix = live.last_recording();
  const TrackingConfig recorded = LoadTrackingConfig(prefix + ".yaml");
  // 2 respecs (one a trackbar each), 3 x (respec + reselect), 1 reselect, 1 reset.
  ASSERT_EQ(recorded.changes.size(), 10u);
  EXPECT_EQ(recorded.changes.front().after_frame, 2);  // Frame 4 is the recording's frame 2.
  EXPECT_EQ(recorded.changes.back().kind, ConfigChange::Kind::kResetTipReference);
  EXPECT_EQ(recorded.changes.back().after_frame, 8);
  const ConfigChange& drag = recorded.changes[8];
  EXPECT_EQ(drag.kind, ConfigChange::Kind::kReselect);
  EXPECT_EQ(drag.marker, "blue");
  EXPECT_EQ(drag.rect.size(), cv::Size(23, 22));
  EXPECT_EQ(TrackerMethodName(recorded.markers[1].params), "colour") << "the start stays as it was";

  Track(prefix + ".yaml", prefix + ".raw.avi", (dir_ / "again.csv").string());
  const std::vector<std::string> live_rows = CsvRowsWithoutTiming(prefix + ".csv");
  ASSERT_EQ(live_rows.size(), 15u);  // Header and frames 2..15.
  EXPECT_EQ(CsvRowsWithoutTiming((dir_ / "again.csv").string()), live_rows);
  // Without the edits the rows differ after the first of them: the test can fail.
  TrackingConfig unedited = recorded;
  unedited.changes.clear();
  SaveTrackingConfig(unedited, (dir_ / "unedited.yaml").string());
  Track((dir_ / "unedited.yaml").string(), prefix + ".raw.avi", (dir_ / "unedited.csv").string());
  EXPECT_NE(CsvRowsWithoutTiming((dir_ / "unedited.csv").string()), live_rows);
}

TEST_F(LiveControllerTest, WhilePausedARangeChangeRetracksTheFrameOnScreenAtOnce) {
  LiveController live(SceneConfig(), Options());
  SceneTruth truth;
  for (int i = 0; i < 4; ++i) truth = Feed(live, i);
  ExpectAt(live, 1, truth, 0.3);
  live.on_event(UiEvent::Key(' '));
  ASSERT_TRUE(live.paused());
  // Blue's hue range moved onto green's hue with the trackbars: blue's ring moves to the green
  // blob at once, on the same frame.
  live.on_event(UiEvent::Key('2'));
  live.on_event(UiEvent::Trackbar(1, 75));
  live.on_event(UiEvent::Trackbar(0, 45));
  EXPECT_EQ(live.last_result()->frame_index, 3);
  const auto& blue = live.last_result()->markers[1].observation;
  ASSERT_TRUE(blue.found()) << live.message();
  EXPECT_NEAR(blue.position_px->x, truth.markers[2].centroid_px->x, 0.3);
  EXPECT_NEAR(blue.position_px->y, truth.markers[2].centroid_px->y, 0.3);
  const cv::Mat canvas = live.canvas().clone();
  EXPECT_GE(RingPoints(canvas, *truth.markers[2].centroid_px), 20);
}

TEST_F(LiveControllerTest, MaskViewShowsTheMembersAndClicksGrowAndShrinkTheRangeRetrackingAtOnce) {
  TrackingConfig config = SceneConfig();
  config.markers[1].params.get<ColourParams>().h = {117, 125};  // Blue (hue 112 here) is outside its range.
  LiveController live(config, Options());
  SceneTruth truth;
  for (int i = 0; i < 4; ++i) truth = Feed(live, i);
  EXPECT_FALSE(live.last_result()->markers[1].observation.found());
  live.on_event(UiEvent::Key(' '));
  live.on_event(UiEvent::Key('2'));
  live.on_event(UiEvent::Key('v'));
  ASSERT_TRUE(live.mask_view());
  const cv::Point2d blue = *truth.markers[1].centroid_px;
  const cv::Point2d red = *truth.markers[0].centroid_px;
  cv::Mat frame;
  scene_->render(3, frame);
  {
    // Nothing is a member: the whole image dimmed to a quarter, blue's pixel too.
    const cv::Mat canvas = live.canvas();
    const cv::Vec3b shown = canvas.at<cv::Vec3b>(cv::Point(blue));
    const cv::Vec3b original = frame.at<cv::Vec3b>(cv::Point(blue));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(shown[c], original[c] * 0.25, 1.5);
  }
  // A click on blue adds its colours: blue is found there at once (still paused, same frame),
  // its pixels shown in their own colours, red's still dimmed; the chosen blob is circled green.
  EXPECT_FALSE(live.chart().newest(0).has_value());  // No angle without blue.
  Click(live, blue);
  EXPECT_EQ(live.last_result()->frame_index, 3);
  ExpectAt(live, 1, truth, 0.3);
  // The strip chart reads the re-tracked frame's angle, as the text block does.
  ASSERT_TRUE(live.last_result()->measurement.angle_deg.has_value());
  EXPECT_EQ(live.chart().newest(0), live.last_result()->measurement.angle_deg);
  EXPECT_EQ(live.chart().size(), 4u);
  EXPECT_EQ(live.config().markers[1].params.get<ColourParams>().h.lo, 112);
  EXPECT_EQ(live.config().markers[1].params.get<ColourParams>().h.hi, 125);
  {
    const cv::Mat canvas = live.canvas();
    EXPECT_EQ(canvas.at<cv::Vec3b>(cv::Point(blue)), frame.at<cv::Vec3b>(cv::Point(blue)));
    const cv::Vec3b red_shown = canvas.at<cv::Vec3b>(cv::Point(red));
    EXPECT_NEAR(red_shown[2], frame.at<cv::Vec3b>(cv::Point(red))[2] * 0.25, 1.5);
    int green = 0;
    for (int deg = 0; deg < 360; deg += 10) {
      for (int radius = 9; radius <= 15; ++radius) {
        const cv::Point p(cvRound(blue.x + radius * std::cos(deg * CV_PI / 180)),
                          cvRound(blue.y + radius * std::sin(deg * CV_PI / 180)));
        const cv::Vec3b px = canvas.at<cv::Vec3b>(p);
        if (px[1] > 150 && px[1] > px[0] + 60 && px[1] > px[2] + 60) {  // Green, antialiased.
          ++green;
          break;
        }
      }
    }
    EXPECT_GE(green, 30) << "the chosen blob is not circled";
  }
  // Shift-click on blue takes its colours out again: blue is not found, at once.
  live.on_event(UiEvent::Mouse(Type::kMouseDown, blue.x, blue.y, true));
  live.on_event(UiEvent::Mouse(Type::kMouseUp, blue.x, blue.y, true));
  EXPECT_EQ(live.last_result()->frame_index, 3);
  EXPECT_FALSE(live.last_result()->markers[1].observation.found()) << live.message();
  EXPECT_NE(live.message().find("removed"), std::string::npos) << live.message();
}

TEST(RangeEdit, GrowTakesInTheClickedColoursAcrossHueZeroAndShrinkCutsTheCheapestEnd) {
  const auto pixels = [](std::vector<cv::Vec3b> hsv) {
    return cv::Mat(hsv, true).reshape(3, 1);
  };
  // Red around hue 0: a range 170..5 grows to 8 (nearer than going down from 170).
  HsvRanges red{{170, 5}, {100, 255}, {60, 255}};
  red = GrowRanges(red, pixels({{8, 150, 200}, {2, 90, 50}}));
  EXPECT_EQ(red.h.lo, 170);
  EXPECT_EQ(red.h.hi, 8);
  EXPECT_EQ(red.s.lo, 90);
  EXPECT_EQ(red.v.lo, 50);
  EXPECT_TRUE(InRanges(red, {175, 200, 200}));
  EXPECT_TRUE(InRanges(red, {8, 150, 200}));
  EXPECT_FALSE(InRanges(red, {12, 150, 200}));
  // A pale patch (low saturation) taken out: the saturation's low end moves above it, which
  // removes less than any other cut; the marker's saturated pixels stay in.
  HsvRanges blue{{95, 125}, {40, 255}, {40, 255}};
  std::string why;
  ASSERT_TRUE(ShrinkRanges(blue, pixels({{100, 50, 200}, {110, 60, 180}}), &why)) << why;
  EXPECT_EQ(blue.s.lo, 61);
  EXPECT_EQ(blue.h.lo, 95);
  EXPECT_FALSE(InRanges(blue, {100, 50, 200}));
  EXPECT_TRUE(InRanges(blue, {107, 200, 150}));
  // Hue cut across 0.
  HsvRanges wrap{{170, 10}, {0, 255}, {0, 255}};
  ASSERT_TRUE(ShrinkRanges(wrap, pixels({{8, 0, 0}, {9, 255, 255}}), &why)) << why;
  EXPECT_EQ(wrap.h.lo, 170);
  EXPECT_EQ(wrap.h.hi, 7);
  // Nothing to take out.
  EXPECT_FALSE(ShrinkRanges(wrap, pixels({{60, 100, 100}}), &why));
  EXPECT_NE(why.find("not in the ranges"), std::string::npos);
}

TEST(LiveLayout, AFrameFitsTheScreenAndCanvasPixelsMapBackToImagePixels) {
  // 1280x720 with the 180 px chart and the help panel on a 1366x768 laptop screen.
  const cv::Size screen(1366, 768);
  const cv::Size max_canvas = MaxCanvasForScreen(screen);
  for (const bool help : {false, true}) {
    const LiveLayout layout = ComputeLiveLayout({1280, 720}, 180, help ? 300 : 0, max_canvas);
    EXPECT_LE(layout.canvas.width, screen.width - kScreenMarginWidthPx);
    EXPECT_LE(layout.canvas.height, screen.height - kScreenMarginHeightPx);
    EXPECT_LT(layout.scale_x(), 1.0);
    EXPECT_NEAR(layout.scale_x(), layout.scale_y(), 0.01);  // Not distorted.
    EXPECT_EQ(layout.chart.y, layout.image.height);
    EXPECT_EQ(layout.help.empty(), !help);
    // A canvas pixel's centre maps to the image point it shows, and back.
    for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(1279, 719), cv::Point2d(640.25, 77.5)}) {
      const cv::Point2d back = layout.to_image(layout.to_view(p));
      EXPECT_NEAR(back.x, p.x, 1e-9);
      EXPECT_NEAR(back.y, p.y, 1e-9);
    }
    EXPECT_NEAR(layout.to_image({-0.5, -0.5}).x, -0.5, 1e-9);  // The image's corner.
  }
  // A small frame is never enlarged.
  const LiveLayout small = ComputeLiveLayout({320, 240}, 180, 0, max_canvas);
  EXPECT_EQ(small.image, cv::Rect(0, 0, 320, 240));
  EXPECT_EQ(small.canvas, cv::Size(320, 420));
}

// The trackbar window goes beside the canvas where there is room, else under it, else into the
// screen's bottom-right corner; it never starts over the canvas's top-left text block.
TEST(LiveLayout, TheTrackbarWindowIsPlacedBesideTheCanvasNotOverIt) {
  const auto overlaps_text = [](cv::Point at, cv::Size canvas) {
    return cv::Rect(at, kTrackbarWindowPx).contains({10, 10}) && canvas.area() > 0;
  };
  // A 640x480 frame with its chart on a 1920x1080 screen: to the right.
  const cv::Point right = TrackbarWindowPlace({1920, 1080}, {640, 660});
  EXPECT_GE(right.x, 640);
  EXPECT_EQ(right.y, 0);
  // A 1280x720 frame on a 1366x768 laptop (canvas 1296x668 after scaling) with the help panel:
  // neither right nor under fits, the bottom-right corner.
  const cv::Point corner = TrackbarWindowPlace({1366, 768}, {1334, 668});
  EXPECT_FALSE(overlaps_text(corner, {1334, 668}));
  EXPECT_LE(corner.x + kTrackbarWindowPx.width, 1366);
  EXPECT_LE(corner.y + kTrackbarWindowPx.height, 768);
  // A wide but short canvas: under it.
  const cv::Point under = TrackbarWindowPlace({1366, 1080}, {1300, 420});
  EXPECT_EQ(under.x, 0);
  EXPECT_GE(under.y, 420);
}

TEST(LiveControllerOnAScreen, A720pFrameFitsALaptopScreenAndClicksSelectTheRightPixels) {
  const SceneOptions options = testing::LiveTest720pScene(10);
  SyntheticScene scene(options);
  LiveOptions live_options;
  const testing::TempDir dir;
  live_options.save_config_path = dir.file("fit.yaml");
  LiveController live(SceneConfig(), live_options);
  live.set_screen({1366, 768});
  Frame frame;
  SceneTruth truth;
  for (int i = 0; i < 3; ++i) {
    truth = scene.render(i, frame.image);
    frame.index = i;
    frame.time_s = truth.time_s;
    live.on_frame(frame, SteadyClock::now());
  }
  for (const bool help : {false, true}) {
    if (help) live.on_event(UiEvent::Key('h'));
    const cv::Mat& canvas = live.canvas();
    EXPECT_LE(canvas.cols, 1366 - kScreenMarginWidthPx) << "help " << help;
    EXPECT_LE(canvas.rows, 768 - kScreenMarginHeightPx) << "help " << help;
    // The rings are drawn where the found markers are, in canvas pixels (red and blue at least:
    // this scene's green is darker than the test config's range).
    ASSERT_TRUE(live.last_result()->markers[0].observation.found());
    ASSERT_TRUE(live.last_result()->markers[1].observation.found());
    for (const MarkerTruth& marker : truth.markers) {
      if (!live.last_result()->markers[&marker - &truth.markers[0]].observation.found()) continue;
      const cv::Point2d at = live.to_view(*marker.centroid_px);
      EXPECT_LT(at.x, 1280 * 0.8);  // Scaled down.
      EXPECT_GE(RingPoints(canvas, at, 12 * (at.x / marker.centroid_px->x)), 18) << marker.name;
    }
  }
  // A click at blue's place on the scaled canvas: blue's colour is picked around the image pixel
  // under the pointer (the search box is centred there, within a pixel).
  const cv::Point2d blue = *truth.markers[1].centroid_px;
  const cv::Point2d on_canvas = live.to_view(blue);
  live.on_event(UiEvent::Mouse(Type::kMouseDown, std::round(on_canvas.x), std::round(on_canvas.y)));
  live.on_event(UiEvent::Mouse(Type::kMouseUp, std::round(on_canvas.x), std::round(on_canvas.y)));
  EXPECT_EQ(live.active_marker(), 1);
  const MarkerSpec& spec = live.config().markers[1];
  ASSERT_TRUE(spec.params.get<ColourParams>().roi) << live.message();
  const cv::Point2d centre(spec.params.get<ColourParams>().roi->x + spec.params.get<ColourParams>().roi->width / 2.0,
                           spec.params.get<ColourParams>().roi->y + spec.params.get<ColourParams>().roi->height / 2.0);
  // Rounding the click to a canvas pixel moves it by up to half a canvas pixel, and the box is
  // cut around the nearest image pixel.
  const double scale = live.to_view({1, 0}).x - live.to_view({0, 0}).x;
  EXPECT_NEAR(centre.x, blue.x, 0.5 / scale + 1.0) << live.message();
  EXPECT_NEAR(centre.y, blue.y, 0.5 / scale + 1.0);
  EXPECT_LT(spec.params.get<ColourParams>().h.lo, 107);  // Blue's hue, about 107.
  EXPECT_GT(spec.params.get<ColourParams>().h.hi, 107);
}

class LivePlaybackTest : public LiveFileTest {
 protected:
  // The file as `live` plays it: seekable under the pacing, with a ring of only 8 frames so
  // that going back further reopens the file (both ways of reaching a frame are exercised).
  void Play(const std::string& video) {
    FrameSourceSpec spec;
    spec.input = video;
    auto seekable = std::make_unique<SeekableSource>(
        OpenFrameSource(spec), [spec] { return OpenFrameSource(spec); }, 8 * 320 * 240 * 3);
    seekable_ = seekable.get();
    source_ = std::make_unique<PacedFrameSource>(std::move(seekable), clock_.timing());
  }
  // The frame on screen is source frame `index`: the row names it, the markers are found at
  // its rendered truth, and the overlay's rings are drawn there.
  void ExpectShowing(LiveController& live, int index) {
    ASSERT_TRUE(live.last_result());
    EXPECT_EQ(live.last_result()->frame_index, index);
    EXPECT_NEAR(live.last_result()->time_s, index / 30.0, 1e-6);
    cv::Mat image;
    const SceneTruth truth = scene_->render(index, image);
    for (int m = 0; m < 3; ++m) ExpectAt(live, m, truth, 0.3);
    const cv::Mat canvas = live.canvas().clone();
    for (const MarkerTruth& marker : truth.markers) {
      EXPECT_GE(RingPoints(canvas, *marker.centroid_px), 20) << marker.name << " frame " << index;
    }
  }
  static void Key(LiveController& live, int key) { live.on_event(UiEvent::Key(key)); }

  FakeClock clock_;
  SeekableSource* seekable_ = nullptr;
  std::unique_ptr<PacedFrameSource> source_;
};

TEST_F(LivePlaybackTest, StepSeekStartEndLandOnTheSourcesFramesWithTheOverlayOnTheirTruth) {
  const std::string video = WriteVideo(40);
  Play(video);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source_, seekable_);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 4);

  Key(live, '.');  // Step forward: pauses, shows the next frame.
  ASSERT_TRUE(feed.step(live));
  EXPECT_TRUE(live.paused());
  ExpectShowing(live, 5);
  EXPECT_FALSE(feed.step(live));  // Paused: nothing more.
  Key(live, ',');
  ASSERT_TRUE(feed.step(live));
  Key(live, ',');
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 3);
  const int64_t decoded = seekable_->frames_decoded();
  Key(live, ']');  // +1 s = 30 frames: the file's own seek, not a decode of the frames between.
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 33);
  EXPECT_EQ(seekable_->direct_seeks(), 1);
  EXPECT_EQ(seekable_->frames_decoded(), decoded + 1);
  Key(live, kKeyLeft);  // -1 s: frame 3 is still in the ring, a copy.
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 3);
  EXPECT_EQ(seekable_->frames_decoded(), decoded + 1);
  Key(live, '>');  // End: the last frame, and the end of input at once (nothing follows it).
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 39);
  EXPECT_TRUE(live.ended());
  EXPECT_TRUE(feed.ended());
  Key(live, '.');  // Past the last frame: still END, the last frame stays.
  EXPECT_FALSE(feed.step(live));
  EXPECT_TRUE(live.ended());
  ExpectShowing(live, 39);
  // At END every control still works.
  Key(live, ',');
  ASSERT_TRUE(feed.step(live));
  EXPECT_FALSE(live.ended());
  ExpectShowing(live, 38);
  Key(live, ']');  // Past the end: the last frame.
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 39);
  Key(live, kKeyHome);
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 0);
  Key(live, '[');  // Before the start: the first frame.
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 0);
  Key(live, ',');
  EXPECT_FALSE(feed.step(live));
  EXPECT_EQ(live.message(), "at the first frame");
}

TEST_F(LivePlaybackTest, PlayingOnAfterASeekKeepsTheFilesRateAndEndKeepsEveryKeyWorking) {
  const std::string video = WriteVideo(12);
  Play(video);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source_, seekable_);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(feed.step(live));
  // +1 s while playing, past the end of this 0.4 s clip: the last frame at once, no wait for
  // the old schedule, then END.
  const auto before = clock_.now;
  Key(live, ']');
  ASSERT_TRUE(feed.step(live));
  EXPECT_EQ(clock_.now, before);
  ExpectShowing(live, 11);
  EXPECT_FALSE(feed.step(live));
  EXPECT_TRUE(live.ended());
  EXPECT_TRUE(feed.ended());
  // Space at END plays from the start; the next frame comes one frame period after it.
  Key(live, ' ');
  EXPECT_FALSE(live.paused());
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 0);
  const auto at_start = clock_.now;
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 1);
  EXPECT_GE(clock_.now - at_start, std::chrono::milliseconds(33));
  EXPECT_LE(clock_.now - at_start, std::chrono::milliseconds(34));
}

// After End, space plays from the first frame (as at the end of playing), saying so: it used to
// say "running", read past the end and say "end of input".
TEST_F(LivePlaybackTest, SpaceAfterEndPlaysFromTheStart) {
  const std::string video = WriteVideo(12);
  Play(video);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source_, seekable_);
  ASSERT_TRUE(feed.step(live));
  Key(live, ' ');  // Paused.
  EXPECT_TRUE(live.paused());
  Key(live, kKeyEnd);
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 11);
  EXPECT_TRUE(live.ended());
  EXPECT_EQ(live.message().rfind("end of input", 0), 0u) << live.message();
  Key(live, ' ');
  EXPECT_EQ(live.message(), "playing from the first frame");
  EXPECT_FALSE(live.paused());
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 0);
  EXPECT_FALSE(live.ended());
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 1);
}

TEST_F(LivePlaybackTest, LoopWrapsToTheFirstFrameAndRestartStartsTheTrackersAfresh) {
  const std::string video = WriteVideo(10);
  Play(video);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source_, seekable_);
  Key(live, 'l');
  EXPECT_TRUE(live.loop());
  std::vector<int64_t> frames;
  for (int i = 0; i < 25; ++i) {
    ASSERT_TRUE(feed.step(live));
    frames.push_back(live.last_result()->frame_index);
  }
  for (int i = 0; i < 25; ++i) EXPECT_EQ(frames[i], i % 10) << i;
  ExpectShowing(live, 4);
  // A recording stops at the wrap: its raw video must hold consecutive frames.
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(feed.step(live));
  Key(live, 'r');
  ASSERT_TRUE(live.recording());
  Key(live, '[');  // Refused while recording.
  EXPECT_NE(live.message().find("stop the recording first"), std::string::npos);
  live.take_messages();
  while (live.last_result()->frame_index != 0) ASSERT_TRUE(feed.step(live));
  EXPECT_FALSE(live.recording());
  // Said, on screen and in the log: the wrap's frame message does not replace it.
  const std::string said = "recorded 3 frames to " + live.last_recording() +
                           ".* (stopped: the loop went back to the first frame)";
  EXPECT_EQ(live.message(), said);
  const std::vector<std::string> log = live.take_messages();
  EXPECT_NE(std::find(log.begin(), log.end(), said), log.end());
  const CsvTable table = ReadCsvTable(live.last_recording() + ".csv");
  ASSERT_EQ(table.row_count(), 3u);  // Frames 7, 8, 9.
  EXPECT_EQ(*table.values[*table.find("frame")][0], 7.0);

  Key(live, 'l');  // Loop off: the clip ends.
  while (feed.step(live)) {
  }
  EXPECT_TRUE(live.ended());
  Key(live, '0');  // Restart: from frame 0, playing.
  ASSERT_TRUE(feed.step(live));
  EXPECT_FALSE(live.paused());
  ExpectShowing(live, 0);
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 1);
}

TEST_F(LiveControllerTest, ACameraAnswersTransportKeysWithAMessage) {
  LiveController live(SceneConfig(), Options());
  auto source = OpenSyntheticSource(SceneOptions{}, NoiseOptions{});
  LiveFeed feed(*source);  // No seekable source: played as it comes, like a camera.
  ASSERT_TRUE(feed.step(live));
  live.on_event(UiEvent::Key(','));
  EXPECT_FALSE(feed.step(live));
  EXPECT_NE(live.message().find("no stepping or seeking"), std::string::npos);
}

// The timeline under the picture, driven as a user does: a click on it seeks to the frame under
// the pointer, a drag seeks once to where it is let go (the seeks on the way are replaced, not
// queued), and it marks the frames where an edit was made, where a recording ran and where a
// marker was not found (the mark follows a re-track: an undone range change clears it).
TEST_F(LivePlaybackTest, TheTimelineSeeksByClickAndDragAndMarksEditsRecordingsAndLostMarkers) {
  const std::string video = WriteVideo(40);
  Play(video);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source_, seekable_);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(feed.step(live));
  ASSERT_EQ(live.timeline().length(), 40);  // The header's count, before reading to the end.
  EXPECT_EQ(live.timeline().position(), 2);
  const int width = 320;  // No screen given: the image and the timeline are unscaled.
  const double bar_y = 240 + StatusBandHeight() + kTimelineHeightPx / 2.0;
  const auto x_of = [&](int64_t frame) { return live.timeline().x_of(frame, width) + 0.2; };
  Click(live, {x_of(20), bar_y});
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 20);

  Key(live, ' ');  // Paused: only the drag's own seek can change the frame.
  live.on_event(UiEvent::Mouse(UiEvent::Type::kMouseDown, x_of(5), bar_y));
  live.on_event(UiEvent::Mouse(UiEvent::Type::kMouseMove, x_of(12), bar_y));
  live.on_event(UiEvent::Mouse(UiEvent::Type::kMouseMove, x_of(30), bar_y + 30));  // Off the bar.
  live.on_event(UiEvent::Mouse(UiEvent::Type::kMouseUp, x_of(30), bar_y + 30));
  ASSERT_TRUE(feed.step(live));
  ExpectShowing(live, 30);
  EXPECT_FALSE(feed.step(live)) << "one seek for the whole drag";
  EXPECT_EQ(live.undo_depth(), 0u) << "a drag on the timeline is no box on the image";

  // Edits: a range change that loses red marks the frame lost; undoing it finds red again.
  const int red_v_lo = live.active_hsv()[4];
  live.on_event(UiEvent::Trackbar(4, 255));  // V lo of red: nothing is that bright.
  live.on_event(UiEvent::Trackbar(4, 254));  // Still the same drag of the trackbar.
  EXPECT_FALSE(live.last_result()->markers[0].observation.found());
  EXPECT_TRUE(live.timeline().marked(30, Timeline::kLost));
  EXPECT_TRUE(live.timeline().marked(30, Timeline::kEdit));
  Key(live, 'u');
  EXPECT_EQ(live.active_hsv()[4], red_v_lo) << "one undo takes back the whole trackbar drag";
  EXPECT_TRUE(live.last_result()->markers[0].observation.found());
  EXPECT_FALSE(live.timeline().marked(30, Timeline::kLost));
  EXPECT_FALSE(live.timeline().marked(29, Timeline::kEdit));

  // A recording marks its frames.
  Key(live, 'r');
  ASSERT_TRUE(live.recording());
  Key(live, ' ');
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(feed.step(live));
  Key(live, 'r');
  for (int frame = 31; frame <= 33; ++frame) EXPECT_TRUE(live.timeline().marked(frame, Timeline::kRecorded));
  EXPECT_FALSE(live.timeline().marked(20, Timeline::kRecorded));

  // Drawn under the picture: the cursor (white) at the frame on screen, the recorded stretch
  // green along the bar's top, the edit yellow.
  const cv::Mat canvas = live.canvas().clone();
  const int bar_top = 240 + StatusBandHeight();
  EXPECT_EQ(canvas.at<cv::Vec3b>(bar_top + 1, live.timeline().x_of(33, width)), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(canvas.at<cv::Vec3b>(bar_top + 1, live.timeline().x_of(31, width) - 2), cv::Vec3b(60, 200, 60));
  EXPECT_EQ(canvas.at<cv::Vec3b>(bar_top + kTimelineHeightPx / 2, live.timeline().x_of(30, width)),
            cv::Vec3b(0, 220, 255));
  EXPECT_EQ(canvas.at<cv::Vec3b>(bar_top + 1, live.timeline().x_of(10, width)), cv::Vec3b(40, 40, 40));
}

// Keys pressed before a seek has been carried out queue up behind it and are carried out in
// their order: none is lost.
TEST_F(LivePlaybackTest, TransportKeysPressedDuringASeekAreQueuedInOrder) {
  const std::string video = WriteVideo(40);
  Play(video);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source_, seekable_);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(feed.step(live));
  Key(live, ' ');
  Key(live, ']');  // 3 -> 33
  EXPECT_TRUE(live.jump_pending());
  const cv::Mat before = live.canvas().clone();
  live.show_seeking();  // The window's hint while the seek runs.
  EXPECT_GT(cv::norm(before, live.canvas(), cv::NORM_L1), 0.0);
  Key(live, '[');  // -> 3
  Key(live, '>');  // -> 39
  Key(live, ',');  // -> 38
  for (const int expected : {33, 3, 39, 38}) {
    ASSERT_TRUE(feed.step(live));
    ExpectShowing(live, expected);
  }
  EXPECT_FALSE(live.jump_pending());
  EXPECT_FALSE(feed.step(live));
}

// `{` and `}` step the playing speed through 0.1x .. 4x; the paced file plays at it (the fake
// clock's waits: frame periods divided by the speed), and the state line says it.
TEST_F(LivePlaybackTest, SpeedKeysSetThePacedFilesRateFromATenthToFourTimes) {
  const std::string video = WriteVideo(40);
  Play(video);
  LiveController live(SceneConfig(), Options());
  LiveFeed feed(*source_, seekable_);
  ASSERT_TRUE(feed.step(live));
  Key(live, '}');
  EXPECT_EQ(live.speed(), 2.0);
  Key(live, '}');
  Key(live, '}');
  EXPECT_EQ(live.speed(), 4.0);  // The fastest.
  const auto next_wait = [&] {
    const auto before = clock_.now;
    EXPECT_TRUE(feed.step(live));
    clock_.now = clock_.waits.back();
    return std::chrono::duration<double>(clock_.waits.back() - before).count();
  };
  next_wait();  // The new speed starts from the last frame shown.
  EXPECT_NEAR(next_wait(), 1.0 / 30 / 4, 1e-6);
  for (int i = 0; i < 8; ++i) Key(live, '{');
  EXPECT_NEAR(live.speed(), 0.1, 1e-12);  // The slowest.
  next_wait();
  EXPECT_NEAR(next_wait(), 1.0 / 30 / 0.1, 1e-6);
  EXPECT_NE(live.message().find("speed 0.10x"), std::string::npos) << live.message();
}

// Zoom about the pointer (+ / -), pan (right-drag), and every click or drag on the zoomed view
// lands on the image pixels under it: a colour pick on blue and a reselection box.
TEST_F(LiveControllerTest, ZoomedViewKeepsThePointedPixelAndClicksAndDragsMapThroughIt) {
  LiveController live(SceneConfig(), Options());
  SceneTruth truth;
  for (int i = 0; i < 3; ++i) truth = Feed(live, i);
  const cv::Point2d blue = *truth.markers[1].centroid_px;
  const cv::Point2d pointer = live.to_view(blue);
  live.on_event(UiEvent::Mouse(UiEvent::Type::kMouseMove, pointer.x, pointer.y));
  for (int i = 0; i < 9; ++i) live.on_event(UiEvent::Key(i % 2 == 0 ? '+' : '='));
  EXPECT_NEAR(live.zoom().zoom, std::pow(1.25, 9.0), 1e-9);
  // The pointed image point stays under the pointer (the image's edge allowing).
  EXPECT_NEAR(live.to_view(blue).x, pointer.x, 1e-6);
  EXPECT_NEAR(live.to_view(blue).y, pointer.y, 1e-6);
  const double scale = live.to_view({1, 0}).x - live.to_view({0, 0}).x;
  EXPECT_NEAR(scale, live.zoom().zoom, 1e-9);
  // The canvas shows the image enlarged: blue's pixels around its centre.
  const cv::Mat canvas = live.canvas().clone();
  const cv::Vec3b shown = canvas.at<cv::Vec3b>(cvRound(pointer.y + 3 * scale), cvRound(pointer.x + 3 * scale));
  EXPECT_GT(shown[0], shown[2] + 60) << "blue under the pointer, 3 image px off the centre";

  // A click through the zoom picks blue's colour (the box around the image pixel clicked).
  live.on_event(UiEvent::Key('3'));  // Active: green; the click goes to blue, found under it.
  Click(live, live.to_view(blue + cv::Point2d(0.3, 0.3)));
  const auto& colour = live.config().markers[1].params.get<ColourParams>();
  ASSERT_TRUE(colour.roi) << live.message();
  EXPECT_NEAR(colour.roi->x + colour.roi->width / 2.0, blue.x, 1.0);
  EXPECT_NEAR(colour.roi->y + colour.roi->height / 2.0, blue.y, 1.0);
  // A box dragged on the zoomed view, in image pixels.
  Drag(live, live.to_view(blue - cv::Point2d(6, 6)), live.to_view(blue + cv::Point2d(7, 7)));
  EXPECT_NE(live.message().find("blue: reselected in [" + std::to_string(cvRound(blue.x - 6)) + ", " +
                                std::to_string(cvRound(blue.y - 6))),
            std::string::npos)
      << live.message();

  // Right-drag pans by the image pixels the pointer moved over; z shows the whole image again.
  const ViewZoom before = live.zoom();
  live.on_event({UiEvent::Type::kPanDown, pointer, 0, 0, 0, false});
  live.on_event({UiEvent::Type::kPanMove, pointer + cv::Point2d(scale * 4, 0), 0, 0, 0, false});
  EXPECT_NEAR(live.zoom().origin_px.x, before.origin_px.x - 4, 1e-6);
  live.on_event(UiEvent::Key('-'));
  EXPECT_NEAR(live.zoom().zoom, before.zoom / 1.25, 1e-9);
  live.on_event(UiEvent::Key('z'));
  EXPECT_EQ(live.zoom().zoom, 1.0);
  EXPECT_NEAR(live.to_view(blue).x, blue.x, 1e-9);
}

// `u` takes back the last reselection or range change, as the marker was; nothing left says so.
TEST_F(LiveControllerTest, UndoRestoresTheMarkerAsItWasBeforeTheLastReselectionOrRangeChange) {
  LiveController live(SceneConfig(), Options());
  SceneTruth truth;
  for (int i = 0; i < 3; ++i) truth = Feed(live, i);
  live.on_event(UiEvent::Key('m'));  // sad: templates cut where the markers are.
  const TemplateParams cut = live.config().markers[1].params.get<TemplateParams>();
  const cv::Point2d blue = *truth.markers[1].centroid_px;
  Drag(live, blue - cv::Point2d(9, 11), blue + cv::Point2d(12, 10));
  ASSERT_NE(live.message().find("blue: reselected"), std::string::npos) << live.message();
  EXPECT_NE(*live.config().markers[1].params.get<TemplateParams>().rect, *cut.rect);
  EXPECT_EQ(live.undo_depth(), 1u);
  live.on_event(UiEvent::Key('u'));
  EXPECT_NE(live.message().find("undone: reselection of blue"), std::string::npos) << live.message();
  const TemplateParams back = live.config().markers[1].params.get<TemplateParams>();
  EXPECT_EQ(*back.rect, *cut.rect);
  EXPECT_EQ(cv::norm(back.image, cut.image, cv::NORM_INF), 0.0);
  const SceneTruth next = Feed(live, 3);  // The old template tracks blue on.
  ExpectAt(live, 1, next, 0.5);
  live.on_event(UiEvent::Key('u'));
  EXPECT_NE(live.message().find("nothing to undo"), std::string::npos);
}

// A recording reproduces under `track` (same rows, found flags and positions) when undo is among
// its edits, whether it was started paused, after a method change, or at the end of the input.
TEST_F(LiveFileTest, RecordingsWithUndoAmongTheEditsReproduceUnderTrackStartedPausedAtTheEndAfterAMethodChange) {
  const std::string video = WriteVideo(30);
  {  // Started paused, after a method change, a reselection and its undo; more while recording.
    FakeClock clock;
    std::unique_ptr<PacedFrameSource> source = PlayFile(video, clock);
    LiveController live(SceneConfig(), FileOptions());
    LiveFeed feed(*source);
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(feed.step(live));
    live.on_event(UiEvent::Key(' '));
    live.on_event(UiEvent::Key('m'));
    const cv::Point2d blue = *live.last_result()->markers[1].observation.position_px;
    Drag(live, blue - cv::Point2d(9, 11), blue + cv::Point2d(12, 10));
    live.on_event(UiEvent::Key('u'));
    ASSERT_NE(live.message().find("undone"), std::string::npos) << live.message();
    live.on_event(UiEvent::Key('r'));
    ASSERT_TRUE(live.recording()) << live.message();
    live.on_event(UiEvent::Key(' '));
    for (int i = 0; i < 4; ++i) ASSERT_TRUE(feed.step(live));
    const cv::Point2d green = *live.last_result()->markers[2].observation.position_px;
    Drag(live, green - cv::Point2d(10, 9), green + cv::Point2d(11, 12));
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(feed.step(live));
    live.on_event(UiEvent::Key('u'));
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(feed.step(live));
    live.on_event(UiEvent::Key('m'));  // A method change while recording: ssd.
    for (int i = 0; i < 2; ++i) ASSERT_TRUE(feed.step(live));
    live.on_event(UiEvent::Key('r'));
    ExpectTrackReproduces(live, 13);
  }
  {  // At the end: colour ranges moved (trackbar) and undone, a pick undone, one row recorded.
    FakeClock clock;
    std::unique_ptr<PacedFrameSource> source = PlayFile(video, clock);
    LiveController live(SceneConfig(), FileOptions());
    LiveFeed feed(*source);
    while (feed.step(live)) {
    }
    ASSERT_TRUE(live.ended());
    live.on_event(UiEvent::Trackbar(0, 100));
    live.on_event(UiEvent::Key('u'));
    Click(live, *live.last_result()->markers[2].observation.position_px);
    live.on_event(UiEvent::Trackbar(5, 200));
    live.on_event(UiEvent::Key('u'));
    live.on_event(UiEvent::Key('r'));
    ASSERT_TRUE(live.recording()) << live.message();
    live.on_event(UiEvent::Key('r'));
    ExpectTrackReproduces(live, 1);
  }
}

TEST(LivePointer, ClicksWithinTheSlopDragsBeyondItAndNothingWithoutAPressInTheImage) {
  LivePointer pointer(4);
  EXPECT_EQ(pointer.up({10, 10}, true).kind, PointerGesture::Kind::kNone);  // No press.
  EXPECT_FALSE(pointer.down({10, 10}, false));  // Outside the image: no gesture starts.
  EXPECT_EQ(pointer.up({10, 10}, true).kind, PointerGesture::Kind::kNone);
  ASSERT_TRUE(pointer.down({10, 10}, true));
  EXPECT_TRUE(pointer.move({12, 11}, false));
  EXPECT_EQ(*pointer.pointer(), cv::Point2d(12, 11));
  const PointerGesture click = pointer.up({13, 10}, true);
  EXPECT_EQ(click.kind, PointerGesture::Kind::kClick);
  EXPECT_EQ(click.press, cv::Point2d(10, 10));
  EXPECT_FALSE(pointer.press() || pointer.pointer());
  ASSERT_TRUE(pointer.down({30.4, 40.6}, true));
  const PointerGesture drag = pointer.up({10.2, 20.5}, true);
  EXPECT_EQ(drag.kind, PointerGesture::Kind::kDrag);
  EXPECT_EQ(drag.box, cv::Rect(cv::Point(10, 20), cv::Point(30, 41)));
  // Released outside the image: the release point is the press (scale mode takes it).
  ASSERT_TRUE(pointer.down({5, 5}, true));
  EXPECT_EQ(pointer.up({-50, 5}, false).release, cv::Point2d(5, 5));
  EXPECT_FALSE(pointer.move({7, 7}, false));  // No button: not followed ...
  EXPECT_TRUE(pointer.move({7, 7}, true));    // ... unless asked (scale mode).
}

}  // namespace
}  // namespace softsight

namespace softsight {
namespace {

// The case a bench user met: paused on frame 250 of synth's scene, switched to ZNCC (templates cut
// where the colour markers were), then seeked on. A jump searches every frame afresh, and in
// gray the three discs look alike: each template must still find its own disc, by its colour.
TEST(LiveSeek, AfterASwitchToZnccEachSeekFindsEveryMarkerOnItsOwnDisc) {
  SyntheticScene scene{SceneOptions{}};
  LiveController live(testing::LiveTestConfig(), LiveOptions{});
  const auto show = [&](int index, FrameOrder order) {
    Frame frame;
    SceneTruth truth = scene.render(index, frame.image);
    frame.index = index;
    frame.time_s = truth.time_s;
    live.on_frame(frame, SteadyClock::now(), order);
    return truth;
  };
  for (int i = 0; i < 3; ++i) show(i, FrameOrder::kNext);
  live.on_event(UiEvent::Key(' '));  // Pause.
  show(250, FrameOrder::kJump);
  for (int k = 0; k < 3; ++k) live.on_event(UiEvent::Key('m'));  // colour -> sad -> ssd -> zncc
  ASSERT_EQ(live.message(), "method: zncc");
  for (int target : {279, 260, 120, 299, 10}) {
    const SceneTruth truth = show(target, FrameOrder::kJump);
    for (int m = 0; m < 3; ++m) {
      const Observation& o = live.last_result()->markers[m].observation;
      ASSERT_TRUE(o.found()) << truth.markers[m].name << " in frame " << target << ": "
                             << MarkerStatusName(o.status());
      EXPECT_LT(cv::norm(*o.position_px - *truth.markers[m].centroid_px), 0.5)
          << truth.markers[m].name << " in frame " << target;
    }
  }
}

}  // namespace
}  // namespace softsight
