// Readers and writers of the config's sections, one pair per module that owns the settings.
// Each Read function consumes its keys from `map` (so YamlMap::finish() can reject unknown keys)
// and throws InputError naming file, line and key. Each Write function emits the same keys.
#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

#include "config/yaml_map.h"
#include "softsight/control/control_config.h"
#include "softsight/core/option_table.h"
#include "softsight/geometry/measurement.h"
#include "softsight/track/tracker.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {

// marker_config.cc: a marker's keys of one kind (softsight/track/tracker_kind.h): the kind's option rows and,
// for a kind that holds an image, the key naming the image file. The file is the config's
// business, not the tracker's, so its name is kept here beside the parameters (its pixels go
// into the parameters).
struct KindSection {
  MarkerParams params;     // Of the kind whose keys these are.
  std::string image_file;  // The image file key's value as written (relative to the config file).
};
// The kind's option rows plus its image file key (a table per kind, made once).
const OptionTable<KindSection>& KindSectionOptions(const TrackerKind& kind);
// Reads the keys of section->params' kind from `marker` into `section` and checks them; a newly
// named image file is read into the parameters. Throws InputError naming file, line and key.
void ReadKindParams(YamlMap& marker, KindSection* section);
// The keys of `section` that differ from its kind's defaults.
void WriteKindParams(const KindSection& section, YAML::Emitter& out);
// Every key of `kind` as commented YAML with its default, unit and range (`config --doc`).
std::string DescribeKindKeys(const TrackerKind& kind, int indent);

// config.cc: one entry of `markers:`: its name, method (`method_override` replaces it) and the
// keys of every kind (all are read and checked: a typo or a bad value in any is an error); the
// marker is the method's kind's parameters. `image_file` gets its kind's image file key ("" when
// none); `aside` (may be null), its parameters of the other kinds whose keys the entry gives
// (a template marker's colour keys, kept for a switch to the colour method).
MarkerSpec ReadMarker(YamlMap& marker, const std::optional<std::string>& method_override,
                      std::string* image_file, std::vector<MarkerParams>* aside = nullptr);
// The same keys back: name, method, the keys of the marker's parameters (and of `aside`, when
// given) that differ from the defaults, with `image_file` as its kind's image file key.
void WriteMarker(const MarkerSpec& spec, const std::string& image_file, YAML::Emitter& out,
                 const std::vector<MarkerParams>* aside = nullptr);

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
