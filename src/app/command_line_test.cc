// The command line's own rough edges (issue 47): a mistyped word named with the nearest one, one
// meaning for -o, help wrapped to the terminal. In process, against the commands' real options:
// parsing fails before a command runs, so each case takes microseconds. One test suite: ctest
// starts the test program once per suite (or 8 tests), ~0.9 s each, more than all of these take.
#include <unistd.h>

#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/command_line.h"
#include "app/command_table.h"
#include "app/commands_plugin.h"
#include "app/commands.h"
#include "app/help_format.h"
#include "app/program_test_util.h"
#include "app/unknown_word.h"
#include "core/test_util.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

struct ParsedLine {
  int exit_code;
  std::string stderr_text;
};

// RunCommandLine on `words` (after the program's name), its stderr captured.
ParsedLine RunWords(std::vector<std::string> words) {
  words.insert(words.begin(), "softsight");
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  ::testing::internal::CaptureStderr();
  const int exit_code =
      RunCommandLine(static_cast<int>(argv.size()), argv.data(), CommandsPluginCommands());
  return {exit_code, ::testing::internal::GetCapturedStderr()};
}

TEST(CommandLine, EditDistanceCountsInsertionsDeletionsSubstitutionsAndSwaps) {
  EXPECT_EQ(EditDistance("track", "track"), 0u);
  EXPECT_EQ(EditDistance("trak", "track"), 1u);
  EXPECT_EQ(EditDistance("trakc", "track"), 1u) << "two neighbours swapped are one edit";
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(EditDistance("", "abc"), 3u);
}

TEST(CommandLine, NearestWordIsOnlyWhatIsCloseForItsLength) {
  const std::vector<std::string> commands = {"track", "track-stereo", "plot", "listen", "live"};
  EXPECT_EQ(NearestWord("trak", commands), "track");
  EXPECT_EQ(NearestWord("trak-sterio", commands), "track-stereo");
  EXPECT_EQ(NearestWord("PLOT", commands), "plot") << "case is no edit";
  EXPECT_EQ(NearestWord("lsten", commands), "listen");
  EXPECT_EQ(NearestWord("xyz", commands), std::nullopt);
  EXPECT_EQ(NearestWord("pl", commands), std::nullopt) << "2 edits are too many for 2 letters";
  const std::vector<std::string> options = {"--config", "--camera", "--input", "--output"};
  EXPECT_EQ(NearestWord("--inptu", options), "--input");
  EXPECT_EQ(NearestWord("--conf", options), "--config") << "the only option it begins";
  EXPECT_EQ(NearestWord("--ca", options), std::nullopt);
}

TEST(CommandLine, AMistypedOptionIsNamedWithTheNearestOneBeforeWhatItLeftOut) {
  // --confg left --config out: CLI11 said only "--config is required".
  ParsedLine parsed = RunWords({"track", "--confg", "m.yaml", "-i", "run.avi", "-o", "run.csv"});
  EXPECT_EQ(parsed.exit_code, 2);
  EXPECT_EQ(parsed.stderr_text,
            "softsight track: error: unknown option \"--confg\"; did you mean \"--config\"?\n");
  parsed = RunWords({"track", "-c", "m.yaml", "--inptu=run.avi", "-o", "run.csv"});
  EXPECT_EQ(parsed.stderr_text,
            "softsight track: error: unknown option \"--inptu\"; did you mean \"--input\"?\n");
  parsed = RunWords({"plot", "run.csv", "--xyz"});
  EXPECT_EQ(parsed.stderr_text,
            "softsight plot: error: unknown option \"--xyz\" (see softsight plot --help)\n");
  parsed = RunWords({"plot", "run.csv", "-O", "run.png"});
  EXPECT_EQ(parsed.stderr_text,
            "softsight plot: error: unknown option \"-O\"; did you mean \"-o\"?\n");
  parsed = RunWords({"config", "stray"});
  EXPECT_EQ(parsed.stderr_text, "softsight config: error: unexpected argument \"stray\" (see "
                                "softsight config --help)\n");
}

// Every command's options, not only track's: a typo of each one's -o.
TEST(CommandLine, EveryCommandNamesItsMistypedOptions) {
  for (const CommandSetup& command : CommandsPluginCommands()) {
    const ParsedLine parsed = RunWords({command.name, "--outptu", "x"});
    EXPECT_EQ(parsed.exit_code, 2) << command.name;
    EXPECT_THAT(parsed.stderr_text, HasSubstr(std::string("softsight ") + command.name +
                                              ": error: unknown option \"--outptu\""));
  }
}

// -o meant --csv, --out or --output depending on the command: now --output (the command's main
// output) everywhere it exists, the old long names kept.
TEST(CommandLine, DashOIsEveryCommandsMainOutputUnderItsOldNamesToo) {
  const std::map<std::string, std::vector<std::string>> expected = {
      {"track", {"output", "csv"}},       {"track-stereo", {"output", "csv"}},
      {"control", {"output", "csv"}},     {"listen", {"output", "csv"}},
      {"evaluate", {"output", "csv"}},    {"init", {"output", "out"}},
      {"pick", {"output", "out"}},        {"synth", {"output", "out"}},
      {"plot", {"output", "out"}},        {"calibrate", {"output", "out"}},
      {"demo", {"output", "out-dir"}},    {"identify", {"output"}},
      {"rig", {}},                        {"config", {}},
      {"cameras", {}},
  };
  for (const CommandSetup& command : CommandsPluginCommands()) {
    CLI::App app;
    CLI::App* sub = app.add_subcommand(command.name);
    command.setup(*sub);
    const std::vector<std::string>& names = expected.at(command.name);
    CLI::Option* output = nullptr;
    for (CLI::Option* option : sub->get_options()) {
      if (option->check_sname("o")) output = option;
    }
    if (names.empty()) {
      EXPECT_EQ(output, nullptr) << command.name << " has no main output file";
      continue;
    }
    ASSERT_NE(output, nullptr) << command.name;
    EXPECT_EQ(output->get_lnames(), names) << command.name;
  }
}

