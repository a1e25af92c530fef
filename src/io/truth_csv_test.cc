#include "softsight/io/truth_csv.h"

#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;

std::vector<std::string> NamesOf(const SceneOptions& options) {
  std::vector<std::string> names;
  for (const SceneMarker& m : options.markers) names.push_back(m.name);
  return names;
}

std::string ErrorOf(const std::string& csv, const std::vector<std::string>& wanted) {
  const testing::TempDir dir;
  testing::WriteTextFile(dir.file("truth.csv"), csv);
  try {
    ReadTruthCsv(dir.file("truth.csv"), wanted);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// What the writer writes, the reader reads: every field of every frame (to the 6 decimals the
// file has), hidden markers and absent measurements included.
TEST(TruthCsv, RendersWrittenAndReadBackAreTheScenesTruth) {
  SceneOptions options;
  options.size = cv::Size(320, 240);
  options.frame_count = 8;
  options.length_px = 150;
  options.width_px = 20;
  options.marker_radius_px = 6;
  Occluder cover;  // All of frame 5 hidden.
  cover.rect_px = cv::Rect2d(0, 0, 320, 240);
  cover.first_frame = 5;
  cover.last_frame = 5;
  SyntheticScene scene(options, NoiseOptions{}, RenderOptions{}, {cover});
  const std::vector<std::string> names = NamesOf(options);
  const testing::TempDir dir;
  std::vector<SceneTruth> written;
  {
    TruthCsvWriter writer(dir.file("truth.csv"), TruthColumns(names));
    cv::Mat image;
    for (int i = 0; i < scene.frame_count(); ++i) {
      written.push_back(scene.render(i, image));
      writer.write(written.back());
    }
  }
  const TruthCsv read = ReadTruthCsv(dir.file("truth.csv"), names);
  EXPECT_EQ(read.markers, names);
  EXPECT_TRUE(read.missing.empty());
  ASSERT_EQ(read.frames.size(), written.size());
  constexpr double kSixDecimals = 5e-7;
  const auto expect_same = [&](const std::optional<double>& a, const std::optional<double>& b,
                               const std::string& what) {
    ASSERT_EQ(a.has_value(), b.has_value()) << what;
    if (a) {
      EXPECT_NEAR(*a, *b, kSixDecimals) << what;
    }
  };
  for (size_t f = 0; f < written.size(); ++f) {
    const SceneTruth& w = written[f];
    const SceneTruth& r = read.frames[f];
    const std::string at = "frame " + std::to_string(f);
    EXPECT_EQ(r.frame_index, w.frame_index) << at;
    EXPECT_NEAR(r.time_s, w.time_s, kSixDecimals) << at;
    EXPECT_NEAR(r.bend_deg, w.bend_deg, kSixDecimals) << at;
    expect_same(r.centreline_radius_px, w.centreline_radius_px, at + " centreline radius");
    ASSERT_EQ(r.markers.size(), w.markers.size()) << at;
    for (size_t m = 0; m < w.markers.size(); ++m) {
      EXPECT_EQ(r.markers[m].name, w.markers[m].name);
      ASSERT_EQ(r.markers[m].centroid_px.has_value(), w.markers[m].centroid_px.has_value()) << at;
      if (w.markers[m].centroid_px) {
        EXPECT_NEAR(r.markers[m].centroid_px->x, w.markers[m].centroid_px->x, kSixDecimals) << at;
        EXPECT_NEAR(r.markers[m].centroid_px->y, w.markers[m].centroid_px->y, kSixDecimals) << at;
      }
      EXPECT_NEAR(r.markers[m].visible_fraction, w.markers[m].visible_fraction, kSixDecimals) << at;
    }
    expect_same(r.measurement.angle_deg, w.measurement.angle_deg, at + " angle");
    expect_same(r.measurement.chord_px, w.measurement.chord_px, at + " chord");
    expect_same(r.measurement.sagitta_px, w.measurement.sagitta_px, at + " sagitta");
    expect_same(r.measurement.radius_px, w.measurement.radius_px, at + " radius");
    expect_same(r.measurement.arc_length_px, w.measurement.arc_length_px, at + " arc length");
    expect_same(r.measurement.tip_disp_px, w.measurement.tip_disp_px, at + " tip displacement");
  }
  EXPECT_FALSE(read.frames[5].markers[0].centroid_px) << "frame 5 is covered";
  EXPECT_EQ(read.frames[5].markers[0].visible_fraction, 0.0);
}

TEST(TruthCsv, ReadsTheWantedMarkersItHasAndNamesTheOthers) {
  const testing::TempDir dir;
  testing::WriteTextFile(dir.file("t.csv"), "frame,tip_x,tip_y\n0,1.5,2\n3,,\n");
  const TruthCsv read = ReadTruthCsv(dir.file("t.csv"), {"base", "tip"});
  EXPECT_EQ(read.markers, std::vector<std::string>{"tip"});
  EXPECT_EQ(read.wanted_index, std::vector<size_t>{1});
  EXPECT_EQ(read.missing, std::vector<std::string>{"base"});
  ASSERT_EQ(read.frames.size(), 2u);
  EXPECT_EQ(read.frames[1].frame_index, 3);
  ASSERT_TRUE(read.frames[0].markers[0].centroid_px);
  EXPECT_EQ(read.frames[0].markers[0].centroid_px->x, 1.5);
  EXPECT_EQ(read.frames[0].markers[0].visible_fraction, 1.0) << "no _visible column: visible";
  EXPECT_FALSE(read.frames[1].markers[0].centroid_px);
  EXPECT_EQ(read.frames[1].markers[0].visible_fraction, 0.0);
}

TEST(TruthCsv, BadFilesAreOneErrorNamingFileAndLine) {
  EXPECT_THAT(ErrorOf("tip_x,tip_y\n1,2\n", {"tip"}), HasSubstr("no 'frame' column"));
  EXPECT_THAT(ErrorOf("frame,red_x,red_y\n0,1,2\n", {"tip"}), HasSubstr("the truth has: red"));
  EXPECT_THAT(ErrorOf("frame,tip_x,tip_y\n0,1,2\n0,1,2\n", {"tip"}),
              HasSubstr("truth.csv: line 3: frame 0 is given twice"));
  EXPECT_THAT(ErrorOf("frame,tip_x,tip_y\n0.5,1,2\n", {"tip"}),
              HasSubstr("line 2: 'frame' must be a frame index"));
  EXPECT_THAT(ErrorOf("frame,tip_x,tip_y,tip_visible\n0,1,2,1.5\n", {"tip"}),
              HasSubstr("line 2: tip_visible must lie within 0..1"));
  EXPECT_THAT(ErrorOf("frame,tip_x,tip_y\n", {"tip"}), HasSubstr("truth.csv: no rows"));
}

}  // namespace
}  // namespace softsight
