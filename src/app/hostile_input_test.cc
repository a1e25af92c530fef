// Hostile input to the commands other than `track` (whose own tests cover it): one error line
// naming the culprit, exit code 2, no input destroyed.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>

#include "app/program_test_util.h"
#include "core/test_util.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::ProgramRun;
using testing::RunProgram;
using testing::TempDir;


void ExpectOneError(const ProgramRun& run, const std::string& what) {
  EXPECT_EQ(run.exit_code, 2) << run.stderr_text;
  EXPECT_THAT(run.stderr_text, HasSubstr(what));
  EXPECT_EQ(std::count(run.stderr_text.begin(), run.stderr_text.end(), '\n'), 1)
      << "one error line, got: " << run.stderr_text;
}

TEST(PlotCommand, RefusesToWriteTheFigureOverItsCsv) {
  TempDir dir;
  testing::WriteTextFile(dir.file("run.csv"), "frame,time_s,angle_deg\n0,0,180\n1,0.1,170\n");
  const std::string before = testing::ReadTextFile(dir.file("run.csv"));
  ExpectOneError(RunProgram("plot " + dir.file("run.csv") + " -o " + dir.file("run.csv"), dir),
                 "refusing to overwrite");
  EXPECT_EQ(testing::ReadTextFile(dir.file("run.csv")), before);
}

TEST(ControlCommand, MissingSerialPortSaysSoNotBadFileDescriptor) {
  TempDir dir;
  const ProgramRun run = RunProgram("control --config " + testing::SourceDir() +
                                 "/examples/rig.yaml --port " + dir.file("ttyNONE") +
                                 " --rig-frames " + dir.file("rig.png") + " --target-deg 120 --csv " +
                                 dir.file("o.csv"),
                             dir);
  ExpectOneError(run, dir.file("ttyNONE"));
  EXPECT_THAT(run.stderr_text, HasSubstr("No such file"));
  EXPECT_THAT(run.stderr_text, ::testing::Not(HasSubstr("Bad file descriptor")));
}

TEST(CalibrateCommand, PatternThatIsNotOneNumberIsRefusedNotFormatted) {
  TempDir dir;
  for (const char* pattern : {"%s.png", "%n.png"}) {
    ExpectOneError(RunProgram("calibrate --input '" + dir.file(pattern) +
                           "' --chessboard 9x6 --square-mm 25 --out " + dir.file("c.yaml"),
                       dir),
                   pattern);
  }
}

// Every numeric option of every command refuses NaN and infinities (CLI11 reads them as numbers).
TEST(EveryCommand, NonFiniteNumbersAreRefusedByName) {
  TempDir dir;
  for (const std::string args :
       {"synth --fps inf -o x.avi", "synth --noise nan -o x.avi", "evaluate --blur inf",
        "demo --noise nan", "plot x.csv -o x.png --width nan", "live --chart-seconds inf",
        "calibrate --input x --chessboard 9x6 --square-mm nan --out c.yaml"}) {
    const ProgramRun run = RunProgram(args, dir);
    EXPECT_EQ(run.exit_code, 2) << args << ": " << run.stderr_text;
    EXPECT_THAT(run.stderr_text, HasSubstr("not a finite number")) << args;
  }
}


// ---- Second round: control, identify and the serial port. ----

// Runs each command against copies of the inputs and checks: exit 2, one error line holding
// `what`, every input byte-identical afterwards.
class InputsKeptTest : public ::testing::Test {
 protected:
  void SetUp() override {
    config_ = dir_.file("rig.yaml");
    testing::WriteTextFile(config_, testing::ReadTextFile(testing::SourceDir() +
                                                          "/examples/rig.yaml"));
    profile_ = dir_.file("p.txt");
    testing::WriteTextFile(profile_, "step 120\nhold 1\n");
    video_ = dir_.file("v.avi");
    ASSERT_EQ(RunProgram("synth --frames 3 -o " + video_, dir_).exit_code, 0);
    before_ = Snapshot();
  }
  std::vector<std::string> Snapshot() const {
    return {testing::ReadTextFile(config_), testing::ReadTextFile(profile_),
            testing::ReadTextFile(video_)};
  }
  void ExpectRefused(const std::string& args, const std::string& what) {
    SCOPED_TRACE(args);
    ExpectOneError(RunProgram(args, dir_), what);
    EXPECT_TRUE(Snapshot() == before_) << "an input was changed";
  }
  TempDir dir_;
  std::string config_, profile_, video_;
  std::vector<std::string> before_;
};

