// Per-frame results as CSV, the stable contract other programs rely on (README "CSV columns"):
//   frame, time_s, per marker <name>_x, <name>_y, <name>_found, <name>_score,
//   angle_deg, chord_px, sagitta_px, radius_px, arc_length_px, tip_disp_px,
//   chord_mm, sagitta_mm, radius_mm, arc_length_mm, tip_disp_mm (only when a metric model is set),
//   any extra columns a caller adds (the controller's), proc_ms.
// Undefined values are empty fields. Every row is flushed as it is written, so a run that stops
// early leaves every row written so far intact.
#pragma once

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "softsight/core/types.h"
#include "softsight/geometry/measurement.h"

namespace softsight {

#include "softsight/core/types.h"

class CsvWriter {
 public:
  // Opens `path` and writes the header. Throws InputError naming the file when it can't.
  CsvWriter(const std::string& path, const std::vector<std::string>& marker_names, bool metric,
            const std::vector<std::string>& extra_columns = {});
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  // Writes one row; `extra` holds one value per extra column (absent -> empty field).
  void write(const FrameResult& result, const std::vector<std::optional<double>>& extra = {});

  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  bool metric_ = false;
  size_t marker_count_ = 0;
  size_t extra_count_ = 0;
  std::string row_;  // Reused buffer: no allocation per row once it has grown.
};

}  // namespace softsight
