// Camera capture settings (the config's `capture:` section and the --camera-* options of live,
// track and control): resolution, frame rate, pixel format, and exposure, gain, white balance
// and focus with their automatic modes off, so that HSV thresholds see the same colours all
// session. Applied through OpenCV's capture properties (V4L2), read back, and reported: what the
// camera accepted, and one line per property it refused naming the value it kept.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace softsight {

struct CameraSettings {
  enum class PixelFormat { kAny, kMjpg, kYuyv };
  std::optional<int> device = std::nullopt;  // V4L2 index (/dev/videoN) when --camera is not given.
  std::optional<int> width = std::nullopt, height = std::nullopt;  // px
  std::optional<double> fps = std::nullopt;
  PixelFormat pixel_format = PixelFormat::kAny;
  // Given: the automatic mode is switched off and this value set (driver units).
  std::optional<double> exposure = std::nullopt, gain = std::nullopt,
                        white_balance_k = std::nullopt, focus = std::nullopt;

  // "key: problem" for the first value out of range (the option table's message).
  bool Check(std::string* error) const;
  // True when nothing is set: the camera keeps its own settings.
  bool empty() const;
  bool operator==(const CameraSettings&) const = default;
};

// Where settings go: a capture device's properties (cv::VideoCapture in use, a fake in tests).
class CaptureBackend {
 public:
  virtual ~CaptureBackend() = default;
  // OpenCV's property ids (cv::CAP_PROP_*). set() false: the driver refused outright.
  virtual bool set(int property, double value) = 0;
  virtual double get(int property) const = 0;
};

struct CameraSettingsReport {
  CameraSettings accepted{};           // What the camera has after applying (read back).
  std::vector<std::string> refused{};  // One line each: "camera 0: exposure 120 refused, kept 156".
  std::string summary{};               // One line: "camera 0: 1280x720 30 fps MJPG exposure 120".
};

// Applies every setting given (pixel format first, then size, rate, and each manual value after
// switching its automatic mode off), then reads all of them back.
CameraSettingsReport ApplyCameraSettings(CaptureBackend& backend, const CameraSettings& settings,
                                         const std::string& camera_name);

// The V4L2 capture devices (/dev/video*) with the pixel formats, sizes and frame rates each
// offers, as lines for `softsight cameras`; empty when there are none.
std::vector<std::string> ListCameras();

}  // namespace softsight
