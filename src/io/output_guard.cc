#include "softsight/io/output_guard.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <optional>

#include "io/sequence_pattern.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;

struct FileId {
  dev_t device;
  ino_t inode;
  bool operator==(const FileId& o) const { return device == o.device && inode == o.inode; }
};

std::optional<FileId> IdOf(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return std::nullopt;
  return FileId{info.st_dev, info.st_ino};
}

std::string Named(const PathRole& p) { return p.role + " " + EscapeForMessage(p.path); }

// The path as the file system would resolve it, for outputs that do not exist yet: the existing
// part made canonical, the rest normalised lexically ("a/./b/../c" is "a/c").
fs::path Normalised(const std::string& path) {
  std::error_code error;
  // Absolute first: weakly_canonical leaves a relative path of which nothing exists relative
  // ("y.csv"), but makes "./y.csv" absolute, and the two would not compare equal.
  const fs::path absolute = fs::absolute(path, error);
  if (error) return fs::path(path).lexically_normal();
  fs::path out = fs::weakly_canonical(absolute, error);
  return error ? absolute.lexically_normal() : out.lexically_normal();
}

// The input file an image-pattern output (frames/%04d.png) would write over: one in the
// pattern's folder whose name the pattern writes. Nothing for other outputs, or a pattern the
// writer will refuse anyway.
const PathRole* InputAPatternWouldWrite(const std::string& output,
                                        const std::vector<PathRole>& inputs) {
  if (output.find('%') == std::string::npos || IdOf(output)) return nullptr;
  SequencePattern pattern;
  try {
    pattern = ParseSequencePattern(output);
  } catch (const InputError&) {
    return nullptr;
  }
  const fs::path folder = fs::path(pattern.prefix).parent_path();
  const SequencePattern names{fs::path(pattern.prefix).filename().string(), pattern.suffix,
                              pattern.width};
  for (const PathRole& input : inputs) {
    const fs::path path(input.path);
    if (!names.Match(path.filename().string())) continue;
    std::error_code error;
    if (fs::equivalent(folder.empty() ? fs::path(".") : folder,
                       path.parent_path().empty() ? fs::path(".") : path.parent_path(), error)) {
      return &input;
    }
  }
  return nullptr;
}

// Whether a file can be created or replaced at `output`, said before any work is done (an
// identification runs minutes of experiment before it writes its config: a typo in the folder
// must not cost the result).
void CheckWritable(const PathRole& output) {
  struct stat info {};
  if (::stat(output.path.c_str(), &info) != 0) {
    if (errno == ELOOP) {
      throw InputError(Named(output) + ": a loop of symbolic links; give a file name");
    }
    if (errno == ENAMETOOLONG) throw InputError(Named(output) + ": the name is too long");
    if (errno == ENOTDIR) {
      throw InputError(Named(output) + ": a part of the path is a file, not a folder");
    }
  } else if (S_ISDIR(info.st_mode)) {
    throw InputError(Named(output) + ": is a folder; give a file name");
  }
  if (output.path.find('%') != std::string::npos) return;  // A pattern: its writer checks.
  fs::path folder = fs::path(output.path).parent_path();
  if (folder.empty()) folder = ".";
  struct stat folder_info {};
  if (::stat(folder.c_str(), &folder_info) != 0 || !S_ISDIR(folder_info.st_mode)) {
    throw InputError(Named(output) + ": the folder " + EscapeForMessage(folder.string()) +
                     " does not exist");
  }
  const bool exists = ::access(output.path.c_str(), F_OK) == 0;
  if (exists ? ::access(output.path.c_str(), W_OK) != 0 : ::access(folder.c_str(), W_OK) != 0) {
    throw InputError(Named(output) + ": cannot write there (" + std::strerror(errno) + ")");
  }
}

}  // namespace

void CheckOutputsAreNotInputs(const std::vector<PathRole>& outputs,
                              const std::vector<PathRole>& inputs) {
  for (const PathRole& input : inputs) {
    struct stat info {};
    if (!input.path.empty() && ::stat(input.path.c_str(), &info) != 0 && errno == ELOOP) {
      throw InputError(Named(input) + ": a loop of symbolic links");
    }
  }
  for (size_t i = 0; i < outputs.size(); ++i) {
    const PathRole& output = outputs[i];
    if (output.path.empty()) continue;
    CheckWritable(output);
    if (const PathRole* input = InputAPatternWouldWrite(output.path, inputs)) {
      throw InputError(Named(output) + " would write " + Named(*input) +
                       ": refusing to overwrite an input (choose another name)");
    }
    const std::optional<FileId> id = IdOf(output.path);
    if (id) {
      for (const PathRole& input : inputs) {
        if (!input.path.empty() && IdOf(input.path) == id) {
          throw InputError(Named(output) + " is " + Named(input) +
                           ": refusing to overwrite an input (choose another name)");
        }
      }
    }
    const fs::path normalised = Normalised(output.path);
    for (size_t j = 0; j < i; ++j) {
      if (outputs[j].path.empty()) continue;
      const bool same = id ? IdOf(outputs[j].path) == id : Normalised(outputs[j].path) == normalised;
      if (same) {
        throw InputError(Named(output) + " and " + Named(outputs[j]) +
                         " are the same file: give each output its own name");
      }
    }
  }
}

}  // namespace softsight
