// Writing a file whole: the one writer every command's small outputs go through (configs,
// calibrations, summaries). The text goes to a temporary file beside the output, is synced, and
// is renamed over the output only when every byte was written, so a full disk, a file size limit
// or a killed process leaves the old file (or none), never a cut one; every failure is an error
// naming the file. A device (/dev/null, /dev/full) is written in place, its errors reported too.
#pragma once

#include <string>

namespace softsight {

// An open file descriptor of an output, locked for the writer alone (flock, exclusive). Throws
// InputError naming `path` when another process holds the lock: the other writer's file is
// left as it is. Call before truncating the file.
void LockOutputOrThrow(int fd, const std::string& path);

// Writes `text` as the whole content of `path`, through a temporary file beside it renamed over
// it, so a failure (disk full, a killed process) leaves the old file or nothing, never half.
// Throws InputError naming the file.
void WriteWholeFileOrThrow(const std::string& path, const std::string& text);

}  // namespace softsight
