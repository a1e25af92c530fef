// HookSink: a hook's values land in the CSV row of the frame they were computed on, a hook that
// throws is reported once and the rows after it stay whole, and a hook that is slow (held on a
// latch the test controls: no clock in these tests) skips frames without holding up the run.
#include "softsight/pipeline/hook.h"

#include <cmath>
#include <condition_variable>
#include <functional>
#include <mutex>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/test_util.h"
#include "pipeline/scene_config_test_util.h"
#include "softsight/core/error.h"
#include "softsight/io/csv_reader.h"
#include "softsight/io/frame_source.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/sim/scene.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::SmallScene;
using testing::TempDir;
using testing::ThreeMarkerSceneConfig;

// A hook given as a function, with its columns.
class FunctionHook : public FrameHook {
 public:
  using Function = std::function<void(const Frame&, const FrameResult&, HookValues&)>;
  FunctionHook(std::vector<std::string> columns, Function function)
      : columns_(std::move(columns)), function_(std::move(function)) {}
  std::vector<std::string> columns() const override { return columns_; }
  void on_frame(const Frame& frame, const FrameResult& result, HookValues& out) override {
    function_(frame, result, out);
  }

 private:
  std::vector<std::string> columns_;
  Function function_;
};

// red_x + 1000 on even frames (odd ones left unset), and the frame's own index.
void RedPlusThousand(const Frame& frame, const FrameResult& result, HookValues& out) {
  if (result.frame_index % 2 == 0 && result.markers[0].observation.found()) {
    out.set("red_x_plus", result.markers[0].observation.position_px->x + 1000.0);
  }
  out.set(size_t{1}, static_cast<double>(frame.index));
}

struct HookRun {
  RunSummary summary;
  CsvTable csv;
  std::vector<std::string> lines;
};

HookRun RunWithHook(const TempDir& dir, HookSink& hook, int frames,
                    std::vector<FrameSink*> after = {}) {
  std::unique_ptr<FrameSource> source = OpenSyntheticSource(SmallScene(frames), NoiseOptions{});
  const TrackingConfig config = ThreeMarkerSceneConfig();
  TrackingSession session(config);
  const CsvColumnTable table = TrackingColumns(config);
  hook.check_against(table);
  CsvSink csv(dir.file("run.csv"), TrackingColumns(config, hook.columns()));
  std::vector<FrameSink*> sinks = {&hook, &csv};
  sinks.insert(sinks.end(), after.begin(), after.end());
  HookRun run;
  run.summary = RunPipeline(*source, session, sinks);
  run.csv = ReadCsvTable(dir.file("run.csv"));
  run.lines = testing::ReadLines(dir.file("run.csv"));
  return run;
}

// Every row has as many fields as the header: none is broken.
void ExpectWholeRows(const HookRun& run) {
  const size_t columns = testing::SplitCsv(run.lines.at(0)).size();
  for (size_t i = 1; i < run.lines.size(); ++i) {
    EXPECT_EQ(testing::SplitCsv(run.lines[i]).size(), columns) << "row " << i;
    EXPECT_EQ(run.lines[i].find("nan"), std::string::npos) << run.lines[i];
  }
}

TEST(HookSink, ValuesLandInTheColumnsOfTheirOwnFrameBeforeTheTimings) {
  TempDir dir;
  FunctionHook hook({"red_x_plus", "frame_seen"}, RedPlusThousand);
  HookSink sink(hook);
  const HookRun run = RunWithHook(dir, sink, 8);
  ASSERT_TRUE(run.summary.ok()) << run.summary.error;
  ASSERT_EQ(run.csv.row_count(), 8u);
  const size_t plus = run.csv.find("red_x_plus").value(), seen = run.csv.find("frame_seen").value();
  EXPECT_EQ(seen, plus + 1);
  EXPECT_LT(seen, run.csv.find("latency_result_ms").value()) << "the hook's columns before the timings";
  const size_t red_x = run.csv.find("red_x").value(), frame = run.csv.find("frame").value();
  for (size_t r = 0; r < 8; ++r) {
    EXPECT_EQ(run.csv.values[seen][r], run.csv.values[frame][r]);
    if (r % 2 == 0) {
      ASSERT_TRUE(run.csv.values[red_x][r]);
      EXPECT_NEAR(*run.csv.values[plus][r], *run.csv.values[red_x][r] + 1000.0, 1e-3) << r;
    } else {
      EXPECT_FALSE(run.csv.values[plus][r]) << "a value not given is an empty field, row " << r;
    }
  }
  ExpectWholeRows(run);
  EXPECT_EQ(sink.ran(), 8);
  EXPECT_EQ(sink.skipped(), 0);
  EXPECT_EQ(sink.call_ms().size(), 8u);
  EXPECT_THAT(run.summary.notes, ::testing::Contains(HasSubstr("hook: values in 8 of 8 rows")));
}

