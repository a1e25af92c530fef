// Readers and writers of the config's sections, one pair per module that owns the settings.
// Each Read function consumes its keys from `map` (so YamlMap::finish() can reject unknown keys)
// and throws InputError naming file, line and key. Each Write function emits the same keys.
#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>

#include "core/option_table.h"
#include "config/yaml_map.h"
#include "softsight/control/control_config.h"
#include "softsight/geometry/measurement.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"
#include "softsight/track/tracker.h"

namespace softsight {

// colour_config.cc: a marker's colour keys (hsv, auto_colour, filter, morphology, blob, roi, ...).
void ReadColourParams(YamlMap& marker, ColourParams* params);
void WriteColourParams(const ColourParams& params, YAML::Emitter& out);

// template_config.cc: a marker's `template:` key and matching options, and the image file the
// template may come from (`template.file`): the file is the config's business, not the
// tracker's, so it is kept here beside the parameters (its pixels go into params.image).
struct TemplateSection {
  TemplateParams params;
  std::string file;  // `template.file` as written, relative to the config file; "" when none.
};
// TemplateParams' option table (track/track_options.h) plus template.file.
const OptionTable<TemplateSection>& TemplateSectionOptions();
// Reads the keys into `section`; a newly named file is read into section->params.image.
void ReadTemplateParams(YamlMap& marker, TemplateSection* section);
void WriteTemplateParams(const TemplateSection& section, YAML::Emitter& out);

// config.cc: one entry of `markers:`: its name, method (`method_override` replaces it) and that
// method's keys (the other method's keys are read and checked too: a marker is one method's
// parameters). `template_file` gets the marker's template.file ("" when none); `colour_aside`
// (may be null), for a template marker, its colour keys (kept for the colour method).
MarkerSpec ReadMarker(YamlMap& marker, const std::optional<std::string>& method_override,
                      std::string* template_file, std::optional<ColourParams>* colour_aside = nullptr);
// The same keys back: name, method, and the keys of the marker's parameters that differ from the
// defaults (`template_file` as template.file for a template marker; `colour_aside`, when given
// for a template marker, as its colour keys).
void WriteMarker(const MarkerSpec& spec, const std::string& template_file, YAML::Emitter& out,
                 const ColourParams* colour_aside = nullptr);

// metric_config.cc: top-level scale_mm_per_px / plane keys.
void ReadMetricModel(YamlMap& top, MetricModel* metric);
void WriteMetricModel(const MetricModel& metric, YAML::Emitter& out);

// metric_config.cc too: the top-level measurement keys (triple, chain, tip_reference) and the
// metric keys. Whether the named markers exist is checked by the caller, who knows them.
void ReadMeasureOptions(YamlMap& top, MeasureOptions* measure);
void WriteMeasureOptions(const MeasureOptions& measure, YAML::Emitter& out);
// MeasureOptions::Check() for what a file may give: no triple is allowed (a config that only
// tracks); the session refuses it if it needs the measurements.
bool CheckMeasureOptionsOfAFile(const MeasureOptions& measure, std::string* error);

// control_config.cc: the `control:` section (examples/rig.yaml documents every key). Read consumes
// the keys of the `control:` mapping into `config` (defaults stay where a key is absent), finishes
// the mapping (unknown keys are errors) and checks the result; Write emits the keys that differ
// from the defaults.
void ReadControlConfig(YamlMap& control, ControlConfig* config);
void WriteControlConfig(const ControlConfig& config, YAML::Emitter& out);

// config.cc: every key a tracking config can have, as commented YAML generated from the option
// tables (`softsight config --doc`): each with its default, unit, range and one-line doc. It is a
// valid config itself, reading back to the defaults.
std::string DocumentConfig();

}  // namespace softsight
