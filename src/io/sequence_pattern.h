// The numbered file names of an image sequence ("frames/%04d.png"), parsed by us rather than
// handed to printf: the user's text is never a format string (a stray "%s" or "%n" would read or
// write through an absent argument).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace softsight {

struct SequencePattern {
  std::string prefix;  // Everything before the number, folder included ("%%" already made "%").
  std::string suffix;  // Everything after it.
  int width = 0;       // %0Nd: at least N digits, zero-padded; %d: 0 (no padding).

  // The file name of `index` (>= 0), as printf would write it.
  std::string Format(int64_t index) const;
  // The index a file name stands for, or nothing when `name` is not one of this pattern's names
  // (wrong prefix or suffix, non-digits, padding that Format would not write, > 18 digits).
  std::optional<int64_t> Match(const std::string& name) const;
};

// Accepts exactly one %d or %0Nd (N = 1..18) in the file-name part of `pattern`, and "%%" for a
// literal percent sign; anything else ("%s", "%n", "%5d", two numbers, none, a "%" in a folder
// name) throws InputError naming the pattern and what is wrong.
SequencePattern ParseSequencePattern(const std::string& pattern);

// One existing file of a sequence and the number it stands for.
struct NumberedFile {
  int64_t index;
  std::string path;
};

// Every regular file `pattern` names, in number order, wherever the numbering starts and
// whatever gaps it has (left01 .. left09, left11 .. left14: thirteen files). Empty when none.
std::vector<NumberedFile> ListSequenceFiles(const SequencePattern& pattern);

// "the numbering has gaps: 3 file numbers missing (first: 5..7)" for `files` in number order,
// nothing without gaps. A gap is never silent: callers say it, with what they number by.
std::optional<std::string> DescribeNumberingGaps(const std::vector<NumberedFile>& files);

}  // namespace softsight
