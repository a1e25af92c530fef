#include "app/evaluate_command.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/synth_command.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;

// A small bending scene, 40 frames: seconds for every method.
EvaluateOptions SmallScene() {
  EvaluateOptions options;
  options.scene.size = cv::Size(320, 240);
  options.scene.frame_count = 40;
  options.scene.length_px = 160;
  options.scene.width_px = 30;
  options.scene.marker_radius_px = 9;
  options.scene.max_bend_deg = 120;
  options.quiet = true;
  return options;
}

const MethodResult& Find(const EvaluateReport& report, const std::string& label) {
  for (const MethodResult& m : report.methods) {
    if (m.label() == label) return m;
  }
  ADD_FAILURE() << "no row " << label;
  static const MethodResult kNone;
  return kNone;
}

TEST(EvaluateTest, ColourIsSubPixelWithoutMissesAndZnccColourKeepsEveryMarker) {
  EvaluateOptions options = SmallScene();
  options.methods = {"colour", "zncc"};
  options.modes = {"colour"};
  const EvaluateReport report = RunEvaluate(options);
  SCOPED_TRACE(FormatEvaluateMarkdown(report));
  ASSERT_EQ(report.methods.size(), 2u);
  EXPECT_EQ(report.frames, 40);

  const MethodResult& colour = Find(report, "colour");
  EXPECT_EQ(colour.visible, 3 * 40);
  EXPECT_EQ(colour.misses, 0);
  EXPECT_EQ(colour.found_visible, colour.visible);
  ASSERT_TRUE(colour.centroid_rms_px.has_value());
  EXPECT_LT(*colour.centroid_rms_px, 0.1);
  ASSERT_TRUE(colour.angle_rms_deg.has_value());
  EXPECT_EQ(colour.angle_frames, 40);
  EXPECT_LT(*colour.angle_rms_deg, 0.3);

  const MethodResult& zncc = Find(report, "zncc colour");
  EXPECT_EQ(zncc.misses, 0);
  EXPECT_EQ(zncc.found_visible, 3 * 40);
  ASSERT_TRUE(zncc.centroid_rms_px && zncc.precision_rms_px);
  // The dragged template is off by up to half a pixel per axis; removing that constant offset
  // leaves the tracking precision, which is much finer.
  EXPECT_LT(*zncc.centroid_rms_px, 0.75);
  EXPECT_LT(*zncc.precision_rms_px, 0.3);
  EXPECT_LE(*zncc.precision_rms_px, *zncc.centroid_rms_px + 1e-9);
  EXPECT_GT(zncc.proc_ms_median, 0.0);
  EXPECT_GE(zncc.proc_ms_p99, zncc.proc_ms_median);
}

// Every found position carries its sigma, and the sigma is calibrated: on a noisy, blurred
// scene at least 99 % of the found positions lie within 3 sigma of the truth along both axes and
// none beyond 5 (tests/real/check_real.py checks the same on real and physically rendered
// footage).
TEST(EvaluateTest, EveryFoundPositionCarriesACalibratedSigma) {
  EvaluateOptions options = SmallScene();
  options.noise.sigma = 6;
  options.noise.blur_sigma_px = 1;
  options.methods = {"colour", "sad", "zncc"};
  options.modes = {"gray", "colour"};
  const EvaluateReport report = RunEvaluate(options);
  SCOPED_TRACE(FormatEvaluateMarkdown(report));
  for (const MethodResult& m : report.methods) {
    EXPECT_GT(m.found_visible, 100) << m.label();
    EXPECT_EQ(m.with_sigma, m.found_visible) << m.label();
    EXPECT_GE(m.within_3_sigma, 0.99 * m.with_sigma) << m.label();
    EXPECT_EQ(m.beyond_5_sigma, 0) << m.label();
  }
}

