// The option tables of the trackers' settings (softsight/core/option_table.h): every key a marker's colour
// and template settings can have, with its unit, range and doc. ColourParams::Check() and
// TemplateParams::Check() run them; the config reader and writer (config) iterate them.
#pragma once

#include "softsight/core/option_table.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"

namespace softsight {

// Keys relative to the marker: hsv.h, filter.type, blob.min_area, roi, window, ...
const OptionTable<ColourParams>& ColourParamsOptions();

// Keys relative to the marker, all under template.: template.rect, template.min_zncc, ...
// (The match measure is the marker's method, not an option here.)
const OptionTable<TemplateParams>& TemplateParamsOptions();

}  // namespace softsight