TEST(HookSink, OnItsOwnThreadWithTimeToSpareEveryRowStillGetsItsValues) {
  TempDir dir;
  FunctionHook hook({"red_x_plus", "frame_seen"}, RedPlusThousand);
  HookOptions options;
  options.wait_ms = 1e6;  // Far more than the hook needs: never late.
  HookSink sink(hook, options);
  const HookRun run = RunWithHook(dir, sink, 6);
  ASSERT_TRUE(run.summary.ok()) << run.summary.error;
  const size_t seen = run.csv.find("frame_seen").value();
  for (size_t r = 0; r < 6; ++r) EXPECT_EQ(run.csv.values[seen][r], static_cast<double>(r));
  EXPECT_EQ(sink.ran(), 6);
  EXPECT_EQ(sink.skipped() + sink.late(), 0);
}

TEST(HookSink, AThrowingHookIsReportedOnceAndTheRowsAfterItAreWhole) {
  TempDir dir;
  int calls = 0;
  FunctionHook hook({"red_x_plus", "frame_seen"},
                    [&](const Frame& frame, const FrameResult& result, HookValues& out) {
                      ++calls;
                      RedPlusThousand(frame, result, out);  // Set, then thrown: not in the row.
                      if (frame.index == 3) throw std::runtime_error("Traceback...\nValueError: boom");
                    });
  std::vector<std::string> reported;
  HookOptions options;
  options.on_error = [&](const std::string& error) { reported.push_back(error); };
  HookSink sink(hook, options);
  const HookRun run = RunWithHook(dir, sink, 8);
  ASSERT_TRUE(run.summary.ok()) << "the run goes on: " << run.summary.error;
  EXPECT_EQ(run.summary.frames, 8);
  EXPECT_EQ(calls, 4) << "switched off after its failure";
  ASSERT_EQ(reported.size(), 1u);
  EXPECT_EQ(reported[0], "Traceback...\nValueError: boom");
  const size_t seen = run.csv.find("frame_seen").value();
  for (size_t r = 0; r < 8; ++r) {
    EXPECT_EQ(run.csv.values[seen][r].has_value(), r < 3) << r;
  }
  ExpectWholeRows(run);
  EXPECT_THAT(run.summary.notes,
              ::testing::Contains(HasSubstr("hook: failed at frame 3 (ValueError: boom), switched off")));
}

TEST(HookSink, WithStopOnErrorTheRunEndsWithOneErrorLine) {
  TempDir dir;
  FunctionHook hook({"frame_seen"}, [](const Frame& frame, const FrameResult&, HookValues& out) {
    out.set(size_t{0}, 1.0);
    if (frame.index == 2) throw std::runtime_error("Traceback...\nValueError: boom");
  });
  HookOptions options;
  options.stop_on_error = true;
  HookSink sink(hook, options);
  const HookRun run = RunWithHook(dir, sink, 8);
  EXPECT_EQ(run.summary.stop_reason, StopReason::kError);
  EXPECT_EQ(run.summary.error, "hook failed at frame 2: ValueError: boom");
  EXPECT_EQ(run.csv.row_count(), 2u) << "rows before the failure, whole";
  ExpectWholeRows(run);
}

