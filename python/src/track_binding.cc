// softsight.track: a whole run (a video, an image sequence or a built-in scene) through the same
// RunPipeline and CSV column table as `softsight track`, its columns returned as numpy arrays;
// and softsight.frames' reader, the same source and session one frame at a time.
#include <chrono>
#include <cstdlib>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <set>

#include <pybind11/stl.h>

#include "bindings.h"
#include "run_reader.h"
#include "softsight/core/error.h"
#include "softsight/io/csv_columns.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/run_source.h"
#include "softsight/pipeline/hook.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/tracking_session.h"

namespace softsight::python {
namespace {

// Keeps every CSV row as `softsight track` writes it (the same column table), so the arrays hold
// exactly the file's values: one text buffer and where each row ends (no allocation per frame
// once the buffer has grown).
class RowSink : public FrameSink {
 public:
  explicit RowSink(const CsvColumnTable& columns) : columns_(columns) {}
  void consume(const Frame&, const FrameResult& result) override {
    columns_.append_row(result, row_);
    text_ += row_;
    text_ += '\n';
    ends_.push_back(text_.size());
  }

  size_t rows() const { return ends_.size(); }
  // The fields of row `r` (each a pointer into the buffer and a length).
  void fields(size_t r, std::vector<std::pair<const char*, size_t>>& out) const {
    out.clear();
    const size_t begin = r == 0 ? 0 : ends_[r - 1];
    const size_t end = ends_[r] - 1;  // Without the newline.
    size_t start = begin;
    for (size_t i = begin; i <= end; ++i) {
      if (i == end || text_[i] == ',') {
        out.emplace_back(text_.data() + start, i - start);
        start = i + 1;
      }
    }
  }

 private:
  const CsvColumnTable& columns_;
  std::string row_, text_;
  std::vector<size_t> ends_;
};

// progress=: each processed frame reported to a Python callable progress(done, total) (total
// None when the source does not know its length), holding the GIL only for the call. Never a
// line on fd 2 from here: a notebook or contextlib.redirect_stderr only sees what Python writes to
// sys.stderr, so the line and the tqdm bar are drawn in Python (softsight/_progress.py). An
// exception from the callable is kept as the thread's Python error and ends the run.
class ProgressCallback : public FrameSink {
 public:
  explicit ProgressCallback(py::object callback) : callback_(std::move(callback)) {}
  void begin(const RunInfo& info) override { total_ = info.frame_count; }
  void consume(const Frame&, const FrameResult&) override {
    ++done_;
    if (failed_) return;
    py::gil_scoped_acquire gil;
    try {
      callback_(done_, total_ ? py::object(py::int_(*total_)) : py::object(py::none()));
    } catch (py::error_already_set& error) {
      error.restore();  // Raised again by the caller once the run has ended.
      failed_ = true;
    }
  }
  bool failed() const { return failed_; }

 private:
  py::object callback_;
  std::optional<int64_t> total_;
  int64_t done_ = 0;
  bool failed_ = false;
};

// hook=: a Python callable hook(frame, result) -> {column: number} run on every frame, in the
// run's thread (a file's run: every row gets its values), holding the GIL only for the call.
// `frame` is a read-only numpy view of the frame, `result` a softsight.FrameResult.
class CallableHook : public FrameHook {
 public:
  CallableHook(py::object callable, std::vector<std::string> columns)
      : callable_(std::move(callable)), columns_(std::move(columns)) {}
  std::vector<std::string> columns() const override { return columns_; }
  void on_frame(const Frame& frame, const FrameResult& result, HookValues& out) override {
    py::gil_scoped_acquire gil;
    try {
      TakeValues(callable_(FrameView(frame.image), py::cast(result)), out);
    } catch (py::error_already_set& error) {
      // The hook's own failure: HookSink reports it (the traceback) and switches it off.
      throw std::runtime_error(TracebackText(error));
    }
  }

