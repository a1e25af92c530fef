// The YAML configuration of a tracking run. Everything a person can do with the mouse (select a
// template, calibrate a colour) can be written here, so batch runs reproduce live ones exactly.
// examples/markers.yaml documents every key.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "softsight/geometry/measurement.h"
#include "softsight/track/tracker.h"

namespace softsight {

struct TrackingConfig {
  std::vector<MarkerSpec> markers;
  MeasureOptions measure;              // Triple, chain, tip reference, metric model.
  std::optional<std::string> camera_file;  // Intrinsics + distortion (softsight calibrate).
  std::string source_file;             // Where this config was read from ("" if built in code).
};

// Reads and checks a config file. `method_override` (from --method) replaces every marker's
// method. Throws InputError naming file, line and key.
TrackingConfig LoadTrackingConfig(const std::string& file,
                                  const std::optional<std::string>& method_override = {});

// Writes `config` back as YAML that LoadTrackingConfig reads to the same values.
void SaveTrackingConfig(const TrackingConfig& config, const std::string& file);

}  // namespace softsight
