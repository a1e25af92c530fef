// A per-frame hook: user code that sees every frame and its result and may add its own numeric
// columns to the run's CSV and stream (`--hook file.py` in the program, `hook=` in Python, a
// FrameHook for library users). The hook cannot stall a live loop nor break a row:
//   * its columns are named before the run, so the CSV header and the stream's hello have them;
//     a value it did not give for a frame is an empty field (never nan, never a missing field);
//   * on a camera it runs on its own thread (HookOptions::wait_ms): the loop waits at most that
//     long for a frame's values, and frames that arrive while it is still busy are skipped by
//     the hook (counted, and said in the summary);
//   * a hook that throws is reported once, switched off, and the run goes on without it (or,
//     with HookOptions::stop_on_error, the run stops with one error line).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "softsight/core/types.h"
#include "softsight/io/csv_columns.h"
#include "softsight/pipeline/sink.h"

namespace softsight {

// The values a hook gives for one frame, one slot per declared column. Cleared before each call.
class HookValues {
 public:
  explicit HookValues(std::vector<std::string> names = {});

  const std::vector<std::string>& names() const { return names_; }
  size_t size() const { return names_.size(); }
  std::optional<size_t> find(std::string_view name) const;

  // Sets column `column` (its index in FrameHook::columns()). A value that is not finite (nan,
  // inf) leaves the field empty: the CSV never holds nan.
  void set(size_t column, double value);
  // By name; throws InputError naming the column and the declared ones when there is none such:
  // a hook's bug that ends the run (RunPipeline reports it as the run's error).
  void set(std::string_view name, double value);
  std::optional<double> get(size_t column) const;
  void clear();
  // Copies `other`'s values (same columns) without allocating.
  void assign(const HookValues& other);

 private:
  std::vector<std::string> names_;
  std::vector<double> values_;
  std::vector<char> given_;
};

class FrameHook {
 public:
  virtual ~FrameHook() = default;
  // The names of the columns the hook may fill, asked once before the run. Each must be a word
  // of letters, digits and '_' and not a column the run already has (HookSink checks).
  virtual std::vector<std::string> columns() const = 0;
  // Every frame the hook runs on: `frame` as read (no overlay; valid during the call only) and
  // its result. Sets what it measured in `out` (cleared before the call); a column it leaves
  // unset is an empty field of this frame's row. May throw: an InputError (a value of the wrong
  // kind, an unknown column) ends the run with its message; any other exception is the hook's
  // failure (HookOptions says what then happens).
  virtual void on_frame(const Frame& frame, const FrameResult& result, HookValues& out) = 0;
  // For messages: what the hook is ("hook tip.py").
  virtual std::string name() const { return "hook"; }
};

struct HookOptions {
  // Absent (a file's run): the hook runs on the run's thread on every frame, before the row is
  // written, so every row has its values; a slow hook slows the run (there is no frame to
  // miss). Set (a camera's run): the hook runs on its own thread, one frame at a time; the run
  // waits at most this long (ms, >= 0) for a frame's values, writes the row without them when
  // they are late (counted: late()), and skips the hook for the frames that arrive while it is
  // still busy (counted: skipped()). The values of a frame are only ever written in that
  // frame's row.
  std::optional<double> wait_ms{};
  // A hook that throws (other than InputError): false (default) reports it once (on_error, and
  // a note in the summary), switches the hook off and the run goes on with empty fields; true
  // ends the run as an error with one line: "<name> failed at frame N: <its last line>".
  bool stop_on_error = false;
  // Called once, on the run's thread, with the hook's whole error (a Python traceback) when it
  // fails. Empty: only the summary's note says it.
  std::function<void(const std::string& error)> on_error{};
};

// Runs a hook in a run: put it among the sinks before every sink that writes its columns (the
// CSV, the stream), which take HookSink::columns() as extra columns (TrackingColumns's
// `extra`). Not copyable; must outlive the run and those tables.
class HookSink : public FrameSink {
 public:
  // Asks the hook for its columns and checks their names (InputError naming the bad one).
  HookSink(FrameHook& hook, HookOptions options = {});
  ~HookSink() override;
  HookSink(const HookSink&) = delete;
  HookSink& operator=(const HookSink&) = delete;

  // The hook's columns for a CSV or stream table: each writes the value the hook gave for the
  // row's frame, or an empty field.
  std::vector<CsvColumn> columns() const;
  // Throws InputError when a hook column has the name of one of `table`'s own (before the run).
  void check_against(const CsvColumnTable& table) const;

  void begin(const RunInfo& info) override;
  // Throws InputError (the hook's InputError, or its failure with stop_on_error).
  void consume(const Frame& frame, const FrameResult& result) override;
  // Waits for a hook still running on its thread (a hook that never returns holds the end).
  void end(const RunSummary& summary) override;
  // A note: frames the hook ran on, skipped and late, and its failure.
  void report(RunSummary& summary) const override;

  const std::vector<std::string>& column_names() const { return current_.names(); }
  int64_t frames() const { return frames_; }    // Frames the run gave it.
  int64_t ran() const { return ran_; }          // Frames whose values reached their row.
  int64_t skipped() const { return skipped_; }  // Not run: it was busy with an earlier frame.
  int64_t late() const { return late_; }        // Run, but its values came after the row.
  const std::optional<std::string>& error() const { return error_; }  // Its failure, once.
  // Calls per frame, ms: how long on_frame took (median and 99th percentile over the run).
  const std::vector<double>& call_ms() const { return call_ms_; }

 private:
  class Worker;
  // The hook's failure `message` at frame `index`: reported, the hook off, or the run stopped.
  void fail(const std::string& message, int64_t index);
  void append(size_t column, const FrameResult& result, std::string& row) const;

  FrameHook& hook_;
  HookOptions options_;
  HookValues current_;           // The values of frame current_index_ (the row being written).
  int64_t current_index_ = -1;
  bool current_valid_ = false;
  bool off_ = false;             // Failed: runs no more.
  std::unique_ptr<Worker> worker_;
  int64_t frames_ = 0, ran_ = 0, skipped_ = 0, late_ = 0;
  std::optional<std::string> error_;
  std::optional<int64_t> error_frame_;
  std::vector<double> call_ms_;
};

}  // namespace softsight
