// Running the `softsight` program from the app's tests (test code only): a run and what it said
// on stderr, and a run interrupted by a signal once its CSV has rows, as a user's Ctrl-C or a
// service manager's SIGTERM would.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "core/test_util.h"

namespace softsight::testing {

// examples/rig.yaml: the control examples' config (the synthetic scene's markers and a rig).
inline std::string RigExample() { return SourceDir() + "/examples/rig.yaml"; }

// How a run of the program ended: its exit code (-1 when a signal ended it) and its stderr.
struct ProgramRun {
  int exit_code;
  std::string stderr_text;
};

// Runs `softsight ARGS` with no input and its stdout discarded; stderr goes to a file in `dir`.
inline ProgramRun RunProgram(const std::string& args, const TempDir& dir) {
  const std::string command = SoftsightBinary() + " " + args + " > /dev/null 2> " +
                              dir.file("stderr.txt") + " < /dev/null";
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ReadTextFile(dir.file("stderr.txt"))};
}

// Runs `softsight ARGS 2> stderr_file`, sends `signal` once `csv` holds `rows` lines (or when
// the program has ended by itself), and returns the wait status. The commands install their
// handlers before the first row, so a run signalled after its rows ends through its own path.
// Waits on the file, not on a clock: no sleep decides the outcome.
inline int RunAndSignalOnceRowsAreWritten(const std::string& args, const std::string& csv,
                                          size_t rows, int signal,
                                          const std::string& stderr_file) {
  const std::string command =
      "exec \"" + SoftsightBinary() + "\" " + args + " 2> \"" + stderr_file + "\"";
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  while (ReadLines(csv).size() < rows) {
    if (waitpid(pid, &status, WNOHANG) == pid) return status;  // Ended before the signal.
    usleep(2000);
  }
  kill(pid, signal);
  waitpid(pid, &status, 0);
  return status;
}

}  // namespace softsight::testing
