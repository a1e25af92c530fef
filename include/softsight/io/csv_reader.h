// Reading back a CSV that softsight (or anyone) wrote: the counterpart of csv_writer.h, used by
// `plot`, the tests and anything that compares runs.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace softsight {

// A CSV read into columns of optional numbers (an empty field, "nan" or "inf" is absent).
struct CsvTable {
  std::string source{};                                      // File name, for messages, title.
  std::vector<std::string> columns{};                        // Header names, in file order.
  std::vector<std::vector<std::optional<double>>> values{};  // values[column][row].

  size_t row_count() const { return values.empty() ? 0 : values.front().size(); }
  std::optional<size_t> find(const std::string& column) const;
};

// Reads a comma-separated file with a header line, RFC 4180 as spreadsheets and Python's csv
// module write it: a field in double quotes may hold commas, line breaks and "" for a quote; CRLF
// line ends and a leading UTF-8 mark are fine; spaces around a field are not part of it. Throws
// InputError (one line naming the file, line and column) when the file is missing or unreadable,
// a quoted field is not closed or has text after its closing quote, a row has the wrong number
// of fields, or a field is not a number (except in `<name>_status` columns: words, read as
// absent).
CsvTable ReadCsvTable(const std::string& file);

}  // namespace softsight
