// The YAML configuration of a tracking run. Everything a person can do with the mouse (select a
// template, calibrate a colour) can be written here, so batch runs reproduce live ones exactly.
// examples/markers.yaml documents every key.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "softsight/calib/camera_calibration.h"
#include "softsight/io/camera_settings.h"
#include "softsight/io/output_guard.h"
#include "softsight/control/control_config.h"
#include "softsight/geometry/measurement.h"
#include "softsight/track/tracker.h"

namespace YAML {
class Node;
}

namespace softsight {

// Where frame 0 of the input sits in the source it was cut from: a live recording's raw video
// starts at a later source frame, and its saved config (the `recording:` key) says which, so
// `softsight track` on it numbers and times rows as the live CSV did (frame + first_frame,
// time_s + first_time_s).
struct RecordingOrigin {
  int64_t first_frame = 0;    // Source frame index of the input's frame 0.
  double first_time_s = 0.0;  // Source timestamp of the input's frame 0, seconds.
};

// One edit the live window made while a recording ran (a marker reselected or respecified, a
// paused frame tracked again, the bending-distance reference reset), kept with the recording's
// config so that re-tracking its raw video makes the same edit at the same place: after the row
// of frame `after_frame` (the raw video's own index, from 0), as the window made it after
// showing that frame. Written by live recordings only (the `changes:` key); the session applies
// them in order.
struct ConfigChange {
  enum class Kind { kRespec, kReselect, kRetrack, kResetTipReference };
  Kind kind = Kind::kRespec;
  int64_t after_frame = 0;
  MarkerSpec spec{};     // kRespec: the marker's new spec (spec.name says which marker).
  std::string marker{};  // kReselect, kRetrack: which marker.
  cv::Rect rect{};       // kReselect: where the marker is on frame `after_frame`.
  // kRespec: the image file of spec's template (as TrackingConfig::template_files), "" if none.
  std::string template_file{};

  static ConfigChange Respec(const MarkerSpec& spec) {
    return {Kind::kRespec, 0, spec, spec.name, {}, {}};
  }
  static ConfigChange Reselect(const std::string& marker, const cv::Rect& rect) {
    return {Kind::kReselect, 0, {}, marker, rect, {}};
  }
  static ConfigChange Retrack(const std::string& marker) {
    return {Kind::kRetrack, 0, {}, marker, {}, {}};
  }
  static ConfigChange ResetTipReference() { return {Kind::kResetTipReference, 0, {}, {}, {}, {}}; }
};

struct TrackingConfig {
  std::vector<MarkerSpec> markers{};
  // Marker name -> the image file its template was read from (`template.file`, as written:
  // relative to the config file), so that a saved config names it again. The pixels themselves
  // are the marker's TemplateParams::image; a template selected anew has no file until a saver
  // (the live window's `s`) writes one.
  std::map<std::string, std::string> template_files{};
  // Marker name -> its parameters of the kinds other than its own whose keys the file gives (a
  // template marker's colour keys: HSV ranges picked in the live window while it matched
  // templates), which a switch of method (`m` in live, `--method colour`) uses. At most one per
  // kind; a marker whose file gives no other kind's keys has none.
  std::map<std::string, std::vector<MarkerParams>> params_aside{};
  MeasureOptions measure{};            // Triple, chain, tip reference, metric model.
  // Lens model from `softsight calibrate` (the `camera:` key, relative to the config file).
  // Trackers work on the frames as recorded; measurements use undistorted marker positions.
  std::optional<std::string> camera_file{};
  std::optional<CameraIntrinsics> camera{};
  // The `control:` section (gains, limits, rig), when the file has one: `softsight control`.
  std::optional<ControlConfig> control{};
  std::optional<RecordingOrigin> recording{};  // Written by live recordings only.
  std::vector<ConfigChange> changes{};         // Likewise: edits made while recording, in order.
  // The `capture:` section: the camera's resolution, rate, pixel format, exposure, gain, white
  // balance and focus (softsight/io/camera_settings.h). (`camera:` names the lens calibration.)
  // A live recording saves what the camera accepted.
  std::optional<CameraSettings> capture{};
  std::string source_file{};           // Where this config was read from ("" if built in code).
  // Every file reading this config opened: the config itself, then the camera, plane and
  // template image files it names (resolved), so no output may overwrite one of them.
  std::vector<std::string> files_read{};
};

// The files a run of `config` reads, as inputs for CheckOutputsAreNotInputs: the config itself
// ("the config") and every file it names ("a file the config names:").
std::vector<PathRole> ConfigInputs(const TrackingConfig& config);

// Reads and checks a config file. `method_override` (from --method) replaces every marker's
// method. Throws InputError naming file, line and key.
TrackingConfig LoadTrackingConfig(const std::string& file,
                                  const std::optional<std::string>& method_override = {});

// The same from a YAML document already in memory (e.g. built from a Python dict): the same keys,
// checks and messages, with `file` standing for the file name in them ("file:line: key: ..."; a
// node built in code has no lines: "file: key: ..."), and relative paths (camera, template and
// plane files) resolved beside `file` (from the working directory when it names no folder).
TrackingConfig ReadTrackingConfig(const YAML::Node& root, const std::string& file,
                                  const std::optional<std::string>& method_override = {});

// Writes `config` back as YAML that LoadTrackingConfig reads to the same values.
void SaveTrackingConfig(const TrackingConfig& config, const std::string& file);

}  // namespace softsight
