// A kind of marker added the way docs/architecture.md ("A new kind of marker") says: a parameter
// struct with its option rows, a Tracker, and a TrackerKind registered with the registry; no
// other file knows it. The config reads, checks, writes and documents its keys, and a
// TrackingSession tracks it, as it does the built-in kinds.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "config/config_sections.h"  // DocumentConfig
#include "core/test_util.h"
#include "softsight/config/config.h"
#include "softsight/core/error.h"
#include "softsight/core/option_table.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;

// ---- The toy kind: a dark spot, the centroid of the pixels darker than a gray level ------------

struct DarkSpotParams {
  int max_gray = 60;        // A pixel at or below it is the spot's.
  double min_area_px = 20;  // Fewer such pixels: not found.

  bool Check(std::string* problem) const;
};

const OptionTable<DarkSpotParams>& DarkSpotOptions() {
  static const OptionTable<DarkSpotParams> table = {
      IntOption<DarkSpotParams>("dark.max_gray", &DarkSpotParams::max_gray)
          .Range(0, 254)
          .Doc("a pixel at or below this gray level belongs to the spot"),
      DoubleOption<DarkSpotParams>("dark.min_area", &DarkSpotParams::min_area_px)
          .AtLeast(1)
          .Unit("px")
          .Doc("fewer dark pixels: the spot is not found"),
  };
  return table;
}

bool DarkSpotParams::Check(std::string* problem) const {
  if (const auto bad = CheckOptions(DarkSpotOptions(), *this)) return Fail(problem, *bad);
  return true;
}

class DarkSpotTracker final : public Tracker {
 public:
  explicit DarkSpotTracker(const DarkSpotParams& params) : params_(params) {}
  void init(const cv::Mat& /*frame_bgr*/, const cv::Rect& /*hint*/) override {}
  bool start(const Frame& /*frame*/) override { return true; }
  Observation update(const cv::Mat& frame_bgr) override {
    cv::cvtColor(frame_bgr, gray_, cv::COLOR_BGR2GRAY);
    cv::threshold(gray_, dark_, params_.max_gray, 255, cv::THRESH_BINARY_INV);
    const cv::Moments m = cv::moments(dark_, /*binaryImage=*/true);
    if (m.m00 < params_.min_area_px) return Observation::NotFound(MarkerStatus::kLost);
    Observation found;
    found.position_px = cv::Point2d(m.m10 / m.m00, m.m01 / m.m00);
    found.score = m.m00;
    return found;
  }
  void reset() override {}

 private:
  DarkSpotParams params_;
  cv::Mat gray_, dark_;  // Reused frame to frame.
};

class DarkSpotKind final : public TrackerKind {
 public:
  std::string name() const override { return "dark spot"; }
  // One method: method_of and select_method keep their defaults.
  std::vector<std::string> methods() const override { return {"dark"}; }
  MarkerParams defaults() const override { return DarkSpotParams{}; }
  const OptionTable<MarkerParams>& options() const override {
    static const OptionTable<MarkerParams> rows = KindOptions(DarkSpotOptions());
    return rows;
  }
  bool check(const MarkerParams& params, std::string* problem) const override {
    return params.get<DarkSpotParams>().Check(problem);
  }
  std::unique_ptr<Tracker> create(const MarkerParams& params) const override {
    return std::make_unique<DarkSpotTracker>(params.get<DarkSpotParams>());
  }
  bool needs_colour(const MarkerParams& /*params*/) const override { return false; }
  double size_hint_px(const MarkerParams& params) const override {
    return std::sqrt(params.get<DarkSpotParams>().min_area_px);
  }
  MarkerSelection selection() const override { return MarkerSelection::kDragBox; }
  void remember_selection(MarkerParams&, const Frame&, const cv::Rect&) const override {}
  void start_in(MarkerParams&, const cv::Rect&) const override {}
  void start_by(MarkerParams&, int64_t) const override {}
};

// Registered once per test program, before the first config that names it is read.
void RegisterDarkSpot() {
  static const bool registered = [] {
    RegisterTrackerKind<DarkSpotParams>(std::make_unique<DarkSpotKind>());
    return true;
  }();
  (void)registered;
}

TrackingConfig ReadText(const std::string& text) {
  return ReadTrackingConfig(YAML::Load(text), "toy.yaml");
}

