#include "app/python_hook.h"

#include <filesystem>
#include <string>
#include <utility>

#include "softsight/core/error.h"

#ifdef SOFTSIGHT_HAVE_PYTHON_HOOK
#include <dlfcn.h>
#endif

namespace softsight {

const FlagTable<HookArgs>& HookFlags() {
  using A = HookArgs;
  static const FlagTable<HookArgs> table = {
      ValueFlag<A>("--hook", &A::file)
          .Help("A Python file run on every frame: it defines columns = [\"name\", ...] and "
                "on_frame(frame, result) returning a dict of those names -> numbers, which go "
                "into the CSV and the stream (docs/usage.md, \"A per-frame hook\")"),
      ValueFlag<A>("--hook-wait-ms", &A::wait_ms)
          .Help("From a camera, the hook runs beside the loop: how long the loop waits for a "
                "frame's values before it writes the row without them (frames that come while "
                "the hook is busy are skipped by it, and counted)")
          .ShowDefault()
          .Check(CLI::Range(0.0, 1e6)),
      SwitchFlag<A>("--hook-stop-on-error", &A::stop_on_error)
          .Help("A hook that raises ends the run with one error line (default: its traceback is "
                "printed once and the run goes on without it)"),
  };
  return table;
}

#ifdef SOFTSIGHT_HAVE_PYTHON_HOOK

// The interpreter is in a module of its own, softsight_python.so beside the code that calls this
// (the commands plugins, the build tree's tests and benchmarks): loaded only for a run with a
// hook, so that no other run loads libpython (python_hook_module.cc).
std::unique_ptr<FrameHook> LoadPythonHook(const std::string& file) {
  using Entry = void (*)(const std::string&, std::unique_ptr<FrameHook>*);
  struct Module {
    Entry entry = nullptr;
    std::string why;  // When there is no entry.
  };
  static const Module module = [] {
    Module loaded;
    Dl_info info;
    std::filesystem::path dir = ".";
    if (dladdr(reinterpret_cast<void*>(&LoadPythonHook), &info) != 0 && info.dli_fname != nullptr) {
      dir = std::filesystem::path(info.dli_fname).parent_path();
    }
    const std::string path = (dir / "softsight_python.so").string();
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);  // Kept for the process.
    if (handle != nullptr) {
      loaded.entry = reinterpret_cast<Entry>(dlsym(handle, "softsight_load_python_hook"));
    }
    if (loaded.entry == nullptr) {
      const char* why = dlerror();
      loaded.why = why != nullptr ? why : path + " has no softsight_load_python_hook";
    }
    return loaded;
  }();
  if (module.entry == nullptr) {
    throw InputError("--hook " + file + ": cannot load softsight's Python module: " +
                     EscapeForMessage(module.why) + " (it is installed beside the softsight plugins)");
  }
  std::unique_ptr<FrameHook> hook;
  module.entry(file, &hook);
  return hook;
}

#else  // No Python at build time.

std::unique_ptr<FrameHook> LoadPythonHook(const std::string& file) {
  throw InputError("--hook " + file + ": this softsight was built without Python (install "
                   "python3-dev and pybind11-dev, scripts/setup.sh, and build again)");
}

#endif

std::unique_ptr<CommandHook> CommandHook::Open(const HookArgs& args, bool camera,
                                               const CsvColumnTable& table, std::ostream& err) {
  if (args.file.empty()) return nullptr;
  std::unique_ptr<CommandHook> hook(new CommandHook());
  hook->hook_ = LoadPythonHook(args.file);
  HookOptions options;
  if (camera) options.wait_ms = args.wait_ms;
  options.stop_on_error = args.stop_on_error;
  const std::string name = hook->hook_->name();
  options.on_error = [&err, name, stop = args.stop_on_error](const std::string& error) {
    err << "softsight: " << name << " raised" << (stop ? "" : "; it is switched off and the run goes on")
        << ":\n" << error;
    if (!error.empty() && error.back() != '\n') err << "\n";
    err.flush();
  };
  hook->sink_ = std::make_unique<HookSink>(*hook->hook_, std::move(options));
  hook->sink_->check_against(table);
  return hook;
}

std::unique_ptr<CommandHook> CommandHook::Open(const HookArgs& args, bool camera,
                                               const std::vector<std::string>& run_columns,
                                               std::ostream& err) {
  // The check asks a table only for its names: one of the names alone does.
  CsvColumnTable named;
  for (const std::string& name : run_columns) named.add({name, {}});
  return Open(args, camera, named, err);
}

CommandHook::~CommandHook() {
  sink_.reset();  // Its thread first: it may be running the hook.
  hook_.reset();
}

}  // namespace softsight
