// Hostile input to the commands other than `track` (whose own tests cover it): one error line
// naming the culprit, exit code 2, no input destroyed.
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/test_util.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

struct ProgramRun {
  int exit_code;
  std::string stderr_text;
};

ProgramRun RunProgram(const std::string& args, const TempDir& dir) {
  const std::string command = testing::SoftsightBinary() + " " + args + " > /dev/null 2> " +
                              dir.file("stderr.txt") + " < /dev/null";
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1,
          testing::ReadTextFile(dir.file("stderr.txt"))};
}

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

}  // namespace
}  // namespace softsight
