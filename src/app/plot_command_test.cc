// `softsight plot` on rendered output: runs overlaid with the renderer's truth, the radius and x/y
// panels, and axes that do not magnify noise below the tracker's precision.
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "app/scene_config.h"
#include "app/synth_command.h"
#include "app/track_command.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/io/plot.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;

struct Rendered {
  std::string video, truth, csv;
  std::vector<SceneTruth> truths;
};

// A short bending clip, its truth CSV and the track CSV of the config a person would write.
Rendered RenderAndTrack(const testing::TempDir& dir, double max_bend_deg) {
  Rendered r;
  SynthOptions synth;
  synth.scene.size = cv::Size(320, 240);
  synth.scene.length_px = 160;
  synth.scene.width_px = 30;
  synth.scene.frame_count = 30;
  synth.scene.max_bend_deg = max_bend_deg;
  synth.noise.sigma = 3;
  synth.out = r.video = dir.file("run.avi");
  synth.truth_csv = r.truth = dir.file("truth.csv");
  synth.quiet = true;
  RunSynth(synth, &r.truths);
  TrackingConfig config;
  for (const SceneMarker& m : synth.scene.markers) {
    MarkerSpec spec;
    spec.name = m.name;
    spec.params = ThresholdsFor(m.bgr);
    config.markers.push_back(spec);
  }
  config.measure = SceneMeasureOptions(synth.scene);
  SaveTrackingConfig(config, dir.file("markers.yaml"));
  TrackOptions track;
  track.config_file = dir.file("markers.yaml");
  track.source.input = r.video;
  track.csv_file = r.csv = dir.file("run.csv");
  track.quiet = true;
  RunTrack(track);
  return r;
}

double Span(const CsvTable& table, const std::string& column) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& v : table.values[*table.find(column)]) {
    if (v) {
      lo = std::min(lo, *v);
      hi = std::max(hi, *v);
    }
  }
  return hi - lo;
}

TEST(PlotCommand, RunsOverlaidWithTheTruthInRadiusAndXyPanels) {
  testing::TempDir dir;
  const Rendered r = RenderAndTrack(dir, 160);
  // The same run twice (a second CSV is a second run, not an error) and the truth.
  std::filesystem::copy_file(r.csv, dir.file("again.csv"));
  PlotData data;
  data.runs = {ReadCsvTable(r.csv), ReadCsvTable(dir.file("again.csv"))};
  data.truth = ReadCsvTable(r.truth);
  PlotOptions options;
  options.panels = {"angle", "radius", "xy"};
  const PlotLayout layout = ComputePlotLayout(data, options);
  ASSERT_EQ(layout.panels.size(), 2u + 6u);  // angle, radius, x and y of three markers.
  EXPECT_EQ(layout.panels[1].y_label, "radius of curvature [px]");
  EXPECT_EQ(layout.panels[2].y_label, "red x [px]");
  EXPECT_EQ(layout.panels[7].y_label, "green y [px]");
  for (const PlotPanel& panel : layout.panels) {
    ASSERT_EQ(panel.series.size(), 3u) << panel.y_label;
    EXPECT_EQ(panel.series[0].label, "run");
    EXPECT_EQ(panel.series[1].label, "again");
    EXPECT_EQ(panel.series[2].label, "truth");
    EXPECT_EQ(panel.series[2].table, 2u);
    EXPECT_EQ(panel.series[2].bgr, cv::Scalar(0, 0, 0));
    EXPECT_NE(panel.series[0].bgr, panel.series[1].bgr) << "runs are told apart";
  }
  // The plotted truth is the renderer's: green's x in frame 20 where the truth puts it.
  const PlotPanel& green_x = layout.panels[6];
  const CsvTable& truth = *data.truth;
  EXPECT_NEAR(*PlotSeriesValue(truth, green_x.series[2], 20), r.truths[20].markers[2].centroid_px->x,
              1e-5);
  // The radius of the nearly straight first frames (25 arc lengths or more) is a gap, not the
  // axis: the axis covers the bent frames' radii.
  const PlotPanel& radius = layout.panels[1];
  EXPECT_FALSE(PlotSeriesValue(data.runs[0], radius.series[0], 0).has_value());
  EXPECT_LT(radius.y_max, 25 * 160 * 1.1);
  EXPECT_GT(radius.y_max, *r.truths.back().measurement.radius_px);

  const std::string png = dir.file("cmp.png");
  WritePlot({r.csv, dir.file("again.csv")}, r.truth, png, options);
  const cv::Mat image = cv::imread(png);
  EXPECT_EQ(image.size(), layout.size);
}

TEST(PlotCommand, ASteadyArcLengthIsNotMagnifiedBeyondTheTrackersPrecision) {
  testing::TempDir dir;
  const Rendered r = RenderAndTrack(dir, 120);
  const CsvTable table = ReadCsvTable(r.csv);
  // The arc length of a bending actuator with markers at fixed body places stays constant: what
  // the CSV shows is centroid noise, well under a pixel.
  ASSERT_LT(Span(table, "arc_length_px"), 0.6);
  PlotOptions options;
  options.panels = {"arc"};
  const PlotLayout layout = ComputePlotLayout(table, options);
  EXPECT_GE(layout.panels[0].y_max - layout.panels[0].y_min, options.min_span_px);
  options.min_span_px = 0;  // The old behaviour: the axis hugs the noise.
  const PlotLayout hugging = ComputePlotLayout(table, options);
  EXPECT_LT(hugging.panels[0].y_max - hugging.panels[0].y_min, 1.0);
  // An angle that moves keeps its own span.
  options.panels = {"angle"};
  const PlotLayout angle = ComputePlotLayout(table, options);
  EXPECT_GE(angle.panels[0].y_max - angle.panels[0].y_min, Span(table, "angle_deg"));
}

TEST(PlotCommand, BadInputsAreOneErrorNamingTheFileOrPanel) {
  testing::TempDir dir;
  const Rendered r = RenderAndTrack(dir, 120);
  PlotOptions options;
  options.panels = {"curvature"};
  try {
    WritePlot({r.csv}, std::nullopt, dir.file("x.png"), options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown panel 'curvature'"));
  }
  options.panels = {};
  try {
    WritePlot({r.csv, dir.file("missing.csv")}, std::nullopt, dir.file("x.png"), options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("missing.csv"));
  }
  // The command line: two CSVs and a truth are accepted; a bad one is one line and exit 2.
  const std::string cli = testing::SoftsightBinary() + " plot " + r.csv + " " + r.csv +
                          " --truth " + r.truth + " -o " + dir.file("ok.png") + " > /dev/null";
  EXPECT_EQ(WEXITSTATUS(std::system(cli.c_str())), 0);
  const std::string bad = testing::SoftsightBinary() + " plot " + r.csv + " " + r.video + " -o " +
                          dir.file("bad.png") + " 2> " + dir.file("err.txt");
  EXPECT_EQ(WEXITSTATUS(std::system(bad.c_str())), 2);
  const std::string err = testing::ReadTextFile(dir.file("err.txt"));
  EXPECT_THAT(err, HasSubstr("run.avi"));
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1);
}

}  // namespace
}  // namespace softsight
