// softsight: measure soft robots with a camera. See README.md.
//
// The launcher: it links no OpenCV, so `softsight --version` and `softsight --help` start in a
// few milliseconds (the whole program linked ~260 shared libraries and took 0.3 s to start).
// A command runs in the plugin that holds it, loaded from beside this program
// (app/command_table.h says which; app/command_line.h what it does).
#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/command_table.h"
#include "app/help_format.h"
#include "app/unknown_word.h"
#include "softsight/core/error.h"
#include "softsight/version.h"

namespace softsight {
namespace {

// The first word that is not an option: the command, when there is one.
const CommandInfo* ChosenCommand(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (argv[i][0] != '-') return FindCommand(argv[i]);
  }
  return nullptr;
}

// softsight_<plugin>.so beside the program (the build tree), or in <libdir>/softsight (installed;
// SOFTSIGHT_PLUGIN_DIR_FROM_BIN is that folder relative to the program's, e.g. ../lib/softsight).
std::vector<std::filesystem::path> PluginCandidates(const char* plugin) {
  char self[PATH_MAX];
  const ssize_t length = readlink("/proc/self/exe", self, sizeof(self) - 1);
  const std::filesystem::path dir =
      length > 0 ? std::filesystem::path(std::string(self, static_cast<size_t>(length))).parent_path()
                 : std::filesystem::path(".");
  const std::string file = std::string("softsight_") + plugin + ".so";
  return {dir / file, dir / SOFTSIGHT_PLUGIN_DIR_FROM_BIN / file};
}

int RunPlugin(const CommandInfo& command, int argc, char** argv) {
  const char* plugin_name = PluginFor(command, argc, argv);
  std::string why;
  for (const std::filesystem::path& path : PluginCandidates(plugin_name)) {
    if (!std::filesystem::exists(path)) continue;
    // Lazy: a function of the ~260 libraries the plugin links is bound when first called, not
    // all at load (RTLD_NOW bound every one, ~65M instructions, a tenth of the load; a bare
    // program's libraries are bound lazily too). The plugin and softsight's own libraries are
    // linked with -z now (src/app/CMakeLists.txt, cmake/softsight.cmake): their calls are still
    // all bound here, so one missing from a library fails this dlopen with the line below.
    void* plugin = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
    if (plugin == nullptr) {
      why = dlerror();
      break;
    }
    const auto entry = reinterpret_cast<PluginEntry>(dlsym(plugin, kPluginEntry));
    if (entry == nullptr) {
      why = path.string() + " has no " + kPluginEntry;
      break;
    }
    return entry(argc, argv);  // The plugin stays loaded until the process ends.
  }
  if (why.empty()) why = PluginCandidates(plugin_name).front().string() + " not found";
  std::cerr << "softsight " << command.name << ": error: cannot load the program's "
            << plugin_name << " plugin: " << EscapeForMessage(why)
            << " (it is installed beside the softsight program)\n";
  return 1;
}

// No command given (or one the table does not have): --help and --version, or the usage error
// naming the word that is no command, from the table alone.
int RunWithoutCommand(int argc, char** argv) {
  CLI::App app{kProgramDescription};
  app.name("softsight");  // Not argv[0], the path it was started by: "Usage: softsight track".
  app.formatter(TerminalHelpFormatter());  // Before the commands: they take the app's.
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("softsight ") + kVersion);
  for (const CommandInfo& command : kCommandTable) app.add_subcommand(command.name, command.summary);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (const std::optional<int> answered = AnswerHelpOrUnknownWord(app, e, std::cerr)) {
      return *answered;
    }
    std::cerr << "softsight: error: " << EscapeForMessage(e.what()) << " (see softsight --help)\n";
    return kInputErrorExitCode;
  }
  return kInputErrorExitCode;  // Not reached: a known command goes to its plugin.
}

}  // namespace
}  // namespace softsight

int main(int argc, char** argv) {
  if (const softsight::CommandInfo* command = softsight::ChosenCommand(argc, argv)) {
    return softsight::RunPlugin(*command, argc, argv);
  }
  return softsight::RunWithoutCommand(argc, argv);
}
