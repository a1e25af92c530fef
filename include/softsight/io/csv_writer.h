// Per-frame results as CSV, one row per frame from a CsvColumnTable (csv_columns.h documents the
// columns). Every row goes to the file in one write() as it is produced, so a run that stops
// early (Ctrl-C, a crash, an error) leaves every row written so far intact; a failed write (disk
// full, a file-size limit) cuts the file back to its last complete row and throws InputError.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "softsight/core/types.h"
#include "softsight/io/csv_columns.h"

namespace softsight {

class CsvWriter {
 public:
  // Opens `path` and writes the header. Throws InputError naming the file when it can't.
  CsvWriter(const std::string& path, CsvColumnTable columns);
  // The tracking columns (TrackingColumns(marker_names, metric)).
  CsvWriter(const std::string& path, const std::vector<std::string>& marker_names, bool metric);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  // Writes one row. Throws InputError naming the file and frame when the write fails.
  void write(const FrameResult& result);

  const std::string& path() const { return path_; }
  const CsvColumnTable& columns() const { return columns_; }

 private:
  // Writes row_ (plus the newline); frame_index names the row in the error.
  void put(std::optional<int64_t> frame_index);

  std::string path_;
  CsvColumnTable columns_;
  int fd_ = -1;
  off_t committed_bytes_ = 0;  // File size after the last complete row.
  std::string row_;  // Reused buffer: no allocation per row once it has grown.
};

}  // namespace softsight
