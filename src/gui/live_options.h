// The settings of the live window (`softsight live`, RunLiveWindow in live_window.h): where it
// saves and records, how the mouse selects, the strip chart, the colour picker and the overlay.
// Plain option structs with defaults and a Check() that names the bad field.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "gui/overlay.h"
#include "softsight/io/csv_columns.h"
#include "softsight/pipeline/sink.h"
#include "softsight/track/hsv_picker.h"

namespace softsight {

// The scrolling strip chart under the live image (the live window: angle, bending distance, arc
// length and radius; the stereo window: the 3D and each camera's angle, the out-of-plane angle).
struct StripChartOptions {
  double window_s = 10.0;  // Time span shown, seconds. Longer shows slower trends, less detail.
  int height_px = 220;     // Height of the whole chart (all its lanes) under the image.
  bool Check(std::string* error) const;
};

struct LiveOptions {
  // Where `s` writes the config. Default: empty, which makes the command choose
  // <config stem>.live.yaml beside the loaded config.
  std::string save_config_path;
  // Recordings go to <prefix>-NNN.csv, .avi (annotated), .raw.avi (frames as captured, for
  // `softsight track`) and .yaml (the config reproducing the run on the raw video).
  std::string record_prefix = "live";
  // Side of the box cut around a marker when it needs a new template (method switch, start of a
  // recording), px. Default 32: a 10-20 px marker plus context.
  int select_box_px = 32;
  // Frame rate written into recorded videos, frames per second: the source's nominal rate when
  // known (absent: the measured processing rate). The CSV's time_s is always the source's.
  std::optional<double> record_fps;
  // A press and release closer than this is a click (colour pick), farther a drag (reselect), px.
  int click_slop_px = 4;
  // The true distance between the two points clicked in scale mode (`c`), e.g. the ends of a
  // ruler lying in the actuator's plane, mm. Absent (default): `c` only says how to set it.
  std::optional<double> scale_distance_mm;
  StripChartOptions chart;
  HsvPickOptions picker;
  OverlayOptions overlay;  // base/middle/tip filled from the config by the window.
  // Sinks of the program that see every frame the window tracks (`live --publish`: the stream),
  // in the window's run (PipelineRun) from its first frame. Not owned; the caller ends them when
  // RunLiveWindow returns, with its summary.
  std::vector<FrameSink*> sinks;
  // Columns a recording's CSV has after the tracking ones (`--hook`: the hook's, whose sink is
  // first in `sinks`), the same for every recording.
  std::vector<CsvColumn> extra_columns;

  bool Check(std::string* error) const;
};

}  // namespace softsight
