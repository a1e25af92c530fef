#include "app/synth_command.h"
#include "app/scene_config.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include "app/program_test_util.h"
#include "core/test_util.h"
#include "softsight/io/truth_csv.h"
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "softsight/config/config.h"
#include "softsight/core/error.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;

using testing::ReadLines;
using testing::SplitCsv;

// The program refused: exit code 2 and one line on stderr that says `names`.
void ExpectOneErrorLine(const testing::ProgramRun& run, const std::string& names) {
  EXPECT_EQ(run.exit_code, 2) << run.stderr_text;
  EXPECT_EQ(std::count(run.stderr_text.begin(), run.stderr_text.end(), '\n'), 1) << run.stderr_text;
  EXPECT_NE(run.stderr_text.find(names), std::string::npos) << run.stderr_text;
}

SynthOptions SmallRun(const fs::path& out) {
  SynthOptions o;
  o.scene.size = cv::Size(320, 240);
  o.scene.frame_count = 8;
  o.scene.length_px = 150;
  o.scene.width_px = 20;
  o.scene.marker_radius_px = 6;
  o.noise.sigma = 2;
  o.out = out.string();
  o.quiet = true;
  return o;
}

// The plate scene through the same command: gray lossless frames and the dots' truth.
TEST(SynthCommandTest, PlateSceneWritesGrayFramesAndDotTruth) {
  const testing::TempDir temp;
  const fs::path& dir = temp.path();
  SynthOptions options = SmallRun(dir / "plate.avi");
  options.truth_csv = (dir / "truth.csv").string();
  PlateSceneOptions& plate = options.plate.emplace();
  plate.size = cv::Size(320, 240);
  plate.frame_count = 4;
  plate.dot_radius_px = 5;
  const SynthSummary summary = RunSynth(options);
  EXPECT_EQ(summary.frames, 4);
  EXPECT_EQ(summary.scene, "plate");
  const std::vector<std::string> lines = ReadLines(dir / "truth.csv");
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0].rfind("frame,time_s,bend_deg,dot0_x,dot0_y,dot0_visible,dot1_x", 0), 0u) << lines[0];
  PlateScene scene(plate, options.noise, options.render);
  cv::VideoCapture capture(options.out);
  ASSERT_TRUE(capture.isOpened());
  cv::Mat frame, expected;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(capture.read(frame));
    const SceneTruth truth = scene.render(i, expected);
    EXPECT_EQ(cv::norm(frame, expected, cv::NORM_INF), 0.0) << "frame " << i;
    const std::vector<std::string> fields = SplitCsv(lines[i + 1]);
    ASSERT_EQ(fields.size(), 3 + 3 * 5 + 7u);
    EXPECT_NEAR(std::stod(fields[3]), truth.markers[0].centroid_px->x, 1e-5);
    EXPECT_NEAR(std::stod(fields[4]), truth.markers[0].centroid_px->y, 1e-5);
  }
}

// The video is lossless: what OpenCV reads back is exactly what the renderer drew, so accuracy
// tests on video files measure the tracker, not the codec.
TEST(SynthCommandTest, VideoReadsBackExactlyWithTruthCsv) {
  const testing::TempDir temp;
  const fs::path& dir = temp.path();
  SynthOptions options = SmallRun(dir / "scene.avi");
  options.truth_csv = (dir / "truth.csv").string();
  options.occluders = {Occluder{cv::Rect2d(0, 0, 320, 240), 5, 5}};  // Frame 5: all hidden.
  const SynthSummary summary = RunSynth(options);
  EXPECT_EQ(summary.frames, 8);

  SyntheticScene scene(options.scene, options.noise, options.render, options.occluders);
  cv::VideoCapture capture(options.out);
  ASSERT_TRUE(capture.isOpened());
  cv::Mat frame, expected;
  int frames = 0;
  while (capture.read(frame)) {
    ASSERT_EQ(frame.size(), cv::Size(320, 240));
    ASSERT_EQ(frame.type(), CV_8UC3);
    scene.render(frames, expected);
    EXPECT_EQ(cv::norm(frame, expected, cv::NORM_INF), 0.0) << "frame " << frames;
    ++frames;
  }
  EXPECT_EQ(frames, 8);

  const std::vector<std::string> lines = ReadLines(*options.truth_csv);
  ASSERT_EQ(lines.size(), 9u);
  EXPECT_EQ(lines[0],
            "frame,time_s,bend_deg,red_x,red_y,red_visible,blue_x,blue_y,blue_visible,green_x,"
            "green_y,green_visible,angle_deg,chord_px,sagitta_px,radius_px,arc_length_px,"
            "tip_disp_px,centreline_radius_px");
  const size_t columns = SplitCsv(lines[0]).size();
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> fields = SplitCsv(lines[i]);
    ASSERT_EQ(fields.size(), columns) << lines[i];
    EXPECT_EQ(fields[0], std::to_string(i - 1));
  }
  // Straight at frame 0: angle 180, no radius.
  const std::vector<std::string> first = SplitCsv(lines[1]);
  EXPECT_NEAR(std::stod(first[12]), 180.0, 0.01);
  EXPECT_EQ(first[15], "");
  EXPECT_EQ(first[18], "");
  // Frame 5 is fully occluded: empty coordinates, visible 0, no measurements.
  const std::vector<std::string> hidden = SplitCsv(lines[6]);
  EXPECT_EQ(hidden[3], "");
  EXPECT_EQ(hidden[4], "");
  EXPECT_EQ(std::stod(hidden[5]), 0.0);
  EXPECT_EQ(hidden[12], "");
  // The rows are the scene's truth, as `evaluate --truth` reads them back (to the 6 decimals).
  const TruthCsv read = ReadTruthCsv(*options.truth_csv, {"red", "blue", "green"});
  ASSERT_EQ(read.frames.size(), 8u);
  const SceneTruth truth = scene.render(3, expected);
  EXPECT_NEAR(read.frames[3].bend_deg, truth.bend_deg, 5e-7);
  for (size_t m = 0; m < 3; ++m) {
    ASSERT_TRUE(read.frames[3].markers[m].centroid_px) << m;
    EXPECT_NEAR(read.frames[3].markers[m].centroid_px->x, truth.markers[m].centroid_px->x, 5e-7);
    EXPECT_NEAR(read.frames[3].markers[m].centroid_px->y, truth.markers[m].centroid_px->y, 5e-7);
  }
  EXPECT_FALSE(read.frames[5].markers[0].centroid_px) << "hidden at frame 5";
}

