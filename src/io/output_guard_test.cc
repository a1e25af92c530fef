#include "softsight/io/output_guard.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "softsight/core/error.h"
#include "softsight/io/csv_writer.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class OutputGuardTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("softsight_output_guard_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::permissions(dir_ / "locked", fs::perms::owner_all, ignored);
    fs::remove_all(dir_, ignored);
  }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(file(name), std::ios::binary) << text;
  }
  std::string Read(const std::string& name) const {
    std::ifstream in(file(name), std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  // The message of the InputError CheckOutputsAreNotInputs throws, or "" when it accepts.
  static std::string Refusal(const std::vector<PathRole>& outputs,
                             const std::vector<PathRole>& inputs) {
    try {
      CheckOutputsAreNotInputs(outputs, inputs);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(OutputGuardTest, AnOutputThatIsAnInputThroughAnyNameIsRefused) {
  Write("rig.yaml", "markers: []\n");
  fs::create_symlink(file("rig.yaml"), file("link.yaml"));
  const std::vector<PathRole> inputs{{"the config", file("rig.yaml")}};
  for (const std::string& same :
       {file("rig.yaml"), (dir_ / "." / "rig.yaml").string(),
        (dir_ / ".." / dir_.filename() / "rig.yaml").string(), file("link.yaml")}) {
    EXPECT_THAT(Refusal({{"--csv", same}}, inputs),
                HasSubstr("is the config " + file("rig.yaml") + ": refusing to overwrite an input"))
        << same;
  }
  EXPECT_EQ(Refusal({{"--csv", file("run.csv")}}, inputs), "");
  EXPECT_EQ(Read("rig.yaml"), "markers: []\n");
}

TEST_F(OutputGuardTest, TwoOutputsWithOneNameAreRefusedAlsoBeforeEitherExists) {
  const std::vector<PathRole> outputs{{"--csv", file("x.csv")},
                                      {"--annotated", (dir_ / "." / "x.csv").string()}};
  EXPECT_THAT(Refusal(outputs, {}), HasSubstr("are the same file: give each output its own name"));
  EXPECT_FALSE(fs::exists(file("x.csv")));
  EXPECT_EQ(Refusal({{"--csv", file("x.csv")}, {"--annotated", file("x.avi")}}, {}), "");
  // An output not given (empty) is no output.
  EXPECT_EQ(Refusal({{"--csv", file("x.csv")}, {"--metrics-csv", ""}, {"-o", ""}}, {}), "");
  // Relative names, one with "./", in the working folder (a shell user's `-o y.csv
  // --annotated ./y.csv`): the same file, though nothing of either exists yet.
  const fs::path before = fs::current_path();
  fs::current_path(dir_);
  const std::string relative = Refusal({{"--csv", "y.csv"}, {"--annotated", "./y.csv"}}, {});
  const std::string other = Refusal({{"--csv", "./y.csv"}, {"--annotated", "y.csv"}}, {});
  fs::current_path(before);
  EXPECT_THAT(relative, HasSubstr("are the same file"));
  EXPECT_THAT(other, HasSubstr("are the same file"));
}

TEST_F(OutputGuardTest, OutputsThatCannotBeWrittenAreRefusedBeforeAnyWork) {
  EXPECT_THAT(Refusal({{"-o", file("missing/tuned.yaml")}}, {}),
              HasSubstr("-o " + file("missing/tuned.yaml") + ": the folder"));
  EXPECT_THAT(Refusal({{"-o", dir_.string()}}, {}), HasSubstr("is a folder"));
  fs::create_symlink(file("loop_a"), file("loop_b"));
  fs::create_symlink(file("loop_b"), file("loop_a"));
  EXPECT_THAT(Refusal({{"--csv", file("loop_a")}}, {}), HasSubstr("a loop of symbolic links"));
  EXPECT_THAT(Refusal({{"--csv", file("ok.csv")}}, {{"--input", file("loop_b")}}),
              HasSubstr("--input " + file("loop_b") + ": a loop of symbolic links"));
  if (::geteuid() != 0) {  // root writes anywhere: the refusal cannot be seen then.
    fs::create_directories(dir_ / "locked");
    fs::permissions(dir_ / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_THAT(Refusal({{"-o", file("locked/tuned.yaml")}}, {}), HasSubstr("cannot write there"));
  }
}

TEST_F(OutputGuardTest, APatternThatWouldWriteAnInputsNameIsRefused) {
  Write("0003.png", "x");
  EXPECT_THAT(Refusal({{"--record", file("%04d.png")}}, {{"--input", file("0003.png")}}),
              HasSubstr("would write --input"));
  EXPECT_EQ(Refusal({{"--record", file("%04d.png")}}, {{"--input", file("frame3.png")}}), "");
}

TEST_F(OutputGuardTest, ASecondWriterOfTheSameCsvIsRefusedAndTheFirstFileStaysWhole) {
  const std::string path = file("run.csv");
  CsvColumnTable columns;
  columns.add(NumberColumn("a", [](const FrameResult&) { return std::optional<double>(1.0); }));
  CsvWriter first(path, columns);
  FrameResult row;
  row.frame_index = 0;
  first.write(row);
  const std::string before = Read("run.csv");
  try {
    CsvWriter second(path, columns);
    ADD_FAILURE() << "a second writer was let in";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("another program is writing this file"));
  }
  EXPECT_EQ(Read("run.csv"), before);
  first.write(row);
  EXPECT_EQ(Read("run.csv"), before + before.substr(before.find('\n') + 1));
}

TEST_F(OutputGuardTest, AWholeFileIsReplacedAtOnceAndAFailedWriteKeepsTheOldOne) {
  Write("gains.yaml", "old\n");
  WriteWholeFileOrThrow(file("gains.yaml"), "new\n");
  EXPECT_EQ(Read("gains.yaml"), "new\n");
  EXPECT_FALSE(fs::exists(file("gains.yaml.part")));
  EXPECT_THROW(WriteWholeFileOrThrow(file("missing/gains.yaml"), "x"), InputError);
  WriteWholeFileOrThrow("/dev/null", "to a device, in place");
  if (fs::exists("/dev/full")) {
    EXPECT_THROW(WriteWholeFileOrThrow("/dev/full", std::string(1 << 16, 'x')), InputError);
  }
}

}  // namespace
}  // namespace softsight