 private:
  py::object callable_;
  std::vector<std::string> columns_;
};

enum class Kind { kInt, kBool, kText, kNumber };

// The numpy type of each CSV column: frame an int64, <marker>_found a bool, <marker>_status a
// string, every other column a float64 (NaN for an empty field).
Kind ColumnKind(const std::string& name, const std::set<std::string>& found,
                const std::set<std::string>& status) {
  if (name == "frame") return Kind::kInt;
  if (found.count(name)) return Kind::kBool;
  if (status.count(name)) return Kind::kText;
  return Kind::kNumber;
}

py::dict Columns(const RowSink& rows, const CsvColumnTable& table, const TrackingConfig& config) {
  std::set<std::string> found, status;
  for (const MarkerSpec& spec : config.markers) {
    found.insert(spec.name + "_found");
    status.insert(spec.name + "_status");
    status.insert(spec.name + "_track");
  }
  const size_t n = rows.rows();
  std::vector<std::pair<const char*, size_t>> fields;
  std::vector<Kind> kinds;
  std::vector<py::array> arrays;
  std::vector<py::list> texts;
  for (size_t c = 0; c < table.size(); ++c) {
    kinds.push_back(ColumnKind(table.column(c).name, found, status));
    switch (kinds.back()) {
      case Kind::kInt: arrays.push_back(py::array_t<int64_t>(n)); break;
      case Kind::kBool: arrays.push_back(py::array_t<bool>(n)); break;
      case Kind::kNumber: arrays.push_back(py::array_t<double>(n)); break;
      case Kind::kText: arrays.emplace_back(); break;
    }
    texts.emplace_back(kinds.back() == Kind::kText ? py::list(n) : py::list());
  }
  std::string field;
  for (size_t r = 0; r < n; ++r) {
    rows.fields(r, fields);
    CV_Assert(fields.size() == table.size());
    for (size_t c = 0; c < fields.size(); ++c) {
      field.assign(fields[c].first, fields[c].second);
      switch (kinds[c]) {
        case Kind::kInt:
          static_cast<int64_t*>(arrays[c].mutable_data())[r] = std::strtoll(field.c_str(), nullptr, 10);
          break;
        case Kind::kBool:
          static_cast<bool*>(arrays[c].mutable_data())[r] = field == "1";
          break;
        case Kind::kNumber:
          static_cast<double*>(arrays[c].mutable_data())[r] =
              field.empty() ? std::numeric_limits<double>::quiet_NaN()
                            : std::strtod(field.c_str(), nullptr);
          break;
        case Kind::kText:
          texts[c][r] = py::str(field);
          break;
      }
    }
  }
  py::module_ np = py::module_::import("numpy");
  py::dict out;
  for (size_t c = 0; c < table.size(); ++c) {
    py::str name(table.column(c).name);
    if (kinds[c] == Kind::kText) {
      out[name] = np.attr("array")(texts[c], py::arg("dtype") = "U");
    } else {
      out[name] = arrays[c];
    }
  }
  return out;
}

py::dict SummaryDict(const RunSummary& s) {
  py::dict out;
  out["source"] = s.source;
  out["frames"] = s.frames;
  out["dropped"] = s.dropped;
  out["first_index"] = s.first_index ? py::object(py::int_(*s.first_index)) : py::none();
  out["last_index"] = s.last_index ? py::object(py::int_(*s.last_index)) : py::none();
  py::dict found;
  for (size_t i = 0; i < s.markers.size(); ++i) found[py::str(s.markers[i].name)] = s.found_rate(i);
  out["found_rate"] = found;
  out["measured"] = s.measured;
  out["proc_ms_median"] = s.proc_ms_median;
  out["proc_ms_p99"] = s.proc_ms_p99;
  // Capture to result, and to the CSV row written (CsvSink::report: absent without a csv=).
  out["latency_result_ms_median"] = s.latency_result_ms_median;
  out["latency_result_ms_p99"] = s.latency_result_ms_p99;
  const auto optional = [](const std::optional<double>& v) { return v ? py::object(py::float_(*v)) : py::object(py::none()); };
  out["latency_row_ms_median"] = optional(s.latency_row_ms_median);
  out["latency_row_ms_p99"] = optional(s.latency_row_ms_p99);
  out["wall_s"] = s.wall_s;
  out["stop_reason"] = s.stop_text();  // The report's words, as the stream's end record has them.
  out["error"] = s.ok() ? py::object(py::none()) : py::object(py::str(s.error));
  out["report"] = s.FullReport();
  py::list notes;
  for (const std::string& note : s.notes) notes.append(note);
  out["notes"] = notes;  // The sinks' and the source's notes (a hook's: its calls, skips, failure).
  return out;
}

void CheckMaxFrames(std::optional<int64_t> max_frames) {
  if (max_frames && *max_frames < 0) {
    throw InputError("max_frames: " + std::to_string(*max_frames) + " must be >= 0");
  }
}

// What track() and frames() read: `input` (a path or synth:NAME), at `fps` for image sequences.
FrameSourceSpec InputSpec(const py::object& input, double fps) {
  FrameSourceSpec spec;
  const std::optional<std::string> input_path = AsPath(input);
  if (!input_path) {
    throw py::type_error("input: a path (str, bytes or os.PathLike) or synth:NAME, got " +
                         std::string(py::str(py::type::of(input).attr("__name__"))));
  }
  spec.input = *input_path;
  spec.sequence_fps = fps;
  return spec;
}

// Returns (columns, summary); an InputError before the run (config, input, CSV path) is raised,
// one during it ends the run and is the summary's "error" (the caller raises it with the rows
// so far, as the CLI keeps the rows it wrote).
py::tuple Track(const py::object& input, const py::object& config_source,
                std::optional<int64_t> max_frames, const py::object& progress,
                const py::object& csv_path, double fps,
                const std::optional<std::string>& method, const py::object& hook_callable,
                const py::object& hook_columns, bool hook_stop_on_error) {
  CheckMaxFrames(max_frames);
  const TrackingConfig config = ResolveConfig(config_source, method);
  const FrameSourceSpec spec = InputSpec(input, fps);
  std::optional<std::string> csv;
  if (!csv_path.is_none()) {
    csv = AsPath(csv_path);
    if (!csv) throw py::type_error("csv: a path (str, bytes or os.PathLike)");
  }
  RunSummary summary;
  // hook=: its columns after the tracking ones, in the table and the CSV; its sink first.
  std::optional<CallableHook> hook;
  std::optional<HookSink> hook_sink;
  std::optional<std::string> hook_error;
  if (!hook_callable.is_none()) {
    hook.emplace(hook_callable, ColumnNames(hook_columns, "hook_columns"));
    HookOptions options;
    options.stop_on_error = hook_stop_on_error;
    // Its traceback once, where Python writes its errors (a notebook shows it).
    options.on_error = [&hook_error, hook_stop_on_error](const std::string& error) {
      hook_error = error;
      py::gil_scoped_acquire gil;
      py::module_::import("sys").attr("stderr").attr("write")(
          std::string("softsight.track: the hook raised") +
          (hook_stop_on_error ? ":\n" : "; it is switched off and the run goes on:\n") + error);
    };
    hook_sink.emplace(*hook, std::move(options));
    hook_sink->check_against(TrackingColumns(config));
  }
  const CsvColumnTable table =
      TrackingColumns(config, hook_sink ? hook_sink->columns() : std::vector<CsvColumn>{});
  RowSink rows(table);
  std::optional<ProgressCallback> progress_sink;  // Made and destroyed holding the GIL.
  if (!progress.is_none()) progress_sink.emplace(progress);
  bool interrupted = false;
  {
    py::gil_scoped_release release;
    // Decoded ahead on its own thread, as `softsight track` reads it (io/run_source.h).
    std::unique_ptr<FrameSource> source = SourceForRun(OpenFrameSource(spec), FilePacing::kReadAhead);
    TrackingSession session(config);
    std::optional<CsvSink> file;
    std::vector<FrameSink*> sinks;
    if (hook_sink) sinks.push_back(&*hook_sink);  // Before the rows that hold its columns.
    sinks.push_back(&rows);
    if (csv) {
      // The same guard as the program's: the CSV may not be the video, an image of the
      // sequence, the config or a file the config names.
      std::vector<PathRole> inputs = ConfigInputs(config);
      for (const std::string& name : source->files()) inputs.push_back({"input", name});
      CheckOutputsAreNotInputs({{"csv", *csv}}, inputs);
      file.emplace(*csv, table);
      sinks.push_back(&*file);
    }
    if (progress_sink) sinks.push_back(&*progress_sink);
    RunOptions run;
    run.max_frames = max_frames;
    // Ctrl-C in the interpreter's main thread ends the run (checked a few times a second).
    auto next_check = std::chrono::steady_clock::now();
    run.stop_requested = [&] {
      if (progress_sink && progress_sink->failed()) return true;  // Its error is set: no more Python.
      const auto now = std::chrono::steady_clock::now();
      if (now < next_check) return false;
      next_check = now + std::chrono::milliseconds(200);
      py::gil_scoped_acquire gil;
      interrupted = PyErr_CheckSignals() != 0;
      return interrupted;
    };
    summary = RunPipeline(*source, session, sinks, run);
  }
  if (interrupted || (progress_sink && progress_sink->failed())) throw py::error_already_set();
  py::dict summary_dict = SummaryDict(summary);
  summary_dict["hook_error"] = hook_error ? py::object(py::str(*hook_error)) : py::object(py::none());
  return py::make_tuple(Columns(rows, table, config), summary_dict);
}

// softsight.frames' reader: the frames of `input` through the library's own source (videos,
// sequences, folders, built-in scenes, with track's decode rules) and one run's session, one
// frame per next(), the GIL released while a frame is read and tracked. close() (or the end of
// the input, or an error) releases the source, so a generator closed early lets go of the file.
class FrameStream : public ClosableRunReader<FrameStream> {
 public:
  FrameStream(const py::object& input, const py::object& config_source,
              std::optional<int64_t> max_frames, double fps,
              const std::optional<std::string>& method) {
    CheckMaxFrames(max_frames);
    TrackingConfig config = ResolveConfig(config_source, method);
    const FrameSourceSpec spec = InputSpec(input, fps);
    py::gil_scoped_release release;
    source_ = OpenFrameSource(spec);
    session_ = std::make_unique<TrackingSession>(std::move(config));
    RunOptions options;
    options.max_frames = max_frames;
    stream_ = std::make_unique<RunStream>(*source_, *session_, options);
  }

