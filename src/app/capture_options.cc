#include "app/capture_options.h"

#include <cerrno>
#include <cstdlib>
#include <iostream>

#include "io/camera_options.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

std::string FlagOf(const std::string& key) {
  std::string flag = "--camera-" + key;
  for (char& c : flag) {
    if (c == '_') c = '-';
  }
  return flag;
}

}  // namespace

CLI::Validator CameraIdCheck() {
  return CLI::Validator(
      [](std::string& text) { return CameraIdProblem(text).value_or(std::string()); }, "");
}

std::string CameraHelp(const std::string& what) {
  return what + ": a V4L2 index (0: /dev/video0), or aravis: for the first GenICam camera (GigE "
                "Vision, USB3 Vision) and aravis:DEVICE-ID for a named one (`softsight cameras` "
                "lists them; aravis:Fake_1 is Aravis' simulated camera)";
}

const FlagTable<CaptureArgs>& CaptureFlags() {
  static const FlagTable<CaptureArgs> table = [] {
    FlagTable<CaptureArgs> flags;
    for (const Option<CameraSettings>& option : CameraSettingsTable()) {
      // Read as text and checked by MergeCaptureOptions (one message for the flag and the
      // config key alike); the help names the kind of value.
      const char* type_name = option.kind == OptionKind::kInt      ? "INT"
                              : option.kind == OptionKind::kDouble ? "FLOAT"
                                                                   : "TEXT";
      const std::string key = option.key;
      // The map's nodes stay where they are: the flag writes into its own entry.
      auto text = [key](CaptureArgs& args) -> std::string& { return args[key]; };
      flags.push_back(ValueFlag<CaptureArgs>(FlagOf(key), text)
                          .Help(ConfigKeyHelp(option, "capture." + key))
                          .TypeName(type_name)
                          .Group("Camera settings (when the frames come from a camera)"));
    }
    return flags;
  }();
  return table;
}

CameraSettings MergeCaptureOptions(const CaptureArgs& args, CameraSettings settings) {
  for (const Option<CameraSettings>& option : CameraSettingsTable()) {
    const auto it = args.find(option.key);
    if (it == args.end() || it->second.empty()) continue;
    const std::string& text = it->second;
    const std::string flag = FlagOf(option.key);
    OptionValue value;
    char* end = nullptr;
    errno = 0;
    if (option.kind == OptionKind::kInt) {
      const long long number = std::strtoll(text.c_str(), &end, 10);
      if (end == text.c_str() || *end != '\0' || errno != 0) {
        throw InputError(flag + " " + text + ": not a whole number");
      }
      value = static_cast<int64_t>(number);
    } else if (option.kind == OptionKind::kDouble) {
      const double number = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || errno != 0) {
        throw InputError(flag + " " + text + ": not a number");
      }
      value = number;
    } else {
      value = text;
    }
    if (const std::optional<std::string> problem = OptionProblem(option, value)) {
      throw InputError(flag + " " + text + ": " + *problem);
    }
    option.set(settings, value);
  }
  return settings;
}

void RefuseCaptureWithoutCamera(const CaptureArgs& args,
                                const std::optional<CameraSettings>& config,
                                const std::string& config_path, const std::string& source,
                                std::ostream& notes) {
  for (const Option<CameraSettings>& option : CameraSettingsTable()) {
    const auto it = args.find(option.key);
    if (it != args.end() && !it->second.empty()) {
      throw InputError(FlagOf(option.key) + " " + it->second + ": camera settings apply to a " +
                       "camera (--camera N), and the frames come from " + source);
    }
  }
  if (config && !config->empty()) {
    notes << "note: " << config_path << ": its capture: settings are for a camera and are not "
          << "used with " << source << "\n";
  }
}

void PrintCaptureReport(const CameraSettingsReport& report) {
  std::cerr << report.summary << "\n";
  for (const std::string& line : report.refused) std::cerr << line << "\n";
}

std::unique_ptr<FrameSource> OpenLiveSource(std::optional<CameraId> camera, const std::string& input,
                                            const CaptureArgs& capture_args,
                                            const std::string& config_path,
                                            TrackingConfig& config, FrameSourceSpec* spec) {
  const CameraSettings capture =
      MergeCaptureOptions(capture_args, config.capture.value_or(CameraSettings{}));
  if (!camera && input.empty() && capture.device) camera = CameraId(*capture.device);
  if (camera.has_value() == !input.empty()) {
    throw InputError("give exactly one of --camera N or --input VIDEO (or capture.device in " +
                     config_path + ")");
  }
  if (!camera) {
    RefuseCaptureWithoutCamera(capture_args, config.capture, config_path, "the file " + input,
                               std::cerr);
  }
  spec->camera = camera;
  spec->input = input;
  spec->capture = capture;
  CameraSettingsReport accepted;
  spec->capture_report = &accepted;
  std::unique_ptr<FrameSource> source = OpenFrameSource(*spec);
  spec->capture_report = nullptr;  // The reopener (files) needs none.
  if (camera) {
    // What the camera accepted is printed, and saved with every recording's config (and by `s`).
    PrintCaptureReport(accepted);
    if (!capture.empty()) {
      config.capture = accepted.accepted;
      // capture.device holds a V4L2 index; an Aravis camera is named on the command line.
      config.capture->device.reset();
      if (!camera->aravis_device) config.capture->device = camera->index;
    }
  }
  return source;
}

}  // namespace softsight