TEST(EvaluateTest, FullyOccludedMarkerIsNeverReported) {
  EvaluateOptions options = SmallScene();
  options.scene.frame_count = 30;
  options.methods = {"colour", "sad", "ssd", "zncc"};
  options.modes = {"gray", "colour"};
  // A grey card over the tip marker's whole path during frames 10..19 (found from the truth of an
  // unoccluded rendering), so it is fully hidden there while the other markers stay in view.
  constexpr int kFirst = 10, kLast = 19;
  SyntheticScene plain(options.scene);
  cv::Mat image;
  cv::Rect2d path;
  for (int i = kFirst; i <= kLast; ++i) {
    const cv::Point2d tip = *plain.render(i, image).markers.back().centroid_px;
    const double r = options.scene.marker_radius_px + 2;
    const cv::Rect2d around(tip.x - r, tip.y - r, 2 * r, 2 * r);
    path = i == kFirst ? around : (path | around);
  }
  Occluder card;
  card.rect_px = cv::Rect2d(std::floor(path.x), std::floor(path.y), std::ceil(path.width) + 1,
                            std::ceil(path.height) + 1);
  card.first_frame = kFirst;
  card.last_frame = kLast;
  options.occluders = {card};
  const EvaluateReport report = RunEvaluate(options);
  SCOPED_TRACE(FormatEvaluateMarkdown(report));
  for (const MethodResult& m : report.methods) {
    EXPECT_EQ(m.hidden, kLast - kFirst + 1) << m.label();
    // Gray templates cannot tell the discs apart: while the tip is hidden, zncc gray re-acquires
    // onto the middle marker. The session drops a report that lands on another marker, so every
    // method, that one included, reports the hidden marker as not found.
    EXPECT_EQ(m.false_reports, 0) << m.label();
  }
  // The other markers are never lost, and the colour tracker re-finds the tip once uncovered.
  EXPECT_EQ(Find(report, "colour").misses, 0);
}

TEST(EvaluateTest, WritesTheTableAsCsvAndMarkdown) {
  EvaluateOptions options = SmallScene();
  options.scene.frame_count = 5;
  options.methods = {"colour", "sad"};
  options.modes = {"gray", "colour"};
  const testing::TempDir dir;
  const fs::path csv = dir.path() / "evaluate.csv";
  options.csv_file = csv.string();
  const EvaluateReport report = RunEvaluate(options);
  ASSERT_EQ(report.methods.size(), 3u);  // colour, sad gray, sad colour.
  std::ifstream in(csv);
  std::string header, line;
  ASSERT_TRUE(std::getline(in, header));
  EXPECT_EQ(header.rfind("method,mode,frames,", 0), 0u) << header;
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 3);

  const std::string table = FormatEvaluateMarkdown(report);
  EXPECT_NE(table.find("| sad gray |"), std::string::npos) << table;
  EXPECT_NE(table.find("| sad colour |"), std::string::npos) << table;
  EXPECT_NE(table.find("| colour |"), std::string::npos) << table;
}

// The one-line message names the option and the value.
template <typename F>
std::string InputErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}

