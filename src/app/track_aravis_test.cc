// `softsight track --camera aravis:ID` end to end, on Aravis' simulated camera (aravis:Fake_1, in
// the process: no network): the program writes one row per frame, and with the camera showing a
// rendered actuator (the test's painter, as a Bayer sensor sends it) the tracked centroids match
// the renderer's truth frame by frame. Bad camera names are one line naming them.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <mutex>
#include <regex>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/program_test_util.h"
#include "app/scene_markers_test_util.h"
#include "app/track_command.h"
#include "core/test_util.h"
#include "io/aravis_camera.h"
#include "io/aravis_test_util.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

// The CSV's rows as column name -> text.
std::vector<std::map<std::string, std::string>> ReadRows(const std::string& path) {
  const std::vector<std::string> lines = testing::ReadLines(path);
  std::vector<std::map<std::string, std::string>> rows;
  if (lines.empty()) return rows;
  const std::vector<std::string> header = testing::SplitCsv(lines[0]);
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> cells = testing::SplitCsv(lines[i]);
    std::map<std::string, std::string> row;
    for (size_t c = 0; c < header.size() && c < cells.size(); ++c) row[header[c]] = cells[c];
    rows.push_back(row);
  }
  return rows;
}

TEST(TrackAravis, TheProgramWritesARowForEachFrameOfTheSimulatedCamera) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  const testing::ProgramRun run = testing::RunProgram(
      "track -c " + dir.file("markers.yaml") + " --camera aravis:Fake_1 --max-frames 8 " +
          "--camera-width 320 --camera-height 240 --camera-fps 200 --brief -o " +
          dir.file("run.csv"),
      dir);
  ASSERT_EQ(run.exit_code, 0) << run.stderr_text;
  // Aravis' test pattern has no markers: rows, not positions, are what can be checked.
  const auto rows = ReadRows(dir.file("run.csv"));
  ASSERT_EQ(rows.size(), 8u);
  EXPECT_THAT(run.stderr_text, HasSubstr("8 frames (max frames reached)"));
}

// A hook far slower than the camera (100 ms a call against a frame every 10 ms) on a live
// camera: it runs on its own thread, so the run still writes a whole row for every frame, the
// hook's column empty where its values did not come in time, and the summary says how many
// frames it skipped while busy. However loaded the machine, such a hook cannot take every frame;
// one that held up the loop would skip none.
TEST(TrackAravis, ASlowHookOnTheCameraSkipsFramesAndEveryRowIsWhole) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  testing::WriteTextFile(dir.file("slow.py"), R"py(
import time
columns = ["slow_mean"]

def on_frame(frame, result):
    time.sleep(0.1)
    return {"slow_mean": float(frame.mean())}
)py");
  const testing::ProgramRun run = testing::RunProgram(
      "track -c " + dir.file("markers.yaml") + " --camera aravis:Fake_1 --max-frames 30 " +
          "--camera-width 320 --camera-height 240 --camera-fps 100 -o " + dir.file("run.csv") +
          " --hook " + dir.file("slow.py"),
      dir);
  if (run.stderr_text.find("built without Python") != std::string::npos) {
    GTEST_SKIP() << "this build has no Python hooks";
  }
  ASSERT_EQ(run.exit_code, 0) << run.stderr_text;
  const std::vector<std::string> lines = testing::ReadLines(dir.file("run.csv"));
  ASSERT_EQ(lines.size(), 31u) << "a header and one row per frame";
  const std::vector<std::string> header = testing::SplitCsv(lines[0]);
  const auto column = std::find(header.begin(), header.end(), "slow_mean");
  ASSERT_NE(column, header.end());
  const size_t c = static_cast<size_t>(column - header.begin());
  int filled = 0;
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> cells = testing::SplitCsv(lines[i]);
    ASSERT_EQ(cells.size(), header.size()) << "row " << i << " is whole";
    if (cells[c].empty()) continue;
    ++filled;
    EXPECT_GT(std::stod(cells[c]), 0.0) << "row " << i;  // Aravis' pattern is not black.
  }
  // The summary: "<hook>: values in V of 30 rows; skipped S of 30 frames (still busy), L late
  // (over 5 ms; left empty)". The loop waits 5 ms for a frame's values (--hook-wait-ms), so
  // a 100 ms call's values come late and its row is written without them.
  std::smatch note;
  ASSERT_TRUE(std::regex_search(
      run.stderr_text, note,
      std::regex("values in ([0-9]+) of 30 rows; skipped ([0-9]+) of 30 frames \\(still busy\\), "
                 "([0-9]+) late")))
      << run.stderr_text;
  const int values = std::stoi(note[1].str()), skipped = std::stoi(note[2].str()),
            late = std::stoi(note[3].str());
  EXPECT_EQ(values, filled);
  EXPECT_EQ(values + skipped + late, 30);
  EXPECT_GE(skipped, 1) << "frames came while the hook was busy";
  EXPECT_GE(values + late, 1) << "the hook ran";
}

