// `softsight init` and `softsight pick`: a marker config without a GUI.
//   init: finds the markers in one frame by itself (track/marker_finder.h), verifies and orders
//         them, writes the config and a picture of what it found and rejected.
//   pick: the live window's click pick (PickMarkerColourAt) at given points of one frame.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "softsight/config/config.h"
#include "softsight/core/types.h"
#include "softsight/io/frame_source.h"
#include "softsight/track/marker_finder.h"

namespace softsight {

// The frame at position `position` of the source (0 = the first frame read, whatever its
// number). Throws InputError naming the input when it cannot be opened or is shorter.
Frame ReadFrameAt(const FrameSourceSpec& source, int64_t position);

// "X,Y" -> a point; "X,Y,W,H" -> a rectangle. Throw InputError naming `option`.
cv::Point2d ParsePointOption(const std::string& text, const std::string& option);
cv::Rect ParseRectOption(const std::string& text, const std::string& option);

struct InitOptions {
  FrameSourceSpec source;
  int64_t frame = 0;                 // Position of the analysed frame in the input.
  std::string config_out = "init.yaml";
  std::optional<std::string> picture_out;  // Default: the config's name with .png.
  MarkerFinderOptions finder;        // frame_index is set from `frame` (rois apply from it).
};

struct InitResult {
  MarkerFinding finding;
  TrackingConfig config;             // What was written (when finding.ok()).
  std::string picture_file;
};

// Finds the markers, writes the picture always and the config only when the finding is usable;
// throws InputError (after writing the picture) with the finding's problem otherwise.
InitResult RunInit(const InitOptions& options);

struct PickOptions {
  FrameSourceSpec source;
  int64_t frame = 0;
  std::vector<cv::Point2d> at_px;            // One point per marker, base first.
  std::optional<std::string> base_config;    // Markers to update, in order; else new markers.
  std::string config_out = "pick.yaml";
};

// The config `pick` writes: each point's colour as live's click gives it (same function, same
// defaults), into the base config's markers in order or into new markers named by their hue
// (a triple for three points, a chain for more, in the order given). Throws InputError.
TrackingConfig RunPick(const PickOptions& options);

}  // namespace softsight
