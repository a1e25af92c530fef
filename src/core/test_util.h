// Small helpers shared by the tests of every module (test code only).
#pragma once

#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace softsight::testing {

// The running test's name as a file-name part ("Seeks_0" for "Seeks/0"), or "suite" outside a
// test (SetUpTestSuite). A '/' of a parameterised test's name would nest the folder, and removing
// the inner one would leave the outer behind.
inline std::string RunningTestLabel() {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string label = test != nullptr ? test->name() : "suite";
  for (char& c : label) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) c = '_';
  }
  return label;
}

// A fresh folder under the system temp dir, removed with everything in it when it goes out of
// scope: every test that writes files writes them in one (a test fixture's member, a local, or
// a suite's, made in SetUpTestSuite and reset in TearDownTestSuite), never in a process-wide
// static, whose destructor a program that ends through _exit or a signal never runs.
class TempDir {
 public:
  explicit TempDir(const std::string& label = RunningTestLabel()) {
    std::random_device device;
    const auto name = "softsight_test_" + std::to_string(::getpid()) + "_" +
                      std::to_string(device()) + "_" + label;
    path_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    // A test may have taken a permission away (to test an unwritable folder): give it back.
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all,
                                 std::filesystem::perm_options::add, ignored);
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline void WriteTextFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// A whole file as it is on disk (text and binary alike).
inline std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

inline std::vector<std::string> ReadLines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

inline std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::stringstream stream(line);
  while (std::getline(stream, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// Path of the built `softsight` program (set by ctest), for end-to-end tests.
inline std::string SoftsightBinary() {
  const char* path = std::getenv("SOFTSIGHT_BINARY");
  return path != nullptr ? path : SOFTSIGHT_TEST_BINARY;
}

inline std::string SourceDir() {
  const char* path = std::getenv("SOFTSIGHT_SOURCE_DIR");
  return path != nullptr ? path : SOFTSIGHT_TEST_SOURCE_DIR;
}

}  // namespace softsight::testing
