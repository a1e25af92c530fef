#include "softsight/io/csv_writer.h"

#include <cerrno>
#include <cstring>

#include "softsight/core/error.h"

namespace softsight {

CsvWriter::CsvWriter(const std::string& path, CsvColumnTable columns)
    : path_(path), columns_(std::move(columns)) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) {
    throw InputError(path + ": cannot write CSV (" + std::strerror(errno) + ")");
  }
  row_ = columns_.header();
  put(std::nullopt);
}

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& marker_names,
                     bool metric)
    : CsvWriter(path, TrackingColumns(marker_names, metric)) {}

CsvWriter::~CsvWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void CsvWriter::write(const FrameResult& result) {
  columns_.append_row(result, row_);
  put(result.frame_index);
}

void CsvWriter::put(std::optional<int64_t> frame_index) {
  // One write of the whole line with its newline, flushed at once: rows reach the disk whole.
  row_ += '\n';
  if (std::fwrite(row_.data(), 1, row_.size(), file_) != row_.size() ||
      std::fflush(file_) != 0) {
    const std::string what =
        frame_index ? "frame " + std::to_string(*frame_index) : std::string("the header");
    throw InputError(path_ + ": writing " + what + " failed (" + std::strerror(errno) +
                     "); rows before it are intact");
  }
}

}  // namespace softsight
