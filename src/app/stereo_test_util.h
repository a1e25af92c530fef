// What the two-camera tests of the program share (test code only): the renderer's markers as a
// config for two cameras, and a CSV's rows by column name.
#pragma once

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "app/scene_markers_test_util.h"

namespace softsight::testing {

// The scene's markers (or those of `yaml`) as a config for two cameras: without the rim fit
// (the markers move in depth, so each view sees them change size; colour_tracker.h).
inline std::string StereoMarkersYaml(std::string yaml = kSceneMarkersYaml) {
  for (size_t at = yaml.find("    hsv:"); at != std::string::npos; at = yaml.find("    hsv:", at)) {
    at = yaml.find('\n', at) + 1;
    yaml.insert(at, "    rim_fit: false\n");
  }
  return yaml;
}

// Each row's fields by column name (status columns are words).
inline std::vector<std::map<std::string, std::string>> ReadRows(const std::string& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  for (std::stringstream s(line); std::getline(s, line, ',');) header.push_back(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::map<std::string, std::string> row;
    std::stringstream s(line);
    for (const std::string& name : header) {
      std::string field;
      std::getline(s, field, ',');
      row[name] = field;
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace softsight::testing
