// softsight_python.so: the Python interpreter of --hook (app/python_hook.h), a module that
// LoadPythonHook loads only when a run has a hook. Linked into the commands plugin, libpython
// was loaded and relocated by every `track` (one library and ~400 page faults of start-up for
// the few runs with a hook; issue 45).
#include <dlfcn.h>

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/embed.h>

#include "hook_call.h"  // python/src: what softsight.track(hook=) shares.
#include "softsight/core/error.h"
#include "softsight/pipeline/hook.h"

namespace softsight {
namespace {

namespace py = pybind11;

// The interpreter, started with the first hook and kept for the process (a second start after a
// finalize is not safe for extension modules such as numpy). Ctrl-C stays the program's: no
// Python signal handlers. The main thread lets go of the GIL, so a hook may run on any thread.
// The program loads its commands as plugins with their own symbols (RTLD_LOCAL), and libpython
// with them: an extension module a hook imports (numpy) then finds no Python symbols
// ("undefined symbol: PyExc_RecursionError"). Before the interpreter starts, libpython is made
// global, as `python3` itself is.
bool MakePythonGlobal() {
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&Py_InitializeEx), &info) == 0 || info.dli_fname == nullptr) {
    return false;
  }
  return dlopen(info.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_GLOBAL) != nullptr;  // Kept.
}

// The interpreter, started with the first hook (on whichever thread loads it: a test's, a batch
// job's) and never finalized: Py_FinalizeEx at exit waits for the thread that started it, which
// may be gone (a hang), and a second start after a finalize is not safe for extension modules
// such as numpy. The process's end frees it. Ctrl-C stays the program's: no Python signal
// handlers. The starting thread lets go of the GIL for good, so a hook may run on any thread.
void StartInterpreter() {
  static const bool started = [] {
    MakePythonGlobal();
    py::initialize_interpreter(/*init_signal_handlers=*/false);
    PyEval_SaveThread();
    return true;
  }();
  (void)started;
}

// What a hook's `result` is: softsight.FrameResult's attributes that a hook reads, in plain
// Python (the program does not load the softsight module: it may not be installed).
constexpr const char* kResultClasses = R"py(
class Marker:
    """One marker in one frame (softsight.Marker's attributes)."""
    __slots__ = ("name", "x", "y", "found", "score", "status")

    def __init__(self, name, x, y, found, score, status):
        self.name, self.x, self.y = name, x, y
        self.found, self.score, self.status = found, score, status

    def __repr__(self):
        at = "" if self.x is None else " at (%g, %g)" % (self.x, self.y)
        return "Marker(%s: %s%s)" % (self.name, self.status, at)


class FrameResult:
    """One frame's result (softsight.FrameResult's attributes): result["red"], result.angle_deg."""
    __slots__ = ("frame", "time_s", "proc_ms", "markers", "measurement")

    def __init__(self, frame, time_s, proc_ms, markers, measurement):
        self.frame, self.time_s, self.proc_ms = frame, time_s, proc_ms
        self.markers, self.measurement = markers, measurement

    def __getitem__(self, name):
        for marker in self.markers:
            if marker.name == name:
                return marker
        raise KeyError("no marker named %r" % (name,))

    def __getattr__(self, name):
        if name != "measurement" and name in self.measurement:
            return self.measurement[name]
        raise AttributeError(name)

    def __repr__(self):
        return "FrameResult(frame %d, %s)" % (self.frame, ", ".join(map(repr, self.markers)))
)py";

// The last line of a Python error: "SyntaxError: invalid syntax (h.py, line 3)".
std::string LastLine(const std::string& text) {
  const size_t end = text.find_last_not_of("\n ");
  if (end == std::string::npos) return text;
  const size_t begin = text.rfind('\n', end);
  const size_t from = begin == std::string::npos ? 0 : begin + 1;
  return text.substr(from, end + 1 - from);
}

