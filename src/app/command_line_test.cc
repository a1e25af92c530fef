// The command line's own rough edges (issue 47): help wrapped to the terminal. In process,
// against the commands' real options, each case takes microseconds.
#include <unistd.h>

#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/command_line.h"
#include "app/command_table.h"
#include "app/commands.h"
#include "app/help_format.h"
#include "core/test_util.h"

namespace softsight {
namespace {

using testing::TempDir;

// Every command of the commands plugin (plugin_commands.cc; `live` is the live plugin's own).
const std::vector<CommandSetup>& PluginCommands() {
  static const std::vector<CommandSetup> commands = {
      {"demo", SetupDemoCommand},           {"track", SetupTrackCommand},
      {"init", SetupInitCommand},           {"pick", SetupPickCommand},
      {"synth", SetupSynthCommand},         {"evaluate", SetupEvaluateCommand},
      {"calibrate", SetupCalibrateCommand}, {"control", SetupControlCommand},
      {"identify", SetupIdentifyCommand},   {"rig", SetupRigCommand},
      {"plot", SetupPlotCommand},           {"config", SetupConfigCommand},
      {"cameras", SetupCamerasCommand},     {"listen", SetupListenCommand},
      {"track-stereo", SetupTrackStereoCommand},
  };
  return commands;
}

TEST(HelpFormat, WidthIsColumnsElseTheTerminalElse80) {
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

TEST(HelpFormat, TextWrapsAtSpacesAndKeepsItsIndents) {
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
TEST(HelpFormat, EveryCommandsHelpFitsTheWidth) {
  for (const size_t width : {size_t{80}, size_t{60}}) {
    for (const CommandSetup& command : PluginCommands()) {
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

// The launcher's own help, wrapped to COLUMNS.
TEST(Launcher, HelpIsWrappedToColumns) {
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