TEST(TrackAravis, ACameraThatCannotBeOpenedIsOneLineNamingIt) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  testing::ProgramRun run = testing::RunProgram(
      "track -c " + dir.file("markers.yaml") + " --camera aravis:Fake_9 -o " + dir.file("a.csv"),
      dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.stderr_text, "softsight track: error: camera aravis:Fake_9: cannot open: no such "
                             "simulated camera (Aravis' Fake interface has Fake_1)\n");
  run = testing::RunProgram(
      "live -c " + dir.file("markers.yaml") + " --camera gige:cam1", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.stderr_text, HasSubstr("softsight live: error: --camera: 'gige:cam1' is no "
                                         "camera: give a V4L2 index"));
}

// The camera shows the rendered actuator, one scene frame per triggered camera frame (software
// trigger: frame n of the camera is scene frame n, whatever the pipeline drops), as a Bayer
// sensor sends it; the CSV's centroids are the renderer's.
TEST(TrackAravis, TrackedCentroidsOfTheSimulatedCameraMatchTheRenderedTruth) {
  SceneOptions scene_options;
  scene_options.frame_count = 30;
  scene_options.size = {320, 240};
  scene_options.length_px = 150;
  scene_options.marker_radius_px = 6;
  SyntheticScene scene(scene_options, NoiseOptions{});
  std::mutex mutex;
  std::vector<SceneTruth> truths;
  cv::Mat picture;
  SetFakeCameraPainter([&](uint8_t* data, size_t size, int width, int height,
                           const std::string& format) {
    std::lock_guard<std::mutex> lock(mutex);
    truths.push_back(scene.render(static_cast<int>(truths.size()) % scene_options.frame_count, picture));
    const cv::Mat sent = testing::AsSentByCamera(picture, format);
    if (sent.cols != width || sent.rows != height || sent.total() * sent.elemSize() > size) return;
    std::copy(sent.data, sent.data + sent.total() * sent.elemSize(), data);
  });
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.csv_file = dir.file("run.csv");
  options.quiet = true;
  options.max_frames = 12;
  options.source.camera = CameraId("aravis:Fake_1");
  options.source.capture.width = 320;
  options.source.capture.height = 240;
  options.source.capture.pixel_format = CameraSettings::PixelFormat::kBayer8;
  options.source.capture.trigger = "Software";
  const RunSummary summary = RunTrack(options, nullptr);
  SetFakeCameraPainter(nullptr);
  EXPECT_EQ(summary.frames, 12);

  const auto rows = ReadRows(dir.file("run.csv"));
  ASSERT_EQ(rows.size(), 12u);
  std::lock_guard<std::mutex> lock(mutex);
  double worst_px = 0;
  for (const auto& row : rows) {
    const size_t frame = std::stoul(row.at("frame"));
    ASSERT_LT(frame, truths.size());
    for (const MarkerTruth& marker : truths[frame].markers) {
      ASSERT_TRUE(marker.centroid_px);
      const std::string x = row.at(marker.name + "_x"), y = row.at(marker.name + "_y");
      ASSERT_FALSE(x.empty()) << marker.name << " lost in frame " << frame;
      const double error = std::hypot(std::stod(x) - marker.centroid_px->x,
                                      std::stod(y) - marker.centroid_px->y);
      worst_px = std::max(worst_px, error);
    }
  }
  std::printf("aravis:Fake_1 (BayerRG8, demosaiced): worst centroid error %.3f px\n", worst_px);
  EXPECT_LT(worst_px, 0.5);
}

}  // namespace
}  // namespace softsight
