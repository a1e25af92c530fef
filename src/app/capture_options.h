// The camera on the command line: --camera N|aravis:ID (CameraFlag), and its capture settings
// as flags of live, serve, track and control, made from the settings' option table
// (io/camera_options.h), so each setting is described once:
// --camera-width, --camera-height, --camera-fps, --camera-pixel-format, --camera-exposure,
// --camera-gain, --camera-white-balance, --camera-focus (and --camera-device).
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include <CLI/CLI.hpp>

#include "app/flag_table.h"
#include "softsight/config/config.h"
#include "softsight/io/camera_settings.h"
#include "softsight/io/frame_source.h"

namespace softsight {

// The texts given on the command line, by table key.
using CaptureArgs = std::map<std::string, std::string>;

// A camera option's check: a V4L2 index or aravis:[DEVICE-ID] (softsight/io/camera_settings.h),
// checked as it is parsed, so a wrong one is one line naming the option.
CLI::Validator CameraIdCheck();
// A camera option's help: `what` the camera is for, then the syntax.
std::string CameraHelp(const std::string& what);

// A camera flag (`--camera`, `--left-camera`) setting a std::optional<CameraId> field.
template <typename Args, typename Access>
FlagBuilder<Args> CameraFlag(const std::string& name, Access access, const std::string& what) {
  return ValueFlag<Args>(name, access)
      .Help(CameraHelp(what))
      .TypeName("N|aravis:ID")
      .Check(CameraIdCheck());
}

// One flag per row of the camera settings' table (--camera-width ...), its help and range from
// the row; the texts given land in a CaptureArgs, which must outlive parsing.
const FlagTable<CaptureArgs>& CaptureFlags();

// The config's settings with the command line's on top. Throws InputError naming the option
// ("--camera-width 5: must lie within 16..8192").
CameraSettings MergeCaptureOptions(const CaptureArgs& args, CameraSettings settings);

// Capture settings apply to a camera only. With frames from elsewhere (`source`: "the file
// run.avi", "the simulated rig"), a --camera-* option on the command line is refused (it asked
// for what cannot happen: InputError naming the option), and a config's `capture:` section (a
// live recording saves one) is said on `notes` to be left unused.
void RefuseCaptureWithoutCamera(const CaptureArgs& args,
                                const std::optional<CameraSettings>& config,
                                const std::string& config_path, const std::string& source,
                                std::ostream& notes);

// What the camera accepted, on stderr: the summary line, then one line per refused setting.
void PrintCaptureReport(const CameraSettingsReport& report);

// The frame source of a live front end (`live`, `serve`): exactly one of `camera` (or the
// config's capture.device) and `input`. The camera's settings are the config's `capture:`
// section with the --camera-* options on top; what it accepted is printed and written back into
// `config` (so every recording's config and a saved one hold it). Frames from a file refuse
// --camera-* options. `spec` gets what opened the source (a file reopens from it). Throws
// InputError naming the option, the config or the input.
std::unique_ptr<FrameSource> OpenLiveSource(std::optional<CameraId> camera, const std::string& input,
                                            const CaptureArgs& capture_args,
                                            const std::string& config_path,
                                            TrackingConfig& config, FrameSourceSpec* spec);

}  // namespace softsight