TEST(EvaluateTest, BadOptionsAreOneLineInputErrors) {
  EvaluateOptions unknown = SmallScene();
  unknown.methods = {"colour", "ncc"};
  std::string message = InputErrorOf([&] { RunEvaluate(unknown); });
  EXPECT_NE(message.find("--methods"), std::string::npos) << message;
  EXPECT_NE(message.find("'ncc'"), std::string::npos) << message;

  EvaluateOptions bad_mode = SmallScene();
  bad_mode.modes = {"grey"};
  message = InputErrorOf([&] { RunEvaluate(bad_mode); });
  EXPECT_NE(message.find("--modes"), std::string::npos) << message;

  EvaluateOptions no_frames = SmallScene();
  no_frames.scene.frame_count = 0;
  message = InputErrorOf([&] { RunEvaluate(no_frames); });
  EXPECT_NE(message.find("--frames"), std::string::npos) << message;
  EXPECT_NE(message.find("0"), std::string::npos) << message;

  for (const std::string text : {"0.6", "0.6,", "a,1.4", "0.6,1.4,2", "-1,1", "0.6;1.4"}) {
    NoiseOptions noise;
    message = InputErrorOf([&] { ParseGainRamp(text, &noise); });
    EXPECT_NE(message.find("--gain-ramp"), std::string::npos) << text << ": " << message;
    EXPECT_NE(message.find(text), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  NoiseOptions noise;
  ParseGainRamp("0.6,1.4", &noise);
  EXPECT_DOUBLE_EQ(noise.gain_start, 0.6);
  EXPECT_DOUBLE_EQ(noise.gain_end, 1.4);
}

// The built-in comparison and `evaluate --input --truth --config` on the same frames: a rendered
// video (lossless) with synth's truth CSV, and the config the built-in path gives the method.
void ExpectVideoScoreEqualsBuiltIn(const std::string& method,
                                   const std::optional<std::string>& mode) {
  testing::TempDir dir;
  EvaluateOptions builtin = SmallScene();
  builtin.scene.frame_count = 20;
  builtin.noise.sigma = 3;
  builtin.noise.seed = builtin.scene.seed;  // As the command line (and synth) do.
  builtin.methods = {method};
  if (mode) builtin.modes = {*mode};
  const EvaluateReport expected = RunEvaluate(builtin);
  ASSERT_EQ(expected.methods.size(), 1u);

  SynthOptions synth;
  synth.scene = builtin.scene;
  synth.noise = builtin.noise;
  synth.out = dir.file("run.avi");
  synth.truth_csv = dir.file("truth.csv");
  synth.quiet = true;
  std::vector<SceneTruth> truths;
  RunSynth(synth, &truths);
  SaveTrackingConfig(EvaluateMethodConfig(method, mode, builtin, truths.front()),
                     dir.file("config.yaml"));

  VideoEvaluateOptions video;
  video.source.input = synth.out;
  video.truth_csv = *synth.truth_csv;
  video.config_file = dir.file("config.yaml");
  video.quiet = true;
  const EvaluateReport got = RunVideoEvaluate(video);
  ASSERT_EQ(got.methods.size(), 1u);
  const MethodResult& a = expected.methods[0];
  const MethodResult& b = got.methods[0];
  EXPECT_EQ(got.frames, expected.frames);
  EXPECT_EQ(b.visible, a.visible);
  EXPECT_EQ(b.found_visible, a.found_visible);
  EXPECT_EQ(b.misses, a.misses);
  EXPECT_EQ(b.hidden, a.hidden);
  EXPECT_EQ(b.false_reports, a.false_reports);
  EXPECT_EQ(b.wrong_finds, a.wrong_finds);
  EXPECT_EQ(b.angle_frames, a.angle_frames);
  // The truth CSV holds 6 decimals.
  const auto near = [](const std::optional<double>& x, const std::optional<double>& y,
                       const char* what) {
    ASSERT_EQ(x.has_value(), y.has_value()) << what;
    if (x) {
      EXPECT_NEAR(*x, *y, 1e-5) << what;
    }
  };
  near(b.centroid_rms_px, a.centroid_rms_px, "centroid RMS");
  near(b.centroid_p95_px, a.centroid_p95_px, "centroid p95");
  near(b.centroid_max_px, a.centroid_max_px, "centroid max");
  near(b.precision_rms_px, a.precision_rms_px, "precision RMS");
  near(b.angle_rms_deg, a.angle_rms_deg, "angle RMS");
  ASSERT_TRUE(a.centroid_rms_px);
  EXPECT_GT(a.visible, 0);
}

TEST(EvaluateVideo, ColourOnARenderedVideoGivesTheBuiltInFigures) {
  ExpectVideoScoreEqualsBuiltIn("colour", std::nullopt);
}

TEST(EvaluateVideo, ZnccOnARenderedVideoGivesTheBuiltInFigures) {
  ExpectVideoScoreEqualsBuiltIn("zncc", std::string("gray"));
}

TEST(EvaluateVideo, MarkersAreMatchedByNameAndWrongFindsCounted) {
  testing::TempDir dir;
  SynthOptions synth;
  synth.scene = SmallScene().scene;
  synth.scene.frame_count = 5;
  synth.out = dir.file("run.avi");
  synth.quiet = true;
  std::vector<SceneTruth> truths;
  RunSynth(synth, &truths);
  // A hand-made truth: only red and green, in another column order, green 5 px off in frame 2,
  // red hidden (empty) in frame 3, and no row for frame 4.
  std::ofstream truth(dir.file("truth.csv"));
  truth << "green_y,green_x,frame,red_x,red_y\n";
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d r = *truths[i].markers[0].centroid_px, g = *truths[i].markers[2].centroid_px;
    truth << (g.y + (i == 2 ? 5.0 : 0.0)) << "," << g.x << "," << i << ",";
    if (i == 3) {
      truth << ",\n";
    } else {
      truth << r.x << "," << r.y << "\n";
    }
  }
  truth.close();
  TrackingConfig config;
  for (const SceneMarker& m : synth.scene.markers) {
    MarkerSpec spec;
    spec.name = m.name;
    spec.params = EvaluateMethodConfig("colour", std::nullopt, SmallScene(), truths[0])
                      .markers[config.markers.size()]
                      .params;
    config.markers.push_back(spec);
  }
  SaveTrackingConfig(config, dir.file("config.yaml"));
  VideoEvaluateOptions video;
  video.source.input = synth.out;
  video.truth_csv = dir.file("truth.csv");
  video.config_file = dir.file("config.yaml");
  video.quiet = true;
  const EvaluateReport report = RunVideoEvaluate(video);
  EXPECT_EQ(report.frames, 4);
  const MethodResult& m = report.methods.at(0);
  EXPECT_EQ(m.visible, 7);          // red in frames 0-2, green in 0-3.
  EXPECT_EQ(m.hidden, 1);           // red in frame 3, by the truth ...
  EXPECT_EQ(m.false_reports, 1);    // ... but it is there and found.
  EXPECT_EQ(m.wrong_finds, 1);      // green in frame 2.
  EXPECT_THAT(report.conditions, ::testing::HasSubstr("not in the truth (not scored): blue"));

  // The command line: the built-in comparison's options do not mix with a recording.
  const std::string cli = testing::SoftsightBinary() + " evaluate --input " + synth.out +
                          " --truth " + video.truth_csv + " --config " + video.config_file +
                          " --scene bench 2> " + dir.file("err.txt");
  EXPECT_EQ(WEXITSTATUS(std::system(cli.c_str())), 2);
  EXPECT_THAT(testing::ReadTextFile(dir.file("err.txt")), ::testing::HasSubstr("--scene"));
  const std::string half = testing::SoftsightBinary() + " evaluate --input " + synth.out +
                           " 2> " + dir.file("err2.txt");
  EXPECT_EQ(WEXITSTATUS(std::system(half.c_str())), 2);
  EXPECT_THAT(testing::ReadTextFile(dir.file("err2.txt")), ::testing::HasSubstr("--truth"));

  // A truth without any of the config's markers, or without frame numbers: one error each.
  testing::WriteTextFile(dir.file("bad.csv"), "frame,tip_x,tip_y\n0,1,2\n");
  video.truth_csv = dir.file("bad.csv");
  EXPECT_THROW(RunVideoEvaluate(video), InputError);
  testing::WriteTextFile(dir.file("bad2.csv"), "red_x,red_y\n1,2\n");
  video.truth_csv = dir.file("bad2.csv");
  EXPECT_THROW(RunVideoEvaluate(video), InputError);
}

}  // namespace
}  // namespace softsight
