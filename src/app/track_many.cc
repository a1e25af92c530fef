#include "app/track_many.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>

#include "app/cli_checks.h"
#include "app/stop_request.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/io/frame_source.h"

extern char** environ;

namespace softsight {
namespace fs = std::filesystem;
namespace {

// The name an input's CSV starts from (see CsvNamesForInputs).
std::string StemOf(std::string input) {
  if (input.rfind(kSyntheticPrefix, 0) == 0) {
    for (char& c : input) c = c == ':' ? '_' : c;
  } else {
    while (input.size() > 1 && input.back() == '/') input.pop_back();
    input = fs::path(input).stem().string();
  }
  std::string stem;
  for (char c : input) {
    if (c != '%') stem += c;
  }
  return stem.empty() ? "input" : stem;
}

// One input being tracked by a child process.
struct Child {
  size_t input = 0;  // Index into the inputs.
  pid_t pid = -1;
  int output_fd = -1;  // The read end of the child's stdout + stderr.
  std::string output;
};


// `softsight track` on one input with the shared options (the `=` forms keep a value that starts
// with '-' a value).
std::vector<std::string> ChildArguments(const TrackManyOptions& options, const std::string& input,
                                        const std::string& csv) {
  const TrackOptions& common = options.common;
  std::vector<std::string> args = {options.program, "track", "--config=" + common.config_file,
                                   "--input=" + input, "--csv=" + csv, "--brief"};
  if (common.method) args.push_back("--method=" + *common.method);
  if (common.template_colour) args.push_back(*common.template_colour ? "--colour" : "--gray");
  args.push_back("--fps=" + RoundTripNumber(common.source.sequence_fps));
  if (common.max_frames) args.push_back("--max-frames=" + std::to_string(*common.max_frames));
  return args;
}

Child Spawn(const TrackManyOptions& options, size_t input, const std::string& csv) {
  int pipe_fds[2];
  if (pipe2(pipe_fds, O_CLOEXEC) != 0) {
    throw InputError(std::string("track: cannot create a pipe: ") + std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 1);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
  // The child starts with SIGINT and SIGTERM blocked, and its StopRequest unblocks them once its
  // handler is in place: a Ctrl-C that reaches a child still loading (the whole process group
  // gets it) waits for the handler and stops the run cleanly, instead of killing the child
  // before it could write its summary.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t held;
  sigemptyset(&held);
  sigaddset(&held, SIGINT);
  sigaddset(&held, SIGTERM);
  posix_spawnattr_setsigmask(&attributes, &held);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
  const std::vector<std::string> args = ChildArguments(options, options.inputs[input], csv);
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  Child child;
  child.input = input;
  const int error =
      posix_spawn(&child.pid, options.program.c_str(), &actions, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  close(pipe_fds[1]);
  if (error != 0) {
    close(pipe_fds[0]);
    throw InputError("track: cannot start " + options.program + ": " + std::strerror(error));
  }
  child.output_fd = pipe_fds[0];
  return child;
}

// The child's last non-empty line (its summary or its error line).
std::string LastLine(const std::string& text) {
  std::istringstream lines(text);
  std::string last;
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty()) last = line;
  }
  return last;
}

// The options a run over an output folder cannot take (they write one file or read a camera).
void RefuseSingleRunOptions(const TrackManyOptions& options) {
  const TrackOptions& common = options.common;
  if (options.inputs.empty()) throw InputError("track: no input given (--input)");
  if (options.jobs < 1) throw InputError("--jobs " + std::to_string(options.jobs) + ": must be 1 or more");
  if (common.annotated_file || common.record_file) {
    throw InputError(std::string(common.annotated_file ? "--annotated" : "--record") +
                     ": with an output folder, give one input and a CSV file (-o run.csv) to "
                     "also write videos");
  }
  if (common.publish) {
    throw InputError("--publish " + common.publish->endpoint +
                     ": with an output folder, give one input and a CSV file (-o run.csv) to "
                     "also publish its results");
  }
  if (common.source.camera) {
    throw InputError("--camera: with an output folder, give --input files (a camera run writes "
                     "one CSV: -o bench.csv)");
  }
}

// The output folder made, and every input's CSV in it, none of them an input.
std::vector<std::string> PrepareOutputFolder(const TrackManyOptions& options,
                                             const TrackingConfig& config) {
  if (fs::exists(options.out_dir) && !fs::is_directory(options.out_dir)) {
    throw InputError(options.out_dir + ": the output folder is a file");
  }
  std::error_code made;
  fs::create_directories(options.out_dir, made);
  if (made) throw InputError(options.out_dir + ": cannot create the output folder (" + made.message() + ")");
  const std::vector<std::string> csvs = CsvNamesForInputs(options.inputs, options.out_dir);
  std::vector<PathRole> outputs, inputs;
  for (size_t i = 0; i < csvs.size(); ++i) {
    outputs.push_back({"the CSV of --input " + options.inputs[i], csvs[i]});
  }
  for (const PathRole& file : ConfigInputs(config)) inputs.push_back(file);
  for (const std::string& input : options.inputs) {
    // A folder's images are checked by its own run; here every input as given.
    if (!fs::is_directory(input)) inputs.push_back({"--input", input});
  }
  CheckOutputsAreNotInputs(outputs, inputs);
  return csvs;
}

// What the children did, counted as each ends.
struct ChildTally {
  size_t done = 0, stopped = 0;
  int64_t frames = 0;
  int exit_code = 0;  // The first failed child's.
  std::vector<std::string> failed;
};

// A child's output ended: it is waited for, counted, and its line reported.
void FinishChild(const TrackManyOptions& options, const std::vector<std::string>& csvs,
                 const std::string& of_total, Child& child, ChildTally* tally,
                 std::ostream& report) {
  const TrackOptions& common = options.common;
  close(child.output_fd);
  int status = 0;
  while (waitpid(child.pid, &status, 0) < 0 && errno == EINTR) {
  }
  const std::string& input = options.inputs[child.input];
  const std::string line = LastLine(child.output);
  const std::string lead = "track: [" + std::to_string(child.input + 1) + of_total + input;
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (WIFEXITED(status) && (code == 0 || code == 128 + SIGINT || code == 128 + SIGTERM) &&
      line.find(": error:") == std::string::npos) {
    tally->frames += std::strtoll(line.c_str(), nullptr, 10);  // "300 frames (end of input), ..."
    if (code == 0) {
      ++tally->done;
    } else {
      ++tally->stopped;
    }
    if (!common.quiet) report << lead << " -> " << csvs[child.input] << ": " << line << "\n";
  } else {
    tally->failed.push_back(input);
    if (tally->exit_code == 0) tally->exit_code = code;
    report << lead << ": "
           << (WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                   : line.empty() ? "failed, exit code " + std::to_string(code)
                                                  : line)
           << "\n";
  }
}

// The closing line: the inputs done, stopped, failed and not started, and the frame rate.
void ReportTally(const TrackManyOptions& options, const ChildTally& tally, size_t next,
                 double wall_s, std::ostream& report) {
  const size_t total = options.inputs.size();
  char rate[96];
  std::snprintf(rate, sizeof(rate), "%lld frames in %.2f s (%.0f frames/s)",
                static_cast<long long>(tally.frames), wall_s,
                wall_s > 0 ? tally.frames / wall_s : 0.0);
  report << "track: " << total << " inputs, --jobs " << options.jobs << ": " << tally.done
         << " done";
  if (tally.stopped > 0) report << ", " << tally.stopped << " stopped";
  if (!tally.failed.empty()) {
    report << ", " << tally.failed.size() << " failed (";
    for (size_t i = 0; i < tally.failed.size(); ++i) {
      report << (i == 0 ? "" : ", ") << tally.failed[i];
    }
    report << ")";
  }
  if (next < total) report << ", " << total - next << " not started (stop requested)";
  report << "; " << rate << "\n";
}

}  // namespace

std::vector<std::string> CsvNamesForInputs(const std::vector<std::string>& inputs,
                                           const std::string& out_dir) {
  std::set<std::string> taken;
  std::vector<std::string> names;
  for (const std::string& input : inputs) {
    const std::string stem = StemOf(input);
    std::string name = stem + ".csv";
    for (int n = 1; taken.count(name) != 0; ++n) name = stem + "-" + std::to_string(n) + ".csv";
    taken.insert(name);
    names.push_back((fs::path(out_dir) / name).string());
  }
  return names;
}

int RunTrackMany(const TrackManyOptions& options, std::ostream& report) {
  const auto start = std::chrono::steady_clock::now();
  const TrackOptions& common = options.common;
  RefuseSingleRunOptions(options);
  // What concerns every input fails once, before any child starts.
  const TrackingConfig config = LoadTrackConfig(common);
  const std::vector<std::string> csvs = PrepareOutputFolder(options, config);

  const size_t total = options.inputs.size();
  const StopRequest stop;  // Ctrl-C reaches the children too (same process group): they stop.
  bool forwarded = false;
  std::vector<Child> running;
  size_t next = 0;
  ChildTally tally;
  const std::string of_total = "/" + std::to_string(total) + "] ";
  while (next < total || !running.empty()) {
    while (!stop.requested() && next < total && running.size() < static_cast<size_t>(options.jobs)) {
      running.push_back(Spawn(options, next, csvs[next]));
      ++next;
    }
    if (stop.requested() && !forwarded) {
      // A SIGTERM sent to this process alone: the children are asked the same way.
      for (const Child& child : running) kill(child.pid, stop.signal());
      forwarded = true;
    }
    if (running.empty()) break;
    std::vector<pollfd> fds;
    for (const Child& child : running) fds.push_back({child.output_fd, POLLIN, 0});
    if (poll(fds.data(), fds.size(), 200) < 0 && errno != EINTR) {
      throw InputError(std::string("track: poll failed: ") + std::strerror(errno));
    }
    for (size_t i = running.size(); i-- > 0;) {
      if (fds[i].revents == 0) continue;
      Child& child = running[i];
      char buffer[4096];
      const ssize_t got = read(child.output_fd, buffer, sizeof(buffer));
      if (got > 0) {
        if (child.output.size() < (1 << 16)) child.output.append(buffer, static_cast<size_t>(got));
        continue;
      }
      if (got < 0 && errno == EINTR) continue;
      // End of its output: the child has exited (or is about to).
      FinishChild(options, csvs, of_total, child, &tally, report);
      report.flush();
      running.erase(running.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!common.quiet) ReportTally(options, tally, next, wall_s, report);
  if (stop.requested()) return 128 + stop.signal();
  return tally.exit_code;
}

}  // namespace softsight
