// The option tables of the measurement settings (softsight/core/option_table.h): the config's top-level
// triple, chain, tip_reference and metric keys, with their units, ranges and docs.
// MeasureOptions::Check() and MetricModel::Check() run them; the config reader and writer iterate
// them. (Whether the named markers exist is the config's business.)
#pragma once

#include "softsight/core/option_table.h"
#include "softsight/geometry/measurement.h"

namespace softsight {

// scale_mm_per_px, plane_mm_from_image. The metric keys read from other files or derived
// (plane: a file; scale_from_points: the points a scale came from) are the config reader's.
const OptionTable<MetricModel>& MetricModelOptions();

// triple, chain, tip_reference, and MetricModelOptions() at the same level.
const OptionTable<MeasureOptions>& MeasureOptionsTable();

}  // namespace softsight
