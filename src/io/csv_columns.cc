#include "softsight/io/csv_columns.h"

#include <charconv>
#include <chrono>
#include <cstdio>
#include <system_error>
#include <utility>

namespace softsight {

void AppendCsvNumber(std::string& row, const std::optional<double>& value, const char* format) {
  if (!value) return;
  char buffer[64];
  // The columns' formats, "%.<digits>f" and "%.<digits>g", by std::to_chars, which the standard
  // defines as printf's text of them (the same digits, rounding, "-0.0000", "nan", "inf"): a
  // third of snprintf's instructions (its format parsing and multi-precision digits), ~16M of a
  // 300-frame `track` with three markers (issue 45). Any other format, or a text longer than the
  // buffer (cut short as snprintf cuts it), goes through snprintf.
  if (format[0] == '%' && format[1] == '.' && format[2] >= '0' && format[2] <= '9') {
    int precision = format[2] - '0';
    const char* kind = format + 3;
    if (*kind >= '0' && *kind <= '9') precision = precision * 10 + (*kind++ - '0');
    if ((kind[0] == 'f' || kind[0] == 'g') && kind[1] == '\0') {
      const std::chars_format chars = kind[0] == 'f' ? std::chars_format::fixed
                                                     : std::chars_format::general;
      // One less than the buffer: snprintf keeps the last byte for its terminating zero.
      const std::to_chars_result printed =
          std::to_chars(buffer, buffer + sizeof(buffer) - 1, *value, chars, precision);
      if (printed.ec == std::errc{}) {
        row.append(buffer, printed.ptr);
        return;
      }
    }
  }
  std::snprintf(buffer, sizeof(buffer), format, *value);
  row += buffer;
}

namespace {

// A measurement field, 4 decimals as the contract has always had.
CsvColumn MeasurementColumn(std::string name, std::optional<double> Measurement::*member) {
  return {std::move(name), [member](const FrameResult& r, std::string& row) {
            AppendCsvNumber(row, r.measurement.*member, "%.4f");
          }};
}

// Milliseconds from `captured` to now; absent for a result without a capture time.
std::optional<double> MillisecondsSince(std::chrono::steady_clock::time_point captured) {
  if (captured == std::chrono::steady_clock::time_point{}) return std::nullopt;
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - captured)
      .count();
}

}  // namespace

CsvColumnTable TrackingColumns(const std::vector<std::string>& marker_names, bool metric,
                               const std::vector<CsvColumn>& extra,
                               const std::vector<std::string>& inner_angle_markers) {
  CsvColumnTable table;
  table.add({"frame", [](const FrameResult& r, std::string& row) {
               row += std::to_string(r.frame_index);
             }});
  table.add({"time_s", [](const FrameResult& r, std::string& row) {
               AppendCsvNumber(row, r.time_s, "%.6f");
             }});
  for (size_t i = 0; i < marker_names.size(); ++i) {
    const std::string& name = marker_names[i];
    // Per-marker columns read markers[i]: the session reports every marker in config order.
    table.add({name + "_x", [i](const FrameResult& r, std::string& row) {
                 const Observation& o = r.markers.at(i).observation;
                 if (o.found()) AppendCsvNumber(row, o.position_px->x, "%.4f");
               }});
    table.add({name + "_y", [i](const FrameResult& r, std::string& row) {
                 const Observation& o = r.markers.at(i).observation;
                 if (o.found()) AppendCsvNumber(row, o.position_px->y, "%.4f");
               }});
    table.add({name + "_sigma_px", [i](const FrameResult& r, std::string& row) {
                 const Observation& o = r.markers.at(i).observation;
                 if (o.found()) AppendCsvNumber(row, o.sigma_px, "%.4f");
               }});
    table.add({name + "_found", [i](const FrameResult& r, std::string& row) {
                 row += r.markers.at(i).observation.found() ? '1' : '0';
               }});
    table.add({name + "_score", [i](const FrameResult& r, std::string& row) {
                 AppendCsvNumber(row, r.markers.at(i).observation.score, "%.4f");
               }});
    // Why the marker has no position (or "found"): a word, never a number.
    table.add({name + "_status", [i](const FrameResult& r, std::string& row) {
                 row += MarkerStatusName(r.markers.at(i).observation.status());
               }});
    // What the session believes of the marker over time (tentative, confirmed, coasting, lost).
    table.add({name + "_track", [i](const FrameResult& r, std::string& row) {
                 row += TrackStateName(r.markers.at(i).track);
               }});
  }
  table.add(MeasurementColumn("angle_deg", &Measurement::angle_deg));
  table.add(MeasurementColumn("chord_px", &Measurement::chord_px));
  table.add(MeasurementColumn("sagitta_px", &Measurement::sagitta_px));
  table.add(MeasurementColumn("radius_px", &Measurement::radius_px));
  table.add(MeasurementColumn("arc_length_px", &Measurement::arc_length_px));
  table.add(MeasurementColumn("tip_disp_px", &Measurement::tip_disp_px));
  for (size_t k = 0; k < inner_angle_markers.size(); ++k) {
    table.add({"angle_" + inner_angle_markers[k] + "_deg",
               [k](const FrameResult& r, std::string& row) {
                 const auto& angles = r.measurement.inner_angle_deg;
                 if (k < angles.size()) AppendCsvNumber(row, angles[k], "%.4f");
               }});
  }
  if (metric) {
    table.add(MeasurementColumn("chord_mm", &Measurement::chord_mm));
    table.add(MeasurementColumn("sagitta_mm", &Measurement::sagitta_mm));
    table.add(MeasurementColumn("radius_mm", &Measurement::radius_mm));
    table.add(MeasurementColumn("arc_length_mm", &Measurement::arc_length_mm));
    table.add(MeasurementColumn("tip_disp_mm", &Measurement::tip_disp_mm));
  }
  for (const CsvColumn& column : extra) table.add(column);
  // Latency from the frame's capture (Frame::captured) to its result, and to this row: taken
  // while the row is formatted, just before it is written, so every sink before the CSV (the
  // controller's command) is in it. Timings, like proc_ms: they differ from run to run.
  table.add({"latency_result_ms", [](const FrameResult& r, std::string& row) {
               const bool stamped = r.captured != std::chrono::steady_clock::time_point{};
               AppendCsvNumber(row, stamped ? std::optional<double>(r.latency_result_ms) : std::nullopt,
                            "%.3f");
             }});
  table.add({"latency_row_ms", [](const FrameResult& r, std::string& row) {
               AppendCsvNumber(row, MillisecondsSince(r.captured), "%.3f");
             }});
  table.add({"proc_ms", [](const FrameResult& r, std::string& row) {
               AppendCsvNumber(row, r.proc_ms, "%.4f");
             }});
  return table;
}

}  // namespace softsight
