// Real images with known answers for golden tests: the sample data Debian's `opencv-doc` package
// ships (scripts/setup.sh installs it). Test-only; a header so any module's tests can use it
// without a library dependency.
//
// Tests skip (GTEST_SKIP, naming the package and the path) when a file is absent, so a machine
// without the package still runs the rest of the suite; CI installs it.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

namespace softsight::samples {

// Where opencv-doc puts its sample data; SOFTSIGHT_OPENCV_SAMPLES overrides it (a folder holding
// the same files, e.g. OpenCV's source tree's samples/data).
inline std::string OpenCvSamplesDir() {
  if (const char* dir = std::getenv("SOFTSIGHT_OPENCV_SAMPLES"); dir != nullptr && *dir != '\0') {
    return dir;
  }
  return "/usr/share/doc/opencv-doc/examples/data";
}

// The path of sample `name` (e.g. "left01.jpg"), or nothing when it is not installed. Debian
// may compress documentation, but OpenCV's readers need the plain file: a compressed copy only
// counts as absent (the message names it).
inline std::optional<std::string> OpenCvSample(const std::string& name) {
  const std::filesystem::path path = std::filesystem::path(OpenCvSamplesDir()) / name;
  std::error_code ignored;
  if (std::filesystem::is_regular_file(path, ignored)) return path.string();
  return std::nullopt;
}

// The GTEST_SKIP message for an absent sample.
inline std::string MissingSampleMessage(const std::string& name) {
  const std::filesystem::path path = std::filesystem::path(OpenCvSamplesDir()) / name;
  std::error_code ignored;
  const bool compressed = std::filesystem::is_regular_file(path.string() + ".gz", ignored);
  return "real-image golden test skipped: " + path.string() +
         (compressed ? " is only present gzip-compressed (gunzip it)"
                     : " is absent (install the Debian package opencv-doc: scripts/setup.sh "
                       "does; or point SOFTSIGHT_OPENCV_SAMPLES at OpenCV's samples/data)");
}

}  // namespace softsight::samples
