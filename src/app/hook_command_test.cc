// `--hook FILE.py` end to end (docs/usage.md, "A per-frame hook"): a Python hook's column in
// track's CSV and stream with the values it computed from the markers; a hook that raises is
// reported once with its traceback and the run goes on (or stops with one line); a bad hook file
// is one error line naming it, exit 2, no CSV.
#include <chrono>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/program_test_util.h"
#include "app/scene_markers_test_util.h"
#include "app/track_command.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/io/csv_reader.h"
#include "stream/subscriber.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::ReadTextFile;
using testing::RunProgram;
using testing::TempDir;
using testing::WriteTextFile;

// The sum of the three markers' x (when all are found) and the frame's mean green: one value
// the CSV's own columns check, one that only the image gives.
constexpr const char* kSumHook = R"py(
columns = ["x_sum", "mean_green"]

def on_frame(frame, result):
    values = {"mean_green": float(frame[:, :, 1].mean())}
    if all(m.found for m in result.markers):
        values["x_sum"] = result["red"].x + result["blue"].x + result["green"].x
    return values
)py";

std::string HookRunArgs(const TempDir& dir, const std::string& hook, int frames) {
  WriteTextFile(dir.file("markers.yaml"), testing::kScaledSceneMarkersYaml);
  WriteTextFile(dir.file("h.py"), hook);
  return "track --config " + dir.file("markers.yaml") + " --input synth:bending --max-frames " +
         std::to_string(frames) + " --csv " + dir.file("run.csv") + " --hook " + dir.file("h.py");
}

