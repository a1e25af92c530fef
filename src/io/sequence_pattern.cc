#include "io/sequence_pattern.h"

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr int kMaxDigits = 18;  // Every 18-digit number fits an int64_t.

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

[[noreturn]] void Reject(const std::string& pattern, const std::string& problem) {
  throw InputError(pattern + ": " + problem +
                   " (an image sequence pattern holds one %d or %0Nd, e.g. frames/%04d.png)");
}

}  // namespace

std::string SequencePattern::Format(int64_t index) const {
  std::string digits = std::to_string(index);
  if (static_cast<int>(digits.size()) < width) digits.insert(0, width - digits.size(), '0');
  return prefix + digits + suffix;
}

std::optional<int64_t> SequencePattern::Match(const std::string& name) const {
  if (name.size() <= prefix.size() + suffix.size()) return std::nullopt;
  if (name.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  if (name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) return std::nullopt;
  const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  if (digits.size() > static_cast<size_t>(kMaxDigits)) return std::nullopt;
  int64_t index = 0;
  for (char c : digits) {
    if (!IsDigit(c)) return std::nullopt;
    index = index * 10 + (c - '0');
  }
  // Only the spelling Format writes: "7" for %d, "0007" for %04d (not "07" nor "007").
  if (Format(index) != name) return std::nullopt;
  return index;
}

SequencePattern ParseSequencePattern(const std::string& pattern) {
  SequencePattern parsed;
  std::string* out = &parsed.prefix;
  bool have_number = false;
  size_t last_slash = pattern.find_last_of('/');
  for (size_t i = 0; i < pattern.size(); ++i) {
    const char c = pattern[i];
    if (c != '%') {
      *out += c;
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      *out += '%';
      ++i;
      continue;
    }
    // A conversion: %d or %0<digits>d, nothing else.
    size_t j = i + 1;
    int width = 0;
    if (j < pattern.size() && pattern[j] == '0') {
      ++j;
      const size_t digits_start = j;
      while (j < pattern.size() && IsDigit(pattern[j]) && j - digits_start < 3) {
        width = width * 10 + (pattern[j] - '0');
        ++j;
      }
      if (j == digits_start || width < 1 || width > kMaxDigits) {
        Reject(pattern, "'%0' must be followed by a width of 1 to 18 and 'd'");
      }
    }
    if (j >= pattern.size() || pattern[j] != 'd') {
      const std::string spec = pattern.substr(i, std::min<size_t>(j + 1, pattern.size()) - i);
      Reject(pattern, "'" + spec + "' is not %d or %0Nd");
    }
    if (have_number) Reject(pattern, "more than one number");
    if (last_slash != std::string::npos && i < last_slash) {
      Reject(pattern, "the number must be in the file name, not in a folder name");
    }
    have_number = true;
    parsed.width = width;
    out = &parsed.suffix;
    i = j;
  }
  if (!have_number) Reject(pattern, "no %d in the pattern");
  return parsed;
}

std::vector<NumberedFile> ListSequenceFiles(const SequencePattern& pattern) {
  namespace fs = std::filesystem;
  const size_t slash = pattern.prefix.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "." : pattern.prefix.substr(0, slash + 1);
  const SequencePattern names{slash == std::string::npos ? pattern.prefix
                                                         : pattern.prefix.substr(slash + 1),
                              pattern.suffix, pattern.width};
  std::vector<NumberedFile> files;
  std::error_code error;
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    const std::optional<int64_t> index = names.Match(it->path().filename().string());
    std::error_code ignored;
    if (index && it->is_regular_file(ignored)) files.push_back({*index, pattern.Format(*index)});
  }
  std::sort(files.begin(), files.end(),
            [](const NumberedFile& a, const NumberedFile& b) { return a.index < b.index; });
  return files;
}

std::optional<std::string> DescribeNumberingGaps(const std::vector<NumberedFile>& files) {
  int64_t missing = 0;
  std::string first_gap;
  for (size_t i = 1; i < files.size(); ++i) {
    const int64_t gap = files[i].index - files[i - 1].index - 1;
    if (gap <= 0) continue;
    if (missing == 0) {
      first_gap = gap == 1 ? std::to_string(files[i - 1].index + 1)
                           : std::to_string(files[i - 1].index + 1) + ".." +
                                 std::to_string(files[i].index - 1);
    }
    missing += gap;
  }
  if (missing == 0) return std::nullopt;
  return "the numbering has gaps: " + std::to_string(missing) + " file number" +
         (missing == 1 ? "" : "s") + " missing (first: " + first_gap + ")";
}

}  // namespace softsight
