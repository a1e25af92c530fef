#include "softsight/core/file_write.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "softsight/core/error.h"

namespace softsight {

void LockOutputOrThrow(int fd, const std::string& path) {
  struct stat info {};
  // Devices (/dev/null, /dev/full, a terminal) are shared by nature: nothing to lock.
  if (::fstat(fd, &info) == 0 && !S_ISREG(info.st_mode)) return;
  while (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    if (errno == EINTR) continue;
    if (errno == EWOULDBLOCK) {
      throw InputError(EscapeForMessage(path) +
                       ": another program is writing this file; give this run its own name");
    }
    return;  // A file system without locks (some network mounts): write unlocked.
  }
}

void WriteWholeFileOrThrow(const std::string& path, const std::string& text) {
  const std::string shown = EscapeForMessage(path);
  struct stat info {};
  const bool special = ::stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode);
  // A device (/dev/null, a terminal) cannot be replaced by a rename: written in place.
  const std::string temporary = special ? path : path + ".part";
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
  if (fd < 0) throw InputError(shown + ": cannot write it (" + std::strerror(errno) + ")");
  try {
    LockOutputOrThrow(fd, temporary);
  } catch (...) {
    ::close(fd);
    throw InputError(shown + ": another program is writing this file; give this run its own name");
  }
  int error = special || ::ftruncate(fd, 0) == 0 ? 0 : errno;
  size_t written = 0;
  while (error == 0 && written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n > 0) {
      written += static_cast<size_t>(n);
    } else if (!(n < 0 && errno == EINTR)) {
      error = n < 0 ? errno : ENOSPC;
    }
  }
  if (error == 0 && !special && ::fsync(fd) != 0) error = errno;
  ::close(fd);
  if (error == 0 && !special && std::rename(temporary.c_str(), path.c_str()) != 0) error = errno;
  if (error != 0) {
    if (!special) ::unlink(temporary.c_str());
    throw InputError(shown + ": cannot write it (" + std::strerror(error) + ")");
  }
}

}  // namespace softsight
