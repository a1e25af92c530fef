#include "softsight/io/csv_writer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "softsight/core/error.h"
#include "softsight/io/output_guard.h"

namespace softsight {

CsvFile::CsvFile(const std::string& path, std::string header) : path_(path) {
  // Opened without O_TRUNC: the file is emptied only once this writer holds its lock, so a
  // second program naming a CSV another one is writing is refused and leaves it intact.
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    throw InputError(EscapeForMessage(path) + ": cannot write CSV (" + std::strerror(errno) + ")");
  }
  try {
    LockOutputOrThrow(fd_, path);
    struct stat info {};
    if (::fstat(fd_, &info) == 0 && S_ISREG(info.st_mode) && ::ftruncate(fd_, 0) != 0) {
      throw InputError(EscapeForMessage(path) + ": cannot empty it (" + std::strerror(errno) + ")");
    }
    put(header, std::nullopt);
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

CsvFile::~CsvFile() {
  if (fd_ >= 0) ::close(fd_);
}

void CsvFile::put(std::string& line, std::optional<int64_t> frame_index) {
  // One write() of the whole line with its newline. When it fails (disk full, a file-size limit
  // with SIGXFSZ ignored, an I/O error) or writes only part of the line, the file is cut back to
  // the last complete row, so a reader never sees half a row.
  line += '\n';
  size_t written = 0;
  int error = 0;
  while (written < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + written, line.size() - written);
    if (n > 0) {
      written += static_cast<size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      error = n < 0 ? errno : ENOSPC;
      break;
    }
  }
  if (error == 0) {
    committed_bytes_ += static_cast<off_t>(line.size());
    return;
  }
  if (written > 0) {
    // Best effort: a device such as /dev/full cannot be truncated, and has no rows to keep.
    [[maybe_unused]] const int ignored = ::ftruncate(fd_, committed_bytes_);
  }
  const std::string what =
      frame_index ? "frame " + std::to_string(*frame_index) : std::string("the header");
  throw InputError(path_ + ": writing " + what + " failed (" + std::strerror(error) + ")" +
                   (frame_index ? "; the rows before it are intact" : ""));
}

}  // namespace softsight