TEST(SynthCommandTest, ImageSequenceIsLossless) {
  const testing::TempDir temp;
  const fs::path& dir = temp.path();
  SynthOptions options = SmallRun(dir / "f_%03d.png");
  options.scene.kind = SceneKind::kWedge4;
  options.scene.frame_count = 3;
  RunSynth(options);
  SyntheticScene scene(options.scene, options.noise);
  cv::Mat expected;
  for (int i = 0; i < 3; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "f_%03d.png", i);
    const cv::Mat image = cv::imread((dir / name).string());
    ASSERT_FALSE(image.empty()) << name;
    scene.render(i, expected);
    EXPECT_EQ(cv::norm(image, expected, cv::NORM_INF), 0.0) << name;
  }
  EXPECT_FALSE(fs::exists(dir / "f_003.png"));
}

TEST(SynthCommandTest, BadInputIsOneLineInputError) {
  const testing::TempDir temp;
  const fs::path& dir = temp.path();
  auto expect_error = [](const SynthOptions& options, const std::string& needle) {
    try {
      RunSynth(options);
      ADD_FAILURE() << "no error for " << needle;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(needle), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  };
  SynthOptions zero = SmallRun(dir / "a.avi");
  zero.scene.frame_count = 0;
  expect_error(zero, "--frames");
  SynthOptions missing_folder = SmallRun(dir / "no_such_folder" / "a.avi");
  missing_folder.truth_csv = (dir / "truth.csv").string();
  expect_error(missing_folder, "no_such_folder");
  EXPECT_FALSE(fs::exists(dir / "truth.csv"));  // Nothing written before the error.
  expect_error(SmallRun(dir / "a.xyz"), ".xyz");
  expect_error(SmallRun(dir / "f_%s.png"), "%d");
  SynthOptions codec = SmallRun(dir / "a.avi");
  codec.codec = "h265";
  expect_error(codec, "h265");
  SynthOptions bad_truth = SmallRun(dir / "a.avi");
  bad_truth.truth_csv = (dir / "nowhere" / "t.csv").string();
  expect_error(bad_truth, "nowhere");
  EXPECT_THROW(ParseSceneKind("spiral"), InputError);
}

// Through the real program: an unknown scene is one line on stderr and exit code 2.
TEST(SynthCommandTest, ProgramReportsBadSceneOnce) {
  const testing::TempDir dir;
  ExpectOneErrorLine(testing::RunProgram("synth --scene spiral --out " + dir.file("a.avi"), dir),
                     "spiral");
}

// `serve --input synth:NAME` without --config: the scene brings the config a person would write
// for it, written once into the folder; a config already there (saved from an earlier run) is
// kept and used; other inputs still need --config, and the error says so.
TEST(SynthCommandTest, ASynthSceneBringsItsOwnConfigWrittenOnceAndKept) {
  testing::TempDir dir;
  const std::string path = ConfigForBuiltinInput("synth:bending", dir.path().string());
  EXPECT_EQ(fs::path(path).filename(), "synth-bending.yaml");
  const TrackingConfig config = LoadTrackingConfig(path);
  ASSERT_EQ(config.markers.size(), 3u);  // The bending scene's red, blue and green markers.
  EXPECT_EQ(config.markers[0].name, "red");
  EXPECT_TRUE(config.markers[0].params.holds<ColourParams>());
  {
    std::ofstream edited(path);
    edited << "markers:\n  - name: mine\n    method: colour\n";
  }
  EXPECT_EQ(ConfigForBuiltinInput("synth:bending", dir.path().string()), path);
  EXPECT_EQ(LoadTrackingConfig(path).markers.at(0).name, "mine");  // Not overwritten.
  try {
    ConfigForBuiltinInput("run.avi", dir.path().string());
    ADD_FAILURE() << "a video file was given a config";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--config is required for run.avi"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ConfigForBuiltinInput("synth:plate", dir.path().string()), InputError);
  EXPECT_THROW(ConfigForBuiltinInput("synth:nosuchscene", dir.path().string()), InputError);
}

// `serve --compare VIDEO` shows a second video at the served file's position: with the rig's own
// frames (or a camera) there is no position to match. One line naming --compare, exit code 2,
// and nothing written into the folder first (the simulated rig's config is written later).
TEST(SynthCommandTest, ServeCompareNeedsAFileServedAndWritesNothingFirst) {
  const testing::TempDir dir;
  const fs::path folder = dir.path() / "folder";
  fs::create_directory(folder);
  ExpectOneErrorLine(testing::RunProgram("serve --simulate --compare " + dir.file("b.avi") +
                                             " --port 0 --folder " + folder.string(),
                                         dir),
                     "--compare needs --input");
  EXPECT_TRUE(fs::is_empty(folder));
}

}  // namespace
}  // namespace softsight
