// The flag tables (app/flag_table.h): a row registers its flag with its check and help, a shared
// row or group is the same flag on every command that takes it, and a flag that sets a config
// key says what the key's option table says. In process: parsing takes microseconds.
#include "app/flag_table.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/capture_options.h"
#include "app/cli_checks.h"
#include "app/command_line.h"
#include "app/commands.h"
#include "app/publish_options.h"
#include "app/python_hook.h"
#include "app/shared_flags.h"
#include "core/test_util.h"
#include "io/camera_options.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;

struct ToyArgs {
  int width = 640;
  std::optional<double> scale;
  bool quiet = false;
  struct Inner {
    std::string name;
  } inner;
};

const FlagTable<ToyArgs>& ToyFlags() {
  using A = ToyArgs;
  static const FlagTable<ToyArgs> table = {
      ValueFlag<A>("-w,--width", &A::width)
          .Help("Width, pixels")
          .ShowDefault()
          .Check(CLI::Range(16, 8192)),
      ValueFlag<A>("--scale", &A::scale).Help("Scale").Check(NumberIn(1e-3, 1e3)),
      SwitchFlag<A>(kQuietFlag, &A::quiet).Help("Say nothing"),
      ValueFlag<A>("--name", [](A& a) -> auto& { return a.inner.name; }).Help("A name"),
      ActionFlag<A>("--wide", [](A& a) { a.width = 1920; }).Help("1920 wide").Excludes("--width"),
  };
  return table;
}

// Parses `words` against ToyFlags; the error CLI11 raised, if any.
std::optional<std::string> ParseToy(std::vector<std::string> words, ToyArgs* args) {
  CLI::App app;
  AddFlags(app, ToyFlags(), args);
  words.insert(words.begin(), "toy");
  std::vector<const char*> argv;
  for (const std::string& word : words) argv.push_back(word.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return std::string(e.what());
  }
  return std::nullopt;
}

TEST(FlagTable, RowsLandInTheirFieldsThroughMembersAndFunctions) {
  ToyArgs args;
  ASSERT_EQ(ParseToy({"-w", "800", "--scale", "2.5", "-q", "--name", "tip"}, &args), std::nullopt);
  EXPECT_EQ(args.width, 800);
  EXPECT_EQ(args.scale, 2.5);
  EXPECT_TRUE(args.quiet);
  EXPECT_EQ(args.inner.name, "tip");
  ToyArgs wide;
  ASSERT_EQ(ParseToy({"--wide"}, &wide), std::nullopt);
  EXPECT_EQ(wide.width, 1920);
  ToyArgs none;
  ASSERT_EQ(ParseToy({}, &none), std::nullopt);
  EXPECT_EQ(none.width, 640) << "an absent flag leaves the default";
  EXPECT_EQ(none.scale, std::nullopt);
}

TEST(FlagTable, ARowsCheckRefusesWithTheFlagsName) {
  ToyArgs args;
  const std::optional<std::string> error = ParseToy({"--width", "5"}, &args);
  ASSERT_TRUE(error.has_value());
  EXPECT_THAT(*error, HasSubstr("--width"));
  EXPECT_THAT(*error, HasSubstr("5"));
  EXPECT_THAT(ParseToy({"--scale", "nan"}, &args).value_or(""), HasSubstr("--scale"));
  EXPECT_THAT(ParseToy({"--wide", "--width", "800"}, &args).value_or(""), HasSubstr("excludes"));
}

TEST(FlagTable, HelpShowsTheRowsHelpAndDefault) {
  CLI::App app;
  ToyArgs args;
  AddFlags(app, ToyFlags(), &args);
  const std::string help = app.help();
  EXPECT_THAT(help, HasSubstr("Width, pixels"));
  EXPECT_THAT(help, HasSubstr("640")) << "ShowDefault";
  EXPECT_THAT(help, HasSubstr("Say nothing"));
}

