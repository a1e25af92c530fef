#include "softsight/io/csv_writer.h"

#include <cerrno>
#include <cstring>

#include "softsight/core/error.h"
#include "softsight/core/types.h"

namespace softsight {
namespace {

void Append(std::string& row, const std::optional<double>& value, const char* format) {
  row += ',';
  if (!value) return;
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, *value);
  row += buffer;
}

}  // namespace

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& marker_names,
                     bool metric, const std::vector<std::string>& extra_columns)
    : path_(path), metric_(metric), marker_count_(marker_names.size()),
      extra_count_(extra_columns.size()) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) {
    throw InputError(path + ": cannot write CSV (" + std::strerror(errno) + ")");
  }
  std::string header = "frame,time_s";
  for (const std::string& name : marker_names) {
    header += "," + name + "_x," + name + "_y," + name + "_found," + name + "_score";
  }
  header += ",angle_deg,chord_px,sagitta_px,radius_px,arc_length_px,tip_disp_px";
  if (metric_) header += ",chord_mm,sagitta_mm,radius_mm,arc_length_mm,tip_disp_mm";
  for (const std::string& column : extra_columns) header += "," + column;
  header += ",proc_ms\n";
  std::fputs(header.c_str(), file_);
  std::fflush(file_);
}

CsvWriter::~CsvWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void CsvWriter::write(const FrameResult& result, const std::vector<std::optional<double>>& extra) {
  CV_Assert(result.markers.size() == marker_count_);
  CV_Assert(extra.size() == extra_count_ || extra.empty());
  row_.clear();
  row_ += std::to_string(result.frame_index);
  Append(row_, result.time_s, "%.6f");
  for (const MarkerObservation& marker : result.markers) {
    const Observation& obs = marker.observation;
    Append(row_, obs.found() ? std::optional<double>(obs.position_px->x) : std::nullopt, "%.4f");
    Append(row_, obs.found() ? std::optional<double>(obs.position_px->y) : std::nullopt, "%.4f");
    row_ += obs.found() ? ",1" : ",0";
    Append(row_, obs.score, "%.4f");
  }
  const Measurement& m = result.measurement;
  Append(row_, m.angle_deg, "%.4f");
  Append(row_, m.chord_px, "%.4f");
  Append(row_, m.sagitta_px, "%.4f");
  Append(row_, m.radius_px, "%.4f");
  Append(row_, m.arc_length_px, "%.4f");
  Append(row_, m.tip_disp_px, "%.4f");
  if (metric_) {
    Append(row_, m.chord_mm, "%.4f");
    Append(row_, m.sagitta_mm, "%.4f");
    Append(row_, m.radius_mm, "%.4f");
    Append(row_, m.arc_length_mm, "%.4f");
    Append(row_, m.tip_disp_mm, "%.4f");
  }
  for (size_t i = 0; i < extra_count_; ++i) {
    Append(row_, extra.empty() ? std::nullopt : extra[i], "%.6g");
  }
  Append(row_, result.proc_ms, "%.4f");
  row_ += '\n';
  if (std::fputs(row_.c_str(), file_) < 0 || std::fflush(file_) != 0) {
    throw InputError(path_ + ": writing frame " + std::to_string(result.frame_index) +
                     " failed (" + std::strerror(errno) + "); rows before it are intact");
  }
}

}  // namespace softsight