// The hook's own failure (the traceback); an InputError ends the run instead.
class HookFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class PythonHook : public FrameHook {
 public:
  explicit PythonHook(std::string file) : file_(std::move(file)) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(file_, error)) {
      throw InputError("--hook " + file_ + ": no such file");
    }
    StartInterpreter();
    py::gil_scoped_acquire gil;
    try {
      load();
    } catch (py::error_already_set& e) {
      const std::string message = file_ + ": cannot load the hook: " + LastLine(python::TracebackText(e));
      release();
      throw InputError(message);
    } catch (...) {
      release();
      throw;
    }
  }
  ~PythonHook() override {
    py::gil_scoped_acquire gil;
    release();
  }

  std::vector<std::string> columns() const override { return columns_; }
  std::string name() const override { return "hook " + file_; }

  void on_frame(const Frame& frame, const FrameResult& result, HookValues& out) override {
    py::gil_scoped_acquire gil;
    try {
      python::TakeValues(on_frame_(python::FrameView(frame.image), ResultObject(result)), out);
    } catch (py::error_already_set& e) {
      throw HookFailure(python::TracebackText(e));
    }
  }

 private:
  void load() {
    py::module_ util = py::module_::import("importlib.util");
    py::module_ sys = py::module_::import("sys");
    const std::string folder = std::filesystem::absolute(file_).parent_path().string();
    sys.attr("path").attr("insert")(0, folder);  // Its own modules beside it import.
    sys.attr("argv") = py::make_tuple(file_);
    // Any file name, .py or not: the loader is chosen for the source, not by the suffix.
    py::object loader = py::module_::import("importlib.machinery")
                            .attr("SourceFileLoader")("softsight_hook", file_);
    py::object spec = util.attr("spec_from_loader")("softsight_hook", loader);
    module_ = util.attr("module_from_spec")(spec);
    loader.attr("exec_module")(module_);
    if (!py::hasattr(module_, "on_frame") || !PyCallable_Check(module_.attr("on_frame").ptr())) {
      throw InputError(file_ + ": no function on_frame(frame, result) in it");
    }
    on_frame_ = module_.attr("on_frame");
    if (!py::hasattr(module_, "columns")) {
      throw InputError(file_ + ": no `columns` in it: the names of the values on_frame returns, "
                               "e.g. columns = [\"tip_speed\"]");
    }
    columns_ = python::ColumnNames(module_.attr("columns"), file_ + ": columns");
    py::dict scope;
    scope["__builtins__"] = py::module_::import("builtins");
    py::exec(kResultClasses, scope);
    marker_class_ = scope["Marker"];
    result_class_ = scope["FrameResult"];
  }
  void release() {
    on_frame_ = py::object();
    module_ = py::object();
    marker_class_ = py::object();
    result_class_ = py::object();
  }

  py::object ResultObject(const FrameResult& r) const {
    py::list markers(r.markers.size());
    for (size_t i = 0; i < r.markers.size(); ++i) {
      const MarkerObservation& m = r.markers[i];
      const bool found = m.observation.found();
      markers[i] = marker_class_(
          m.name, found ? py::object(py::float_(m.observation.position_px->x)) : py::object(py::none()),
          found ? py::object(py::float_(m.observation.position_px->y)) : py::object(py::none()),
          found, python::Optional(m.observation.score), MarkerStatusName(m.observation.status()));
    }
    return result_class_(r.frame_index, r.time_s, r.proc_ms, markers,
                         python::MeasurementDict(r.measurement));
  }

  std::string file_;
  std::vector<std::string> columns_;
  py::object module_, on_frame_, marker_class_, result_class_;
};

}  // namespace

// The module's one entry (python_hook.cc's LoadPythonHook finds it by this name): the hook
// loaded into `*hook`, or the exception its loading threw.
extern "C" void softsight_load_python_hook(const std::string& file,
                                           std::unique_ptr<FrameHook>* hook) {
  *hook = std::make_unique<PythonHook>(file);
}


}  // namespace softsight