TEST(CommandLine, HelpWidthIsColumnsElseTheTerminalElse80) {
  const char* before = std::getenv("COLUMNS");
  const std::string saved = before != nullptr ? before : "";
  setenv("COLUMNS", "100", 1);
  EXPECT_EQ(HelpWidth(), 100u);
  setenv("COLUMNS", "12", 1);
  EXPECT_EQ(HelpWidth(), 40u) << "never narrower than 40";
  unsetenv("COLUMNS");
  if (isatty(STDOUT_FILENO) == 0) {
    EXPECT_EQ(HelpWidth(), 80u) << "not a terminal";
  }
  if (before != nullptr) setenv("COLUMNS", saved.c_str(), 1);
}

TEST(CommandLine, HelpTextWrapsAtSpacesAndKeepsItsIndents) {
  EXPECT_EQ(WrapText("one two three four", 9, 0), "one two\nthree\nfour");
  // From column 4 on (the caller wrote the first 4): continuations indented to it.
  EXPECT_EQ(WrapText("aaa bbb ccc", 11, 4), "aaa bbb\n    ccc");
  // An example line keeps its own indent, its continuation 4 more.
  EXPECT_EQ(WrapText("Example:\n  softsight track --config m.yaml", 24, 0),
            "Example:\n  softsight track\n      --config m.yaml");
  EXPECT_EQ(WrapText("a-very-long-word x", 5, 0), "a-very-long-word\nx");
  EXPECT_EQ(TextColumns("\xc2\xb1" "1 deg"), 6u) << "a character, not its bytes";
  EXPECT_EQ(JoinSoftLineBreaks("a line written at 90\ncolumns goes on."),
            "a line written at 90 columns goes on.");
  EXPECT_EQ(JoinSoftLineBreaks("Ends here.\nNew one:\n  softsight x\nThen\nmore"),
            "Ends here.\nNew one:\n  softsight x\nThen more");
}

// Every command's --help at 80 columns: the descriptions (up to 388 characters on one line
// before) stay within the width, in their column.
TEST(CommandLine, EveryCommandsHelpFitsTheWidth) {
  for (const size_t width : {size_t{80}, size_t{60}}) {
    for (const CommandSetup& command : CommandsPluginCommands()) {
      CLI::App app{kProgramDescription};
      app.formatter(std::make_shared<WrappingFormatter>(width));
      CLI::App* sub = app.add_subcommand(command.name, FindCommand(command.name)->summary);
      command.setup(*sub);
      std::istringstream help(sub->help());
      size_t lines = 0;
      for (std::string line; std::getline(help, line); ++lines) {
        // A single word wider than the line (a long option's name) is all that may stick out.
        const size_t start = line.find_first_not_of(' ');
        const bool one_word =
            start == std::string::npos || line.find(' ', start) == std::string::npos;
        if (!one_word) {
          EXPECT_LE(TextColumns(line), width) << command.name << ": " << line;
        }
        EXPECT_TRUE(line.empty() || line.back() != ' ') << command.name << ": '" << line << "'";
      }
      EXPECT_GT(lines, 3u) << command.name;
    }
  }
}

// The launcher alone (no plugin loaded: milliseconds): a command that does not exist.
TEST(CommandLine, TheLauncherNamesAnUnknownCommandWithTheNearestOne) {
  TempDir dir;
  testing::ProgramRun run = testing::RunProgram("trak -c m.yaml", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.stderr_text,
            "softsight: error: unknown command \"trak\"; did you mean \"track\"?\n");
  run = testing::RunProgram("--hlep", dir);
  EXPECT_EQ(run.stderr_text,
            "softsight: error: unknown option \"--hlep\"; did you mean \"--help\"?\n");
  run = testing::RunProgram("frobnicate", dir);
  EXPECT_EQ(run.stderr_text,
            "softsight: error: unknown command \"frobnicate\" (see softsight --help)\n");
  EXPECT_EQ(testing::RunProgram("", dir).stderr_text,
            "softsight: error: A subcommand is required (see softsight --help)\n");
}

// The launcher's own help, wrapped to COLUMNS.
TEST(CommandLine, TheLaunchersHelpIsWrappedToColumns) {
  TempDir dir;
  const std::string command = "COLUMNS=50 " + testing::SoftsightBinary() + " --help > " +
                              dir.file("help.txt");
  ASSERT_EQ(std::system(command.c_str()), 0);
  const std::vector<std::string> lines = testing::ReadLines(dir.file("help.txt"));
  ASSERT_GT(lines.size(), 20u);
  for (const std::string& line : lines) EXPECT_LE(TextColumns(line), 50u) << line;
  EXPECT_THAT(lines, ::testing::Contains("  track         Track markers in a video or image"));
}

}  // namespace
}  // namespace softsight
