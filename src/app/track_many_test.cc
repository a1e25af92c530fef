// `softsight track` with several inputs: the CSVs are the single-input runs' CSVs whatever the
// number of jobs, a failing input is reported and the others complete.
#include "app/track_many.h"

#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/scene_markers_test_util.h"
#include "core/test_util.h"
#include "softsight/io/frame_writer.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

const char* const kConfig = testing::kSceneMarkersYaml;

// A short rendered bending clip (lossless), a different texture per seed.
std::string RenderClip(const std::string& path, int frames, unsigned seed) {
  SceneOptions scene;
  scene.frame_count = frames;
  scene.size = {320, 240};
  scene.length_px = 150;
  scene.marker_radius_px = 6;
  scene.seed = seed;
  SyntheticScene renderer(scene);
  FrameWriter writer({path, "hfyu", scene.fps});
  cv::Mat image;
  for (int i = 0; i < frames; ++i) {
    renderer.render(i, image);
    writer.write(image, i);
  }
  return path;
}

struct ProgramRun {
  int exit_code;
  std::string stderr_text;
};

ProgramRun RunProgram(const std::string& args, const TempDir& dir) {
  const std::string command =
      testing::SoftsightBinary() + " " + args + " 2> " + dir.file("stderr.txt");
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, testing::ReadTextFile(dir.file("stderr.txt"))};
}

// Every column of a CSV but the timings (proc_ms, latency_*), which differ from run to run.
std::vector<std::vector<std::string>> RowsWithoutTimings(const std::string& csv) {
  const std::vector<std::string> lines = testing::ReadLines(csv);
  std::vector<std::vector<std::string>> rows;
  if (lines.empty()) return rows;
  const std::vector<std::string> header = testing::SplitCsv(lines[0]);
  for (const std::string& line : lines) {
    const std::vector<std::string> fields = testing::SplitCsv(line + ",");
    std::vector<std::string> kept;
    for (size_t i = 0; i < header.size() && i < fields.size(); ++i) {
      if (header[i] != "proc_ms" && header[i].rfind("latency_", 0) != 0) kept.push_back(fields[i]);
    }
    rows.push_back(kept);
  }
  return rows;
}

TEST(TrackMany, CsvNamesComeFromTheInputsAndNeverClash) {
  EXPECT_EQ(CsvNamesForInputs({"runs/a.avi", "other/a.mkv", "a-1.avi", "synth:bending",
                               "frames/%04d.png", "shots/", "x.tar.gz"},
                              "out"),
            (std::vector<std::string>{"out/a.csv", "out/a-1.csv", "out/a-1-1.csv",
                                      "out/synth_bending.csv", "out/04d.csv", "out/shots.csv",
                                      "out/x.tar.csv"}));
}

TEST(TrackMany, JobsGiveTheCsvsOfSingleRunsAndAFailingInputDoesNotStopTheOthers) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  std::vector<std::string> clips;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    clips.push_back(RenderClip(dir.file("clip" + std::to_string(seed) + ".avi"), 12, seed));
  }
  {  // A fourth clip, cut short: its rows before the cut are kept and it ends in its error.
    const std::string full = RenderClip(dir.file("full.avi"), 12, 4);
    std::ifstream in(full, std::ios::binary);
    std::string data((std::istreambuf_iterator<char>(in)), {});
    data.resize(data.size() * 2 / 3);
    clips.push_back(dir.file("cut.avi"));
    std::ofstream(clips.back(), std::ios::binary).write(data.data(), static_cast<std::streamsize>(data.size()));
  }
  const std::string config = " -c " + dir.file("markers.yaml");
  std::vector<std::string> single_errors;
  for (size_t i = 0; i < clips.size(); ++i) {
    const ProgramRun run =
        RunProgram("track -q" + config + " -i " + clips[i] + " -o " + dir.file("single" + std::to_string(i) + ".csv"), dir);
    EXPECT_EQ(run.exit_code, i == 3 ? 2 : 0) << run.stderr_text;
    single_errors.push_back(run.stderr_text);
  }
  ASSERT_THAT(single_errors[3], HasSubstr("truncated"));
  std::string inputs;
  for (const std::string& clip : clips) inputs += " -i " + clip;
  for (int jobs : {1, 2}) {
    const std::string out = dir.file("jobs" + std::to_string(jobs)) + "/";
    const ProgramRun run = RunProgram("track" + config + inputs + " -o " + out + " --jobs " + std::to_string(jobs), dir);
    EXPECT_EQ(run.exit_code, 2) << "one input failed: " << run.stderr_text;
    // Its error line, as the single run gave it, and a line for every input that completed.
    EXPECT_THAT(run.stderr_text, HasSubstr("[4/4] " + clips[3] + ": " + single_errors[3]));
    for (size_t i = 0; i < 3; ++i) {
      std::ostringstream line;
      line << "[" << i + 1 << "/4] " << clips[i] << " -> " << out << "clip" << i + 1
           << ".csv: 12 frames (end of input)";
      EXPECT_THAT(run.stderr_text, HasSubstr(line.str()));
    }
    EXPECT_THAT(run.stderr_text, HasSubstr("4 inputs, --jobs " + std::to_string(jobs) +
                                           ": 3 done, 1 failed (" + clips[3] + ")"));
    const char* names[] = {"clip1", "clip2", "clip3", "cut"};
    for (size_t i = 0; i < clips.size(); ++i) {
      const auto rows = RowsWithoutTimings(out + names[i] + ".csv");
      EXPECT_EQ(rows.size(), i == 3 ? 8u : 13u) << names[i] << " with --jobs " << jobs;
      EXPECT_EQ(rows, RowsWithoutTimings(dir.file("single" + std::to_string(i) + ".csv")))
          << names[i] << " with --jobs " << jobs;
    }
  }
}

TEST(TrackMany, RefusesSeveralInputsIntoOneFileAndACsvThatIsAnInput) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), kConfig);
  const std::string clip = RenderClip(dir.file("a.avi"), 2, 1);
  const std::string config = " -c " + dir.file("markers.yaml");
  ProgramRun run = RunProgram("track" + config + " -i " + clip + " -i synth:bending -o " + dir.file("one.csv"), dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.stderr_text, HasSubstr("output folder"));
  EXPECT_FALSE(std::filesystem::exists(dir.file("one.csv")));
  // The CSV of a.avi in this folder would be a.csv, which is also an input: nothing runs.
  testing::WriteTextFile(dir.file("a.csv"), "precious\n");
  run = RunProgram("track" + config + " -i " + clip + " -i " + dir.file("a.csv") + " -o " + dir.path().string() + "/", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(std::count(run.stderr_text.begin(), run.stderr_text.end(), '\n'), 1) << run.stderr_text;
  EXPECT_THAT(run.stderr_text, HasSubstr("a.csv"));
  EXPECT_EQ(testing::ReadTextFile(dir.file("a.csv")), "precious\n");
  run = RunProgram("track" + config + " -i " + clip + " -i synth:bending -o " + dir.file("o") + "/ --annotated x.avi", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.stderr_text, HasSubstr("--annotated"));
}

}  // namespace
}  // namespace softsight