TEST(HookSink, AnUnknownColumnEndsTheRunNamingIt) {
  TempDir dir;
  FunctionHook hook({"speed"}, [](const Frame&, const FrameResult&, HookValues& out) {
    out.set("sped", 1.0);
  });
  HookSink sink(hook);
  const HookRun run = RunWithHook(dir, sink, 4);
  EXPECT_EQ(run.summary.stop_reason, StopReason::kError);
  EXPECT_EQ(run.summary.error, "hook at frame 0: 'sped' is not one of the hook's columns (speed)");
}

TEST(HookSink, BadColumnNamesAreRefusedBeforeTheRun) {
  const auto refused = [](std::vector<std::string> columns) {
    FunctionHook hook(std::move(columns), [](const Frame&, const FrameResult&, HookValues&) {});
    try {
      HookSink sink(hook);
      sink.check_against(TrackingColumns({"red"}, false));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refused({"a,b"}), "hook: column 'a,b' is not a name of letters, digits and _");
  EXPECT_EQ(refused({"x", "x"}), "hook: column 'x' is named twice");
  EXPECT_EQ(refused({"red_x"}),
            "hook: column 'red_x' is already a column of the run (choose another name)");
  EXPECT_EQ(refused({"speed"}), "");
}

// Opens once; waits until then.
class Latch {
 public:
  void open() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      open_ = true;
    }
    opened_.notify_all();
  }
  void wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    opened_.wait(lock, [this] { return open_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable opened_;
  bool open_ = false;
};

// Opens the latch when the run reaches frame `at`: the run got there with the hook held.
class OpenAt : public FrameSink {
 public:
  OpenAt(Latch& latch, int64_t at) : latch_(latch), at_(at) {}
  void consume(const Frame& frame, const FrameResult&) override {
    if (frame.index == at_) latch_.open();
  }

 private:
  Latch& latch_;
  int64_t at_;
};

TEST(HookSink, ASlowHookSkipsFramesWithoutHoldingUpTheRunAndSaysHowMany) {
  TempDir dir;
  Latch latch;
  FunctionHook hook({"frame_seen"}, [&](const Frame& frame, const FrameResult&, HookValues& out) {
    if (frame.index == 0) latch.wait();  // Held until the run has gone on to frame 10.
    out.set(size_t{0}, static_cast<double>(frame.index));
  });
  HookOptions options;
  options.wait_ms = 0.0;
  HookSink sink(hook, options);
  OpenAt open(latch, 10);
  const HookRun run = RunWithHook(dir, sink, 16, {&open});
  ASSERT_TRUE(run.summary.ok()) << run.summary.error;
  EXPECT_EQ(run.summary.frames, 16) << "the run was not held by the hook";
  EXPECT_GE(sink.skipped(), 10) << "frames 1..10 came while it was busy";
  EXPECT_GE(sink.late(), 1) << "frame 0's values came after its row";
  EXPECT_EQ(sink.ran() + sink.skipped() + sink.late(), 16);
  // Whatever reached a row is that row's frame's value, never another's.
  const size_t seen = run.csv.find("frame_seen").value();
  for (size_t r = 0; r < 16; ++r) {
    if (r <= 10) {
      EXPECT_FALSE(run.csv.values[seen][r]) << r;
    }
    if (run.csv.values[seen][r]) {
      EXPECT_EQ(*run.csv.values[seen][r], static_cast<double>(r));
    }
  }
  ExpectWholeRows(run);
  EXPECT_THAT(run.summary.notes,
              ::testing::Contains(HasSubstr("skipped " + std::to_string(sink.skipped()) +
                                            " of 16 frames (still busy)")));
}

TEST(HookValues, NotFiniteIsAnEmptyFieldAndClearKeepsTheColumns) {
  HookValues values({"a", "b"});
  values.set("a", 1.5);
  values.set(size_t{1}, std::nan(""));
  EXPECT_EQ(values.get(0), 1.5);
  EXPECT_FALSE(values.get(1));
  values.clear();
  EXPECT_FALSE(values.get(0));
  EXPECT_EQ(values.size(), 2u);
}

}  // namespace
}  // namespace softsight