TEST_F(InputsKeptTest, ControlNeverWritesOverTheConfigProfileOrVideo) {
  const std::string run = "control --config " + config_ + " --simulate ";
  ExpectRefused(run + "--target-deg 120 --csv " + config_, "refusing to overwrite an input");
  ExpectRefused(run + "--profile " + profile_ + " --csv " + profile_,
                "refusing to overwrite an input");
  ExpectRefused(run + "--input " + video_ + " --target-deg 120 --csv " + video_,
                "refusing to overwrite an input");
  // Through another name of the same file.
  ExpectRefused(run + "--target-deg 120 --csv " + dir_.file("./rig.yaml"),
                "refusing to overwrite an input");
}

TEST_F(InputsKeptTest, TheRigNeverPaintsItsFramesOverItsConfig) {
  // `rig --frames` names the picture it keeps rewriting: its own config was turned into a PNG.
  ExpectRefused("rig --pty --config " + config_ + " --frames " + config_,
                "refusing to overwrite an input");
}

TEST_F(InputsKeptTest, OneNameForTwoOutputsIsRefusedBeforeTheRun) {
  const std::string x = dir_.file("x.csv");
  ExpectRefused("control --config " + config_ + " --simulate --target-deg 120 --csv " + x +
                    " --metrics-csv " + x,
                "are the same file");
  ExpectRefused("identify --config " + config_ + " --simulate -o " + x + " --csv " + x,
                "are the same file");
  EXPECT_FALSE(std::filesystem::exists(x)) << "nothing is written when the run is refused";
}

TEST_F(InputsKeptTest, IdentifyNeverWritesOverTheConfig) {
  const std::string run = "identify --config " + config_ + " --simulate -o " + dir_.file("o.yaml");
  ExpectRefused(run + " --csv " + config_, "refusing to overwrite an input");
  ExpectRefused(run + " --model-csv " + config_, "refusing to overwrite an input");
  // The gains would be lost after the experiment: refused before it.
  ExpectRefused("identify --config " + config_ + " --simulate -o " + dir_.file("no/o.yaml"),
                "does not exist");
}

TEST_F(InputsKeptTest, AutoTuneNeverWritesItsExperimentOverTheConfig) {
  // --auto-tune writes the experiment beside --csv as run_identify.csv: a config of that name.
  const std::string named = dir_.file("run_identify.csv");
  testing::WriteTextFile(named, testing::ReadTextFile(config_));
  const std::string text = testing::ReadTextFile(named);
  ExpectOneError(RunProgram("control --config " + named + " --simulate --auto-tune "
                            "--target-deg 120 --csv " + dir_.file("run.csv"),
                            dir_),
                 "refusing to overwrite an input");
  EXPECT_EQ(testing::ReadTextFile(named), text);
  for (const char* bad : {"-1", "0", "inf", "nan", "101"}) {
    ExpectRefused("control --config " + config_ + " --simulate --auto-tune --target-deg 120 "
                  "--closed-loop-s " + std::string(bad) + " --csv " + dir_.file("r.csv"),
                  "--closed-loop-s");
  }
}

