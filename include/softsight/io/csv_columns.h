// The per-frame CSV as one table of columns: each column has its name (the header) and the code
// that writes its field for a frame (the row), so header and rows cannot disagree, and callers
// add columns by name (the controller's), never by position. The tracking columns are the stable
// contract other programs rely on (README "CSV columns"):
//   frame, time_s, per marker <name>_x, <name>_y, <name>_sigma_px, <name>_found, <name>_score,
//   <name>_status,
//   angle_deg, chord_px, sagitta_px, radius_px, arc_length_px, tip_disp_px,
//   angle_<name>_deg per inner marker of the chain (none without a chain),
//   chord_mm, sagitta_mm, radius_mm, arc_length_mm, tip_disp_mm (only with a metric model),
//   any extra columns a caller adds (the controller's), latency_result_ms, latency_row_ms,
//   proc_ms.
// Undefined values are empty fields.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "softsight/core/types.h"

namespace softsight {

// A column of a CSV with one row per `Row` (a FrameResult; a SceneTruth for the truth CSV,
// io/truth_csv.h).
template <typename Row>
struct BasicCsvColumn {
  std::string name{};
  // Appends this column's field for `row_data` to `row` (nothing for an empty field). Fields must
  // not contain commas, quotes or newlines (numbers and names).
  std::function<void(const Row& row_data, std::string& row)> append{};
};
using CsvColumn = BasicCsvColumn<FrameResult>;

// Appends `value` printed with `format` (printf style); nothing when absent.
void AppendCsvNumber(std::string& row, const std::optional<double>& value, const char* format);

// A numeric column: the value printed with `format` (printf style), absent -> empty field.
template <typename Row = FrameResult>
BasicCsvColumn<Row> NumberColumn(
    std::string name, std::type_identity_t<std::function<std::optional<double>(const Row&)>> value,
    const char* format = "%.6g") {
  return {std::move(name), [value = std::move(value), format](const Row& r, std::string& row) {
            AppendCsvNumber(row, value(r), format);
          }};
}

template <typename Row>
class BasicCsvColumnTable {
 public:
  void add(BasicCsvColumn<Row> column) { columns_.push_back(std::move(column)); }
  // Inserts before the column named `before` (e.g. "proc_ms"); throws std::logic_error when no
  // column has that name.
  void insert_before(const std::string& before, BasicCsvColumn<Row> column) {
    const std::optional<size_t> at = find(before);
    if (!at) throw std::logic_error("CsvColumnTable: no column '" + before + "'");
    columns_.insert(columns_.begin() + static_cast<std::ptrdiff_t>(*at), std::move(column));
  }

  size_t size() const { return columns_.size(); }
  const BasicCsvColumn<Row>& column(size_t i) const { return columns_[i]; }
  std::optional<size_t> find(const std::string& name) const {
    for (size_t i = 0; i < columns_.size(); ++i) {
      if (columns_[i].name == name) return i;
    }
    return std::nullopt;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> names;
    names.reserve(columns_.size());
    for (const BasicCsvColumn<Row>& column : columns_) names.push_back(column.name);
    return names;
  }

  // The header line and one row, both without the newline; append_row clears `row` first.
  std::string header() const {
    std::string line;
    for (size_t i = 0; i < columns_.size(); ++i) {
      if (i > 0) line += ',';
      line += columns_[i].name;
    }
    return line;
  }
  void append_row(const Row& row_data, std::string& row) const {
    row.clear();
    for (size_t i = 0; i < columns_.size(); ++i) {
      if (i > 0) row += ',';
      columns_[i].append(row_data, row);
    }
  }

 private:
  std::vector<BasicCsvColumn<Row>> columns_;
};
using CsvColumnTable = BasicCsvColumnTable<FrameResult>;

// The tracking columns above for these markers (in FrameResult::markers order), an inner-angle
// column per name of `inner_angle_markers` (Measurement::inner_angle_deg, in that order), the
// _mm twins when `metric`, then `extra`, then latency_result_ms and latency_row_ms (a caller's
// latency column goes between them: insert_before("latency_row_ms")), then proc_ms.
CsvColumnTable TrackingColumns(const std::vector<std::string>& marker_names, bool metric,
                               const std::vector<CsvColumn>& extra = {},
                               const std::vector<std::string>& inner_angle_markers = {});
// (The columns of a run of a TrackingConfig: TrackingColumns(config) in pipeline/sinks.h.)

}  // namespace softsight