std::string ErrorOf(const std::string& text) {
  try {
    ReadText(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// A white frame with a black disc of radius 6 px at `centre`.
Frame SpotFrame(int index, const cv::Point2d& centre) {
  Frame frame;
  frame.index = index;
  frame.time_s = index / 30.0;
  frame.image = cv::Mat(120, 160, CV_8UC3, cv::Scalar::all(230));
  cv::circle(frame.image, cv::Point(cvRound(centre.x), cvRound(centre.y)), 6, cv::Scalar::all(10),
             cv::FILLED);
  return frame;
}

TEST(MarkerKind, ARegisteredKindIsAMethodWithItsKeysReadCheckedWrittenAndDocumented) {
  RegisterDarkSpot();
  const std::vector<std::string> methods = TrackerMethods();
  EXPECT_NE(std::find(methods.begin(), methods.end(), "dark"), methods.end());

  const TrackingConfig config = ReadText(
      "markers:\n  - name: spot\n    method: dark\n    dark: {max_gray: 40, min_area: 12}\n");
  ASSERT_EQ(config.markers.size(), 1u);
  const auto* spot = config.markers[0].params.get_if<DarkSpotParams>();
  ASSERT_NE(spot, nullptr);
  EXPECT_EQ(spot->max_gray, 40);
  EXPECT_EQ(spot->min_area_px, 12);
  EXPECT_EQ(TrackerMethodName(config.markers[0].params), "dark");
  EXPECT_FALSE(NeedsColour(config)) << "its tracker takes gray frames";

  // Its rows give the range and the message, naming file, marker and key.
  EXPECT_THAT(ErrorOf("markers:\n  - name: spot\n    method: dark\n    dark: {max_gray: 300}\n"),
              HasSubstr("toy.yaml:4:"));
  EXPECT_THAT(ErrorOf("markers:\n  - name: spot\n    method: dark\n    dark: {max_gray: 300}\n"),
              HasSubstr("markers[0].dark.max_gray: 300 must lie within 0..254"));
  EXPECT_THAT(ErrorOf("markers:\n  - name: spot\n    method: dark\n    dark: {max_grey: 3}\n"),
              HasSubstr("max_grey"));

  // Written and read back the same; a colour marker's file keeps its dark keys for `--method dark`.
  const testing::TempDir dir;
  SaveTrackingConfig(config, dir.file("saved.yaml"));
  const TrackingConfig again = LoadTrackingConfig(dir.file("saved.yaml"));
  ASSERT_NE(again.markers[0].params.get_if<DarkSpotParams>(), nullptr);
  EXPECT_EQ(again.markers[0].params.get<DarkSpotParams>().max_gray, 40);
  EXPECT_EQ(again.markers[0].params.get<DarkSpotParams>().min_area_px, 12);
  const TrackingConfig as_colour = LoadTrackingConfig(dir.file("saved.yaml"), "colour");
  EXPECT_TRUE(as_colour.markers[0].params.holds<ColourParams>());
  ASSERT_EQ(as_colour.params_aside.at("spot").size(), 1u);
  EXPECT_EQ(as_colour.params_aside.at("spot")[0].get<DarkSpotParams>().max_gray, 40);

  const std::string doc = DocumentConfig();
  EXPECT_THAT(doc, HasSubstr("max_gray: 60"));
  EXPECT_THAT(doc, HasSubstr("a pixel at or below this gray level belongs to the spot"));
}

TEST(MarkerKind, ASessionTracksARegisteredKindFrameByFrame) {
  RegisterDarkSpot();
  const TrackingConfig config =
      ReadText("markers:\n  - name: spot\n    method: dark\n    dark: {max_gray: 100}\n");
  TrackingSession session(config);
  for (int i = 0; i < 12; ++i) {
    // Two pixels a frame to the right: the centroid of a rasterised disc is its centre.
    const cv::Point2d centre(40.0 + 2 * i, 60.0);
    const FrameResult& result = session.process(SpotFrame(i, centre));
    ASSERT_EQ(result.markers.size(), 1u);
    const Observation& seen = result.markers[0].observation;
    ASSERT_TRUE(seen.found()) << "frame " << i << ": " << MarkerStatusName(seen.status());
    EXPECT_NEAR(seen.position_px->x, centre.x, 1e-9) << "frame " << i;
    EXPECT_NEAR(seen.position_px->y, centre.y, 1e-9) << "frame " << i;
  }
  // No spot: not found, never a stale position.
  Frame blank = SpotFrame(12, {0, 0});
  blank.image.setTo(cv::Scalar::all(230));
  EXPECT_FALSE(session.process(blank).markers[0].observation.found());
}

}  // namespace
}  // namespace softsight