  // The next frame's result, or nothing at the end (of the input, or of max_frames). A predicted
  // video's results come once their key-frame group is checked, as track()'s rows do. Throws
  // InputError for an input with no frame at all, a frame that does not decode or a gray video
  // with colour markers, as track() reports them, after the results before it; the input is
  // released when the run ends.
  std::optional<FrameResult> next() {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(mutex_);  // One frame at a time.
    if (closed_) return std::nullopt;
    try {
      std::optional<FrameResult> result = stream_->next();
      // The run has ended: the file is let go of at once (the stream's held results remain).
      if (stream_->ended()) source_.reset();
      if (!result) closed_ = true;
      return result;
    } catch (...) {
      close_locked();
      throw;
    }
  }

 private:
  friend class ClosableRunReader<FrameStream>;
  void release_input() { source_.reset(); }  // The video file or the image sequence.

  std::unique_ptr<FrameSource> source_;
  std::unique_ptr<TrackingSession> session_;
  std::unique_ptr<RunStream> stream_;
};

}  // namespace

void BindTrack(py::module_& m) {
  py::class_<FrameStream>(m, "_FrameStream",
                          "softsight.frames' reader (use softsight.frames, which closes it).")
      .def(py::init<const py::object&, const py::object&, std::optional<int64_t>, double,
                    const std::optional<std::string>&>(),
           py::arg("input"), py::arg("config"), py::arg("max_frames"), py::arg("fps"),
           py::arg("method"))
      .def("next", &FrameStream::next, "The next frame's FrameResult, or None at the end.")
      .def("close", &FrameStream::close, "Releases the input (idempotent).")
      .def_property_readonly("closed", &FrameStream::closed)
      .def_property_readonly("total", &FrameStream::total)
      .def_property_readonly("done", &FrameStream::done);

  m.def("_track", &Track, py::arg("input"), py::arg("config"), py::arg("max_frames"),
        py::arg("progress"), py::arg("csv"), py::arg("fps"), py::arg("method"), py::arg("hook"),
        py::arg("hook_columns"), py::arg("hook_stop_on_error"),
        "softsight.track without the table: (columns dict, summary dict).");
}

}  // namespace softsight::python
