// The ground-truth CSV: what `softsight synth --truth` writes beside a rendered video and
// `softsight evaluate --truth` (or any program) reads back, one row per frame. Writer and reader
// take every column name from one table (truth_csv.cc), so they cannot disagree:
//   frame, time_s, bend_deg, per marker <name>_x, <name>_y, <name>_visible,
//   angle_deg, chord_px, sagitta_px, radius_px, arc_length_px, tip_disp_px, centreline_radius_px
// A hidden marker has empty x and y; a value that cannot be computed is an empty field.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "softsight/io/csv_columns.h"
#include "softsight/io/csv_writer.h"
#include "softsight/sim/scene.h"

namespace softsight {

// The columns for these markers (SceneTruth::markers order). Numbers have 6 decimals.
BasicCsvColumnTable<SceneTruth> TruthColumns(const std::vector<std::string>& marker_names);

// Writes a truth CSV through the output guard (a file another program writes is refused).
using TruthCsvWriter = BasicCsvWriter<SceneTruth>;

// A truth CSV read back for some markers.
struct TruthCsv {
  std::vector<std::string> markers{};  // The wanted markers the file has <name>_x, <name>_y for.
  std::vector<size_t> wanted_index{};  // Each one's index in `wanted`.
  std::vector<std::string> missing{};  // The wanted markers it has no such columns for.
  // In file order; each frame's markers are `markers`, in that order. A marker without a
  // `_visible` column is wholly visible where it has a position; columns the file lacks are
  // absent (time_s and bend_deg: 0).
  std::vector<SceneTruth> frames{};
};

// Reads `file` for the markers `wanted`. Throws InputError naming the file (and line) when it
// cannot be read (csv_reader.h), has no `frame` column, none of the wanted markers, no rows, a
// frame that is not a frame index or is given twice, or a visible fraction outside 0..1.
TruthCsv ReadTruthCsv(const std::string& file, const std::vector<std::string>& wanted);

}  // namespace softsight
