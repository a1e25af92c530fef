// The one guard every entry point runs before it writes anything (the program's commands, the
// library's run functions and the Python package alike): no output may be one of the run's
// inputs (the config and every file it names, a video or an image sequence's files, a profile)
// nor another output of the same call, and every output must be a place a file can be written.
// While an output is written it holds an exclusive lock, so a second program writing the same
// file is refused instead of interleaving its rows.
#pragma once

#include <string>
#include <vector>

#include "softsight/core/file_write.h"  // LockOutputOrThrow, WriteWholeFileOrThrow

namespace softsight {

struct PathRole {
  std::string role{};  // How the user named it: "--csv", "--input", "the config's camera file".
  std::string path{};
};

// Throws InputError (one line naming both roles and paths) when an output
// - is the same file as an input (device and inode, so links, "./x" and "../d/x" count),
// - names the same file as another output (also when neither exists yet: the paths are
//   compared after normalising them),
// - is an image pattern (frames/%04d.png) that would write one of the inputs' names,
// - cannot be written: a loop of symbolic links, a folder that does not exist or is not
//   writable, a folder where a file is expected.
// Empty output paths stand for "not written" and are skipped.
void CheckOutputsAreNotInputs(const std::vector<PathRole>& outputs,
                              const std::vector<PathRole>& inputs);

}  // namespace softsight