// Through the whole command line: a range check refused is one line naming the flag.
TEST(FlagTable, ACommandsRangeCheckIsOneErrorLineNamingTheFlag) {
  testing::TempDir dir;
  const std::string config = dir.file("m.yaml");
  std::ofstream(config) << "markers: []\n";  // Exists: --config's own check passes.
  const std::vector<CommandSetup> commands = {{"track", SetupTrackCommand}};
  std::vector<std::string> words = {"softsight", "track", "-c",    config,          "-i",
                                    "a.avi",     "-o",    "a.csv", "--publish-hwm", "0"};
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  ::testing::internal::CaptureStderr();
  const int exit_code = RunCommandLine(static_cast<int>(argv.size()), argv.data(), commands);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(exit_code, 2);
  EXPECT_THAT(err, HasSubstr("softsight track: error: "));
  EXPECT_THAT(err, HasSubstr("--publish-hwm"));
  EXPECT_THAT(err, HasSubstr("Value 0 not in range 1 to 1000000"));
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

// The names of every flag `setup` adds.
std::vector<std::string> FlagNames(CommandRunner (*setup)(CLI::App&)) {
  CLI::App app;
  CLI::App* sub = app.add_subcommand("command");
  setup(*sub);
  std::vector<std::string> names;
  for (const CLI::Option* option : sub->get_options()) {
    for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
  }
  return names;
}

template <typename Args>
std::vector<std::string> TableNames(const FlagTable<Args>& table) {
  std::vector<std::string> names;
  for (const Flag<Args>& flag : table) {
    CLI::App app;
    Args args{};
    CLI::Option* option = flag.bind(app, args, flag);
    for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
  }
  return names;
}

TEST(FlagTable, ASharedGroupIsOnEveryCommandThatTakesIt) {
  using Setup = CommandRunner (*)(CLI::App&);
  const std::map<std::string, Setup> publishing = {{"track", SetupTrackCommand},
                                                   {"control", SetupControlCommand},
                                                   {"identify", SetupIdentifyCommand},
                                                   {"track-stereo", SetupTrackStereoCommand}};
  const std::map<std::string, Setup> hooked = {{"track", SetupTrackCommand},
                                               {"control", SetupControlCommand}};
  const std::map<std::string, Setup> camera = {{"track", SetupTrackCommand},
                                               {"control", SetupControlCommand}};
  const std::vector<std::pair<std::vector<std::string>, const std::map<std::string, Setup>*>>
      groups = {{TableNames(PublishFlags()), &publishing},
                {TableNames(HookFlags()), &hooked},
                {TableNames(CaptureFlags()), &camera}};
  for (const auto& [group, commands] : groups) {
    ASSERT_FALSE(group.empty());
    for (const auto& [name, setup] : *commands) {
      const std::vector<std::string> names = FlagNames(setup);
      for (const std::string& flag : group) {
        EXPECT_THAT(names, ::testing::Contains(flag)) << name;
      }
    }
  }
  // A shared row: -q,--quiet on every command that is quiet, the same flag.
  for (const Setup setup :
       {SetupTrackCommand, SetupControlCommand, SetupSynthCommand, SetupEvaluateCommand,
        SetupDemoCommand, SetupListenCommand, SetupRigCommand, SetupIdentifyCommand}) {
    CLI::App app;
    CLI::App* sub = app.add_subcommand("command");
    setup(*sub);
    const CLI::Option* quiet = sub->get_option_no_throw("--quiet");
    ASSERT_NE(quiet, nullptr);
    EXPECT_TRUE(quiet->check_sname("q"));
  }
}

// A flag that sets a config key: its help is the key's doc, unit and range from the table.
TEST(FlagTable, AConfigKeysFlagTakesItsHelpFromTheOptionTable) {
  const Option<CameraSettings>* fps = nullptr;
  for (const Option<CameraSettings>& option : CameraSettingsTable()) {
    if (option.key == "fps") fps = &option;
  }
  ASSERT_NE(fps, nullptr);
  CLI::App app;
  CLI::App* sub = app.add_subcommand("track");
  SetupTrackCommand(*sub);
  const CLI::Option* flag = sub->get_option("--camera-fps");
  EXPECT_THAT(flag->get_description(), HasSubstr(fps->doc));
  EXPECT_THAT(flag->get_description(), HasSubstr(OptionRangeText(*fps)));
  EXPECT_THAT(flag->get_description(), HasSubstr("(config: capture.fps)"));
  EXPECT_EQ(ConfigKeyHelp(*fps, "capture.fps"), flag->get_description());
}

}  // namespace
}  // namespace softsight
