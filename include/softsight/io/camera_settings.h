// Camera capture settings (the config's `capture:` section and the --camera-* options of live,
// track and control): resolution, frame rate, pixel format, and exposure, gain, white balance
// and focus with their automatic modes off, so that HSV thresholds see the same colours all
// session. Applied through OpenCV's capture properties (V4L2) or GenICam's features (Aravis),
// read back, and reported: what the camera accepted, and one line per property it refused naming
// the value it kept.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace softsight {

// Which camera: a V4L2 index (`--camera 0`: /dev/video0), or a GenICam camera (GigE Vision,
// USB3 Vision) through Aravis: `--camera aravis:` for the first one found, `--camera
// aravis:DEVICE-ID` for a named one (the ids `softsight cameras` lists; `aravis:Fake_1` is
// Aravis' simulated camera, in the process, no network).
struct CameraId {
  CameraId() = default;
  CameraId(int v4l2_index) : index(v4l2_index) {}  // NOLINT: implicit, `.camera = 0` reads well.
  // "0".."63", "aravis:" or "aravis:DEVICE-ID"; throws InputError naming the text otherwise.
  explicit CameraId(const std::string& text);

  int index = 0;                                 // V4L2: /dev/videoN (when not Aravis).
  std::optional<std::string> aravis_device = {};  // Given: an Aravis camera ("": the first one).

  // As written on the command line: "0", "aravis:Fake_1".
  std::string text() const;
  bool operator==(const CameraId&) const = default;
};

// Why `text` names no camera ("--camera" names it in the message's caller), or nullopt.
std::optional<std::string> CameraIdProblem(const std::string& text);

struct CameraSettings {
  // MJPG and YUYV: V4L2 cameras; Mono8, RGB8, Bayer8 (whichever 8-bit Bayer layout the sensor
  // has): GenICam cameras through Aravis. Every one arrives as BGR.
  enum class PixelFormat { kAny, kMjpg, kYuyv, kMono8, kRgb8, kBayer8 };
  std::optional<int> device = std::nullopt;  // V4L2 index (/dev/videoN) when --camera is not given.
  std::optional<int> width = std::nullopt, height = std::nullopt;  // px
  std::optional<double> fps = std::nullopt;
  PixelFormat pixel_format = PixelFormat::kAny;
  // Given: the automatic mode is switched off and this value set (driver units).
  std::optional<double> exposure = std::nullopt, gain = std::nullopt,
                        white_balance_k = std::nullopt, focus = std::nullopt;
  // GenICam cameras (Aravis): "" leaves the camera's trigger as it is; "off" runs it free
  // (frames at `fps`); any other word is the TriggerSource that starts each frame ("Line0",
  // "Line1": a hardware trigger; "Software": softsight triggers each frame as it reads one).
  std::string trigger = {};

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

// The GenICam cameras Aravis finds (USB3 Vision, and GigE Vision by a discovery broadcast on
// every network interface), one line each naming its --camera aravis:ID; empty when there are
// none. Throws InputError when this build has no Aravis support.
std::vector<std::string> ListAravisCameras();

// Whether this build opens GenICam cameras through Aravis (`--camera aravis:...`).
bool HaveAravisSupport();

}  // namespace softsight
