// `softsight track` with several inputs: the CSVs are the single-input runs' CSVs whatever the
// number of jobs, a failing input is reported and the others complete.
#include "app/track_many.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/scene_markers_test_util.h"
#include "app/program_test_util.h"
#include "core/test_util.h"
#include "softsight/io/frame_writer.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::ProgramRun;
using testing::RunProgram;
using testing::TempDir;


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
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
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
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
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

// Ctrl-C in the terminal reaches the whole process group: the parent and every running child.
// Every child stops cleanly (complete rows, its summary), inputs not started are skipped, what
// had already finished is kept whole, and the run exits 130 (128 + SIGINT).
TEST(TrackMany, CtrlCStopsEveryJobExits130AndKeepsTheFinishedOutputs) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), testing::kSceneMarkersYaml);
  const std::string clip = RenderClip(dir.file("short.avi"), 12, 1);
  const std::string single = dir.file("single.csv");
  ASSERT_EQ(RunProgram("track -q -c " + dir.file("markers.yaml") + " -i " + clip + " -o " + single, dir)
                .exit_code,
            0);
  // The short clip finishes first; the rendered scenes (300 frames) are still running, or not
  // yet started, when the interrupt comes.
  const std::string out = dir.file("out") + "/";
  const std::string err = dir.file("many.err");
  const std::string command = "exec " + testing::SoftsightBinary() + " track -c " +
                              dir.file("markers.yaml") + " -i " + clip +
                              " -i synth:bending -i synth:wedge1 -i synth:wedge4 -o " + out +
                              " --jobs 2 2> " + err;
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    setpgid(0, 0);  // A process group of its own, as a shell's foreground job.
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  setpgid(pid, pid);  // Either side may run first.
  // Interrupt once the short clip's line is out (its CSV is then complete): no timing involved,
  // the 60 s are only a bound for a broken build.
  const std::string finished = "[1/4] " + clip + " -> " + out + "short.csv: 12 frames (end of input)";
  for (int waited_ms = 0;
       waited_ms < 60000 && testing::ReadTextFile(err).find(finished) == std::string::npos;
       waited_ms += 5) {
    usleep(5000);
  }
  ASSERT_THAT(testing::ReadTextFile(err), HasSubstr(finished));
  kill(-pid, SIGINT);  // The group, as the terminal sends it.
  int status = 0;
  waitpid(pid, &status, 0);
  const std::string report = testing::ReadTextFile(err);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping: " << report;
  EXPECT_EQ(WEXITSTATUS(status), 130) << report;
  EXPECT_THAT(report, HasSubstr("4 inputs, --jobs 2: 1 done, ")) << "every other one stopped";
  EXPECT_THAT(report, Not(HasSubstr("failed"))) << report;
  EXPECT_THAT(report, Not(HasSubstr("killed"))) << report;
  // The finished output is the single run's, row for row.
  EXPECT_EQ(RowsWithoutTimings(out + "short.csv"), RowsWithoutTimings(single));
  // A stopped job's CSV holds complete rows only, fewer than the scene's 300; one not started
  // has none.
  int stopped = 0;
  for (const char* name : {"synth_bending", "synth_wedge1", "synth_wedge4"}) {
    const std::string csv = out + name + ".csv";
    if (!std::filesystem::exists(csv)) {
      EXPECT_THAT(report, HasSubstr("not started (stop requested)")) << name;
      continue;
    }
    ++stopped;
    EXPECT_THAT(report, HasSubstr("synth:" + std::string(name + 6) + " -> " + csv + ": "));
    const std::vector<std::string> lines = testing::ReadLines(csv);
    ASSERT_GE(lines.size(), 1u) << name << ": the header at least";
    EXPECT_LT(lines.size(), 301u) << name << " ran to its end before the interrupt";
    const size_t columns = testing::SplitCsv(lines[0]).size();
    for (size_t i = 1; i < lines.size(); ++i) {
      EXPECT_EQ(testing::SplitCsv(lines[i]).size(), columns) << name << " row " << i;
    }
  }
  EXPECT_GE(stopped, 1) << "the second job was running when the interrupt came";
  EXPECT_THAT(report, HasSubstr(std::to_string(stopped) + " stopped"));
}

}  // namespace
}  // namespace softsight
