// Shared by the fuzz targets: the readers under test take file names, so each input is written
// to one scratch file per process first.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace softsight::fuzz {

// A scratch file `name` in a folder made once per process and removed with what it holds when
// the process ends normally (a fuzz run that finds a crash leaves it, beside the crash input).
inline std::string WriteScratchFile(const std::string& name, const uint8_t* data, size_t size) {
  struct Folder {
    std::string path = "/tmp/softsight_fuzz_XXXXXX";
    Folder() {
      if (mkdtemp(path.data()) == nullptr) std::abort();
    }
    ~Folder() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Folder folder;
  const std::string path = folder.path + "/" + name;
  // A new file each time, not the old one truncated: ext4 flushes a file rewritten through
  // truncation on close (auto_da_alloc), 3-4 ms per input, which made the run wait on the disk.
  std::remove(path.c_str());
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, file) != size) std::abort();
  std::fclose(file);
  return path;
}

}  // namespace softsight::fuzz
