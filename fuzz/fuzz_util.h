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

// A scratch file `name` in a folder made once per process. libFuzzer ends its process with
// _Exit, which runs no destructor: scripts/fuzz.sh therefore names a folder of its own in
// SOFTSIGHT_FUZZ_SCRATCH and removes it after the run (whatever way the run ends). Without it
// (a harness run by hand) the folder is made in the temporary directory and removed only when
// the process ends through exit().
inline std::string WriteScratchFile(const std::string& name, const uint8_t* data, size_t size) {
  struct Folder {
    std::string path;
    Folder() {
      const char* given = std::getenv("SOFTSIGHT_FUZZ_SCRATCH");
      if (given != nullptr && *given != '\0') {
        path = given;
        std::error_code failed;
        std::filesystem::create_directories(path, failed);
        if (failed) std::abort();
        return;
      }
      path = (std::filesystem::temp_directory_path() / "softsight_fuzz_XXXXXX").string();
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