TEST_F(InputsKeptTest, APortThatIsNoSerialDeviceIsOneLineNotAnAbort) {
  const std::string fifo = dir_.file("fifo");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string file = dir_.file("plain");
  testing::WriteTextFile(file, "not a port\n");
  const std::pair<std::string, std::string> cases[] = {
      {"/dev/null", "not a terminal"},
      {file, "a regular file, not a serial device"},
      {fifo, "a FIFO, not a serial device"},
      {dir_.path().string(), "Is a directory"},
  };
  for (const auto& [port, what] : cases) {
    ExpectRefused("control --config " + config_ + " --port " + port + " --input " + video_ +
                      " --target-deg 120 --csv " + dir_.file("o.csv"),
                  what);
  }
  EXPECT_EQ(testing::ReadTextFile(file), "not a port\n");
}

TEST_F(InputsKeptTest, AFrameRateTheWatchdogCannotSpanIsRefusedNamingTheRate) {
  ExpectRefused("control --config " + config_ + " --simulate --fps 2 --target-deg 120 --csv " +
                    dir_.file("o.csv"),
                "frames every 500 ms (2 fps) but the board's watchdog vents after 250 ms "
                "without a command: use at least 5 fps");
}

TEST_F(InputsKeptTest, AMinKpaAboveTheBoardsLimitIsRefusedWithNothingSent) {
  const std::string config = dir_.file("high.yaml");
  // The example's control section, with a floor above the rig board's 50 kPa.
  std::string text = testing::ReadTextFile(config_);
  const size_t at = text.find("min_kpa:");
  ASSERT_NE(at, std::string::npos);
  const size_t end = text.find('\n', at);
  text.replace(at, end - at, "min_kpa: 60");
  const size_t max_at = text.find("max_kpa:");
  ASSERT_NE(max_at, std::string::npos);
  text.replace(max_at, text.find('\n', max_at) - max_at, "max_kpa: 70");
  testing::WriteTextFile(config, text);
  const ProgramRun run = RunProgram("control --config " + config +
                                        " --simulate --target-deg 120 --csv " + dir_.file("o.csv"),
                                    dir_);
  EXPECT_EQ(run.exit_code, 2) << run.stderr_text;
  EXPECT_THAT(run.stderr_text, HasSubstr("min_kpa: 60 kPa is not below the board's pressure "
                                         "limit of 50 kPa"));
  EXPECT_THAT(run.stderr_text, HasSubstr("no setpoint sent, vented"));
  // identify: the same refusal before any step.
  const ProgramRun identify = RunProgram(
      "identify --config " + config + " --simulate -o " + dir_.file("o.yaml"), dir_);
  EXPECT_EQ(identify.exit_code, 2) << identify.stderr_text;
  EXPECT_THAT(identify.stderr_text, HasSubstr("min_kpa: 60 kPa is not below the board's pressure "
                                              "limit of 50 kPa"));
  EXPECT_FALSE(std::filesystem::exists(dir_.file("o.yaml")));
}

TEST_F(InputsKeptTest, AVideoWithoutFramesIsAnErrorNotAnEmptyRun) {
  const std::string empty = dir_.file("empty.avi");
  {
    cv::VideoWriter writer(empty, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30,
                           cv::Size(64, 48));
    ASSERT_TRUE(writer.isOpened());
  }
  testing::WriteTextFile(dir_.file("m.yaml"), testing::ReadTextFile(testing::SourceDir() +
                                                                     "/examples/markers.yaml"));
  ExpectOneError(RunProgram("track -c " + dir_.file("m.yaml") + " -i " + empty + " -o " +
                                dir_.file("o.csv"),
                            dir_),
                 "no frames to read");
}

TEST_F(InputsKeptTest, ASymlinkLoopIsOneLineNamingIt) {
  const std::string loop = dir_.file("loop");
  ASSERT_EQ(symlink(loop.c_str(), loop.c_str()), 0);
  testing::WriteTextFile(dir_.file("m.yaml"), testing::ReadTextFile(testing::SourceDir() +
                                                                     "/examples/markers.yaml"));
  ExpectRefused("track -c " + dir_.file("m.yaml") + " -i " + loop + " -o " + dir_.file("o.csv"),
                "loop");
  ExpectRefused("track -c " + dir_.file("m.yaml") + " -i " + video_ + " -o " + loop, "loop");
}

}  // namespace
}  // namespace softsight
