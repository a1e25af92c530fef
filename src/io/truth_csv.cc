#include "softsight/io/truth_csv.h"

#include <cmath>
#include <optional>
#include <set>

#include "softsight/core/error.h"
#include "softsight/io/csv_reader.h"

namespace softsight {
namespace {

constexpr const char* kFormat = "%.6f";

// Each column's name, spelled here only: the writer and the reader use these.
const char* const kFrame = "frame";
const char* const kTime = "time_s";
const char* const kBend = "bend_deg";
const char* const kCentrelineRadius = "centreline_radius_px";
std::string XColumn(const std::string& marker) { return marker + "_x"; }
std::string YColumn(const std::string& marker) { return marker + "_y"; }
std::string VisibleColumn(const std::string& marker) { return marker + "_visible"; }

// The measurement columns, in file order.
struct MeasurementField {
  const char* name;
  std::optional<double> Measurement::*member;
};
const MeasurementField kMeasurementFields[] = {
    {"angle_deg", &Measurement::angle_deg},     {"chord_px", &Measurement::chord_px},
    {"sagitta_px", &Measurement::sagitta_px},   {"radius_px", &Measurement::radius_px},
    {"arc_length_px", &Measurement::arc_length_px}, {"tip_disp_px", &Measurement::tip_disp_px},
};

std::string LineOf(const std::string& file, size_t row) {
  return file + ": line " + std::to_string(row + 2) + ": ";  // After the header, from 1.
}

}  // namespace

BasicCsvColumnTable<SceneTruth> TruthColumns(const std::vector<std::string>& marker_names) {
  BasicCsvColumnTable<SceneTruth> table;
  table.add({kFrame, [](const SceneTruth& t, std::string& row) {
               row += std::to_string(t.frame_index);
             }});
  table.add(NumberColumn<SceneTruth>(kTime, [](const SceneTruth& t) { return t.time_s; }, kFormat));
  table.add(NumberColumn<SceneTruth>(kBend, [](const SceneTruth& t) { return t.bend_deg; }, kFormat));
  for (size_t i = 0; i < marker_names.size(); ++i) {
    // Per-marker columns read markers[i]: a scene reports every marker in its order.
    const auto centroid = [i](const SceneTruth& t) { return t.markers.at(i).centroid_px; };
    table.add(NumberColumn<SceneTruth>(XColumn(marker_names[i]), [centroid](const SceneTruth& t) {
      const auto c = centroid(t);
      return c ? std::optional<double>(c->x) : std::nullopt;
    }, kFormat));
    table.add(NumberColumn<SceneTruth>(YColumn(marker_names[i]), [centroid](const SceneTruth& t) {
      const auto c = centroid(t);
      return c ? std::optional<double>(c->y) : std::nullopt;
    }, kFormat));
    table.add(NumberColumn<SceneTruth>(
        VisibleColumn(marker_names[i]),
        [i](const SceneTruth& t) { return t.markers.at(i).visible_fraction; }, kFormat));
  }
  for (const MeasurementField& field : kMeasurementFields) {
    table.add(NumberColumn<SceneTruth>(
        field.name, [member = field.member](const SceneTruth& t) { return t.measurement.*member; },
        kFormat));
  }
  table.add(NumberColumn<SceneTruth>(
      kCentrelineRadius, [](const SceneTruth& t) { return t.centreline_radius_px; }, kFormat));
  return table;
}

TruthCsv ReadTruthCsv(const std::string& file, const std::vector<std::string>& wanted) {
  const CsvTable table = ReadCsvTable(file);
  const auto frame_column = table.find(kFrame);
  if (!frame_column) {
    throw InputError(file + ": no 'frame' column (the truth needs frame, and <name>_x, <name>_y "
                     "per marker)");
  }
  struct MarkerColumns {
    size_t x, y;
    std::optional<size_t> visible;
  };
  TruthCsv truth;
  std::vector<MarkerColumns> columns;
  for (size_t i = 0; i < wanted.size(); ++i) {
    const auto x = table.find(XColumn(wanted[i])), y = table.find(YColumn(wanted[i]));
    if (!x || !y) {
      truth.missing.push_back(wanted[i]);
      continue;
    }
    truth.markers.push_back(wanted[i]);
    truth.wanted_index.push_back(i);
    columns.push_back({*x, *y, table.find(VisibleColumn(wanted[i]))});
  }
  if (truth.markers.empty()) {
    std::string have;
    for (const std::string& c : table.columns) {
      if (c.size() > 2 && c.compare(c.size() - 2, 2, "_x") == 0) {
        have += (have.empty() ? "" : ", ") + c.substr(0, c.size() - 2);
      }
    }
    throw InputError(file + ": no marker of the config has <name>_x and <name>_y columns here (the "
                     "truth has: " + (have.empty() ? std::string("none") : have) + ")");
  }
  // A column the file may lack: its value in `row`, or absent.
  const auto value_of = [&table](std::optional<size_t> column, size_t row) {
    return column ? table.values[*column][row] : std::nullopt;
  };
  const auto time_column = table.find(kTime), bend_column = table.find(kBend);
  const auto radius_column = table.find(kCentrelineRadius);
  std::vector<std::optional<size_t>> measurement_columns;
  for (const MeasurementField& field : kMeasurementFields) {
    measurement_columns.push_back(table.find(field.name));
  }
  std::set<int64_t> frames_seen;
  for (size_t row = 0; row < table.row_count(); ++row) {
    const std::optional<double>& frame = table.values[*frame_column][row];
    if (!frame || *frame < 0 || *frame != std::floor(*frame)) {
      throw InputError(LineOf(file, row) + "'frame' must be a frame index (0, 1, 2, ...)");
    }
    SceneTruth t;
    t.frame_index = static_cast<int64_t>(*frame);
    if (!frames_seen.insert(t.frame_index).second) {
      throw InputError(LineOf(file, row) + "frame " + std::to_string(t.frame_index) +
                       " is given twice");
    }
    t.time_s = value_of(time_column, row).value_or(0.0);
    t.bend_deg = value_of(bend_column, row).value_or(0.0);
    t.centreline_radius_px = value_of(radius_column, row);
    for (size_t k = 0; k < columns.size(); ++k) {
      MarkerTruth m;
      m.name = truth.markers[k];
      const auto& x = table.values[columns[k].x][row];
      const auto& y = table.values[columns[k].y][row];
      if (x && y) m.centroid_px = cv::Point2d(*x, *y);
      m.visible_fraction = m.centroid_px ? 1.0 : 0.0;
      if (const auto v = value_of(columns[k].visible, row)) {
        if (*v < 0 || *v > 1) {
          throw InputError(LineOf(file, row) + m.name + "_visible must lie within 0..1");
        }
        // A marker without a position is hidden, whatever the column says.
        if (m.centroid_px) m.visible_fraction = *v;
      }
      t.markers.push_back(m);
    }
    for (size_t f = 0; f < std::size(kMeasurementFields); ++f) {
      t.measurement.*kMeasurementFields[f].member = value_of(measurement_columns[f], row);
    }
    truth.frames.push_back(std::move(t));
  }
  if (truth.frames.empty()) throw InputError(file + ": no rows");
  return truth;
}

}  // namespace softsight
