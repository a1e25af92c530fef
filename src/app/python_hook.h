// --hook FILE.py and its companions, the same on track, live, serve and control: a Python file's
// on_frame(frame, result) run on every frame by a HookSink (softsight/pipeline/hook.h), its
// values in the run's CSV and stream. The file is run by an interpreter embedded in the program
// (pybind11's embed), in the library softsight_python_hook of its own, so that nothing of the
// installed library links Python.
//
// The file defines
//   columns = ["tip_speed"]        # the names of the values, known before the run
//   def on_frame(frame, result):   # frame: numpy BGR image (read-only view, valid in the call)
//       return {"tip_speed": ...}  # a dict of column -> number (None: empty), or None
// `result` has the attributes of softsight.FrameResult that a hook reads: frame, time_s,
// proc_ms, markers (each with name, x, y, found, score, status), result["red"], measurement and
// each measurement by name (result.angle_deg).
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/flag_table.h"

#include "softsight/io/csv_columns.h"
#include "softsight/pipeline/hook.h"

namespace softsight {

// What the options hold until the command runs.
struct HookArgs {
  std::string file;            // --hook; empty: no hook.
  double wait_ms = 5.0;        // --hook-wait-ms: a camera's wait for a frame's values.
  bool stop_on_error = false;  // --hook-stop-on-error.
};

// --hook, --hook-wait-ms and --hook-stop-on-error.
const FlagTable<HookArgs>& HookFlags();

// A command's hook: the Python file loaded, and the sink that runs it.
class CommandHook {
 public:
  // Loads args.file (nullptr when no --hook). `camera`: the run's frames come from a camera, so
  // the hook runs on its own thread and is waited for at most args.wait_ms per frame; else on
  // every frame, in the run. Its failure's traceback goes to `err` at once. Throws InputError
  // with one line naming the file: missing, not Python, raising as it loads, no on_frame, no
  // or bad `columns`, a column the run already has (`table`).
  static std::unique_ptr<CommandHook> Open(const HookArgs& args, bool camera,
                                           const CsvColumnTable& table, std::ostream& err);
  // The same for a run whose rows are not one view's (control --stereo): `run_columns` are the
  // names of its table's columns.
  static std::unique_ptr<CommandHook> Open(const HookArgs& args, bool camera,
                                           const std::vector<std::string>& run_columns,
                                           std::ostream& err);
  ~CommandHook();

  HookSink& sink() { return *sink_; }
  // The columns to add to the CSV's and the stream's tables (TrackingColumns's `extra`).
  std::vector<CsvColumn> columns() const { return sink_->columns(); }

 private:
  CommandHook() = default;
  std::unique_ptr<FrameHook> hook_;
  std::unique_ptr<HookSink> sink_;
};

// Loads a Python hook file as `--hook` does (the benchmark's and the tests' way in).
std::unique_ptr<FrameHook> LoadPythonHook(const std::string& file);

}  // namespace softsight
