#include "softsight/io/csv_reader.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "softsight/core/error.h"

namespace softsight {
namespace {

std::string Trim(const std::string& s) {
  const size_t begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const size_t end = s.find_last_not_of(" \t\r");
  return s.substr(begin, end - begin + 1);
}

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    fields.push_back(Trim(line.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

// A marker's status and track columns hold words ("found", "confirmed"): no number to read.
bool IsTextColumn(const std::string& column) {
  for (const std::string suffix : {"_status", "_track"}) {
    if (column.size() >= suffix.size() &&
        column.compare(column.size() - suffix.size(), suffix.size(), suffix) == 0) {
      return true;
    }
  }
  return false;
}

}  // namespace

std::optional<size_t> CsvTable::find(const std::string& column) const {
  for (size_t c = 0; c < columns.size(); ++c) {
    if (columns[c] == column) return c;
  }
  return std::nullopt;
}

CsvTable ReadCsvTable(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file + ": cannot read CSV (" + std::strerror(errno) + ")");
  CsvTable table;
  table.source = file;
  std::string line;
  if (!std::getline(in, line) || Trim(line).empty()) {
    throw InputError(file + ": empty CSV, expected a header line");
  }
  table.columns = SplitFields(line);
  table.values.resize(table.columns.size());
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (Trim(line).empty()) continue;
    const std::vector<std::string> fields = SplitFields(line);
    if (fields.size() != table.columns.size()) {
      throw InputError(file + ":" + std::to_string(line_number) + ": expected " +
                       std::to_string(table.columns.size()) + " fields, found " +
                       std::to_string(fields.size()));
    }
    for (size_t c = 0; c < fields.size(); ++c) {
      std::optional<double> value;
      if (!fields[c].empty() && !IsTextColumn(table.columns[c])) {
        char* end = nullptr;
        const double parsed = std::strtod(fields[c].c_str(), &end);
        if (end != fields[c].c_str() + fields[c].size()) {
          throw InputError(file + ":" + std::to_string(line_number) + ": column " +
                           table.columns[c] + ": '" + fields[c] + "' is not a number");
        }
        if (std::isfinite(parsed)) value = parsed;
      }
      table.values[c].push_back(value);
    }
  }
  return table;
}

}  // namespace softsight