// RunTrack's error with `hook` as --hook when that file does not exist.
std::string MissingHookError(const TempDir& dir, const std::string& hook) {
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.source.input = "synth:bending";
  options.csv_file = dir.file("run.csv");
  options.quiet = true;
  options.hook.file = hook;
  try {
    RunTrack(options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

void ExpectSumsMatch(const CsvTable& csv, size_t row, const std::optional<double>& sum) {
  const auto x = [&](const char* name) { return csv.values[csv.find(name).value()][row]; };
  if (x("red_x") && x("blue_x") && x("green_x")) {
    ASSERT_TRUE(sum) << "row " << row;
    EXPECT_NEAR(*sum, *x("red_x") + *x("blue_x") + *x("green_x"), 1e-3) << "row " << row;
  } else {
    EXPECT_FALSE(sum) << "row " << row;
  }
}

TEST(HookCommand, TrackWritesTheHooksColumnToTheCsvAndTheStream) {
  TempDir dir;
  WriteTextFile(dir.file("markers.yaml"), testing::kScaledSceneMarkersYaml);
  WriteTextFile(dir.file("h.py"), kSumHook);
  TrackOptions options;
  options.config_file = dir.file("markers.yaml");
  options.source.input = "synth:bending";
  options.csv_file = dir.file("run.csv");
  options.max_frames = 20;
  options.quiet = true;
  options.hook.file = dir.file("h.py");
  PublishOptions publish;
  publish.endpoint = "ipc://" + dir.file("s.ipc");
  publish.wait_subscribers = 1;
  options.publish = publish;
  StreamSubscriber records(publish.endpoint, {"hello", "frame", "end"}, "test");
  auto tracked = std::async(std::launch::async, [&] { return RunTrack(options); });
  std::optional<nlohmann::ordered_json> hello;
  std::vector<nlohmann::ordered_json> frames;
  bool ended = false;
  for (int waits = 0; !ended && waits < 600;) {
    const std::optional<StreamMessage> message = records.receive(100);
    if (!message) {
      ++waits;
      continue;
    }
    const nlohmann::ordered_json body = nlohmann::ordered_json::parse(message->body);
    if (message->topic == "hello") hello = body;
    if (message->topic == "frame") frames.push_back(body);
    ended = message->topic == "end";
  }
  const RunSummary summary = tracked.get();
  ASSERT_TRUE(ended);
  ASSERT_TRUE(hello);
  const CsvTable csv = ReadCsvTable(options.csv_file);
  ASSERT_EQ(csv.row_count(), 20u);
  const size_t sum = csv.find("x_sum").value(), green = csv.find("mean_green").value();
  EXPECT_EQ((*hello)["columns"].get<std::vector<std::string>>(), csv.columns);
  ASSERT_EQ(frames.size(), 20u);
  int summed = 0;
  for (size_t r = 0; r < 20; ++r) {
    ExpectSumsMatch(csv, r, csv.values[sum][r]);
    summed += csv.values[sum][r] ? 1 : 0;
    ASSERT_TRUE(csv.values[green][r]);
    EXPECT_GT(*csv.values[green][r], 0.0);
    EXPECT_LT(*csv.values[green][r], 255.0);
    // The stream's record has the same value as the row.
    const nlohmann::ordered_json& value = frames[r]["x_sum"];
    if (csv.values[sum][r]) {
      ASSERT_TRUE(value.is_number()) << r;
      EXPECT_NEAR(value.get<double>(), *csv.values[sum][r], 1e-3);
    } else {
      EXPECT_TRUE(value.is_null()) << r;
    }
  }
  EXPECT_GE(summed, 15) << "the markers are found in most frames";
  EXPECT_THAT(summary.notes, ::testing::Contains(HasSubstr("values in 20 of 20 rows")));
}

TEST(HookCommand, ARaisingHookIsReportedOnceWithItsTracebackAndTheRunGoesOn) {
  TempDir dir;
  const std::string hook = R"py(
columns = ["inverse"]

def on_frame(frame, result):
    return {"inverse": 1 / (5 - result.frame)}
)py";
  const testing::ProgramRun run = RunProgram(HookRunArgs(dir, hook, 10) + " --brief", dir);
  EXPECT_EQ(run.exit_code, 0) << run.stderr_text;
  const size_t traceback = run.stderr_text.find("Traceback (most recent call last)");
  ASSERT_NE(traceback, std::string::npos) << run.stderr_text;
  EXPECT_EQ(run.stderr_text.find("Traceback (most", traceback + 1), std::string::npos) << "once";
  EXPECT_THAT(run.stderr_text, HasSubstr("ZeroDivisionError: division by zero"));
  EXPECT_THAT(run.stderr_text, HasSubstr("line 5, in on_frame"));
  const CsvTable csv = ReadCsvTable(dir.file("run.csv"));
  ASSERT_EQ(csv.row_count(), 10u) << "every row, whole";
  const size_t inverse = csv.find("inverse").value();
  for (size_t r = 0; r < 10; ++r) EXPECT_EQ(csv.values[inverse][r].has_value(), r < 5) << r;

  // With --hook-stop-on-error: one line, and the rows before it.
  const testing::ProgramRun stopped =
      RunProgram(HookRunArgs(dir, hook, 10) + " --quiet --hook-stop-on-error", dir);
  EXPECT_NE(stopped.exit_code, 0);
  EXPECT_THAT(stopped.stderr_text,
              HasSubstr("hook " + dir.file("h.py") +
                        " failed at frame 5: ZeroDivisionError: division by zero\n"));
  EXPECT_EQ(ReadCsvTable(dir.file("run.csv")).row_count(), 5u);
}

TEST(HookCommand, ABadHookFileIsOneErrorLineNamingItAndNoCsv) {
  TempDir dir;
  const std::string h = dir.file("h.py");
  // The program: one line, exit 2, no CSV.
  const testing::ProgramRun run =
      RunProgram(HookRunArgs(dir, "columns = ['a'\ndef on_frame(f, r): pass\n", 3) + " --quiet", dir);
  EXPECT_EQ(run.exit_code, 2) << run.stderr_text;
  EXPECT_EQ(std::count(run.stderr_text.begin(), run.stderr_text.end(), '\n'), 1) << run.stderr_text;
  EXPECT_THAT(run.stderr_text, HasSubstr(h + ": cannot load the hook: SyntaxError: "));
  EXPECT_FALSE(std::filesystem::exists(dir.file("run.csv"))) << "refused before the CSV";

  // Each bad file's message, from RunTrack (what main() prints after "error: ").
  const auto error_of = [&](const std::string& hook) -> std::string {
    WriteTextFile(h, hook);
    TrackOptions options;
    options.config_file = dir.file("markers.yaml");
    options.source.input = "synth:bending";
    options.csv_file = dir.file("run.csv");
    options.max_frames = 3;
    options.quiet = true;
    options.hook.file = h;
    try {
      RunTrack(options);
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      return e.what();
    }
    return "no error";
  };
  EXPECT_THAT(error_of("import no_such_module_here\n"),
              HasSubstr(h + ": cannot load the hook: ModuleNotFoundError: No module named "
                            "'no_such_module_here'"));
  EXPECT_THAT(error_of("columns = ['a']\n"), HasSubstr(h + ": no function on_frame(frame, result) in it"));
  EXPECT_THAT(error_of("def on_frame(f, r): pass\n"), HasSubstr(h + ": no `columns` in it"));
  EXPECT_THAT(error_of("columns = 'a'\ndef on_frame(f, r): pass\n"),
              HasSubstr(h + ": columns must be a list of str"));
  EXPECT_THAT(error_of("columns = ['red_x']\ndef on_frame(f, r): pass\n"),
              HasSubstr("hook " + h + ": column 'red_x' is already a column of the run"));
  EXPECT_THAT(error_of("columns = ['a']\ndef on_frame(f, r): return {'a': 'fast'}\n"),
              HasSubstr("hook " + h + " at frame 0: on_frame returned 'fast' for 'a': not a number"));
  EXPECT_THAT(error_of("columns = ['a']\ndef on_frame(f, r): return {'b': 1}\n"),
              HasSubstr("hook " + h + " at frame 0: 'b' is not one of the hook's columns (a)"));
  EXPECT_THAT(error_of("columns = ['a']\ndef on_frame(f, r): return 3\n"),
              HasSubstr("on_frame returned 3: it returns a dict of column name -> number, or None"));
  std::filesystem::remove(h);
  EXPECT_EQ(MissingHookError(dir, h), "--hook " + h + ": no such file");
}

}  // namespace
}  // namespace softsight
