#include "softsight/io/csv_reader.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string_view>

#include "softsight/core/error.h"

namespace softsight {
namespace {

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string Trim(std::string_view s) {
  size_t begin = 0, end = s.size();
  while (begin < end && IsBlank(s[begin])) ++begin;
  while (end > begin && IsBlank(s[end - 1])) --end;
  return std::string(s.substr(begin, end - begin));
}

// RFC 4180 records: fields separated by commas, records by newlines (LF or CRLF); a field in
// double quotes may hold commas, newlines and doubled quotes ("" for one "). Spaces around a
// field are not part of it (softsight writes none; a spreadsheet's "1, 2" reads as 1 and 2).
class CsvRecords {
 public:
  CsvRecords(std::string text, const std::string& file) : text_(std::move(text)), file_(file) {
    if (text_.compare(0, 3, "\xEF\xBB\xBF") == 0) position_ = 3;  // A spreadsheet's UTF-8 mark.
  }

  // The next record's fields, unquoted; false at the end of the text. A blank line is a record
  // of one empty field.
  bool next(std::vector<std::string>& fields) {
    fields.clear();
    if (position_ >= text_.size()) return false;
    line_ = next_line_;
    while (true) {
      fields.push_back(field(fields.size()));
      if (position_ >= text_.size()) return true;
      const char separator = text_[position_++];
      if (separator == '\n') {
        ++next_line_;
        return true;
      }
      // Otherwise a comma: field() stops only there, at a newline or at the end.
    }
  }

  // The line the last record began on (from 1).
  int line() const { return line_; }

 private:
  std::string field(size_t index) {
    const size_t start = position_;
    while (position_ < text_.size() && IsBlank(text_[position_]) && text_[position_] != '\r') {
      ++position_;
    }
    if (position_ >= text_.size() || text_[position_] != '"') {
      position_ = std::min(text_.find_first_of(",\n", start), text_.size());
      return Trim(std::string_view(text_).substr(start, position_ - start));
    }
    ++position_;  // The opening quote.
    std::string value;
    while (true) {
      if (position_ >= text_.size()) {
        throw InputError(file_ + ":" + std::to_string(line_) + ": field " +
                         std::to_string(index + 1) + ": a quoted field is not closed (no '\"' "
                         "before the end of the file)");
      }
      const char c = text_[position_++];
      if (c == '"') {
        if (position_ < text_.size() && text_[position_] == '"') {
          value += '"';
          ++position_;
          continue;
        }
        break;
      }
      if (c == '\n') ++next_line_;
      value += c;
    }
    while (position_ < text_.size() && IsBlank(text_[position_])) ++position_;
    if (position_ < text_.size() && text_[position_] != ',' && text_[position_] != '\n') {
      throw InputError(file_ + ":" + std::to_string(next_line_) + ": field " +
                       std::to_string(index + 1) + ": text after a quoted field's closing '\"' "
                       "(a quote inside a quoted field is written twice: \"\")");
    }
    return value;
  }

  std::string text_;
  const std::string& file_;
  size_t position_ = 0;
  int line_ = 1;
  int next_line_ = 1;
};

bool IsBlankRecord(const std::vector<std::string>& fields) {
  return fields.size() == 1 && fields.front().empty();
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
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file + ": cannot read CSV (" + std::strerror(errno) + ")");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file + ": cannot read CSV (" + std::strerror(errno) + ")");
  CsvRecords records(std::move(text), file);
  CsvTable table;
  table.source = file;
  std::vector<std::string> fields;
  if (!records.next(fields) || IsBlankRecord(fields)) {
    throw InputError(file + ": empty CSV, expected a header line");
  }
  table.columns = fields;
  table.values.resize(table.columns.size());
  while (records.next(fields)) {
    if (IsBlankRecord(fields)) continue;
    const std::string where = file + ":" + std::to_string(records.line());
    if (fields.size() != table.columns.size()) {
      throw InputError(where + ": expected " + std::to_string(table.columns.size()) +
                       " fields, found " + std::to_string(fields.size()));
    }
    for (size_t c = 0; c < fields.size(); ++c) {
      std::optional<double> value;
      if (!fields[c].empty() && !IsTextColumn(table.columns[c])) {
        char* end = nullptr;
        const double parsed = std::strtod(fields[c].c_str(), &end);
        if (end != fields[c].c_str() + fields[c].size()) {
          throw InputError(where + ": column " + table.columns[c] + ": '" + fields[c] +
                           "' is not a number");
        }
        if (std::isfinite(parsed)) value = parsed;
      }
      table.values[c].push_back(value);
    }
  }
  return table;
}

}  // namespace softsight
