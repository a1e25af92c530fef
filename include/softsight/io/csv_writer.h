// Per-frame results as CSV, one row per frame from a CsvColumnTable (csv_columns.h documents the
// columns). Every row goes to the file in one write() as it is produced, so a run that stops
// early (Ctrl-C, a crash, an error) leaves every row written so far intact; a failed write (disk
// full, a file-size limit) cuts the file back to its last complete row and throws InputError.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "softsight/core/types.h"
#include "softsight/io/csv_columns.h"

namespace softsight {

// The file side of a CSV writer: opens and locks the file (output_guard.h: a file another
// program is writing is refused and left intact), empties it, and writes whole lines.
class CsvFile {
 public:
  // Opens `path` and writes `header`. Throws InputError naming the file when it can't.
  CsvFile(const std::string& path, std::string header);
  ~CsvFile();
  CsvFile(const CsvFile&) = delete;
  CsvFile& operator=(const CsvFile&) = delete;

  // Writes `line` and a newline in one write(); `frame_index` names the row in the error. Throws
  // InputError naming the file and frame when the write fails. `line` is the caller's reused
  // buffer (the newline is appended to it).
  void put(std::string& line, std::optional<int64_t> frame_index);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
  off_t committed_bytes_ = 0;  // File size after the last complete row.
};

// One row per `Row` (which has a frame_index, naming the row in an error), from a column table.
template <typename Row>
class BasicCsvWriter {
 public:
  BasicCsvWriter(const std::string& path, BasicCsvColumnTable<Row> columns)
      : columns_(std::move(columns)), file_(path, columns_.header()) {}

  // Writes one row. Throws InputError naming the file and frame when the write fails.
  void write(const Row& row_data) {
    columns_.append_row(row_data, row_);
    file_.put(row_, row_data.frame_index);
  }
  const std::string& path() const { return file_.path(); }
  const BasicCsvColumnTable<Row>& columns() const { return columns_; }

 private:
  BasicCsvColumnTable<Row> columns_;
  CsvFile file_;
  std::string row_;  // Reused buffer: no allocation per row once it has grown.
};

class CsvWriter : public BasicCsvWriter<FrameResult> {
 public:
  CsvWriter(const std::string& path, CsvColumnTable columns)
      : BasicCsvWriter(path, std::move(columns)) {}
  // The tracking columns (TrackingColumns(marker_names, metric)).
  CsvWriter(const std::string& path, const std::vector<std::string>& marker_names, bool metric)
      : BasicCsvWriter(path, TrackingColumns(marker_names, metric)) {}
};

}  // namespace softsight
