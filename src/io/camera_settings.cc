#include "softsight/core/format.h"
#include "softsight/io/camera_settings.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/videoio.hpp>

#include "io/camera_options.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr char kAravisPrefix[] = "aravis:";

using PixelFormat = CameraSettings::PixelFormat;

OptionTable<CameraSettings> MakeTable() {
  using P = CameraSettings;
  return {
      CustomOption<P>(
          "device", OptionKind::kInt,
          [](const P& p) -> std::optional<OptionValue> {
            if (!p.device) return std::nullopt;
            return OptionValue(static_cast<int64_t>(*p.device));
          },
          [](P& p, const std::optional<OptionValue>& v) {
            if (v) {
              p.device = static_cast<int>(std::get<int64_t>(*v));
            } else {
              p.device.reset();
            }
          },
          true)
          .Range(0, 63)
          .Doc("V4L2 camera index (/dev/videoN), used when --camera is not given"),
      CustomOption<P>(
          "width", OptionKind::kInt,
          [](const P& p) -> std::optional<OptionValue> {
            if (!p.width) return std::nullopt;
            return OptionValue(static_cast<int64_t>(*p.width));
          },
          [](P& p, const std::optional<OptionValue>& v) {
            if (v) {
              p.width = static_cast<int>(std::get<int64_t>(*v));
            } else {
              p.width.reset();
            }
          },
          true)
          .Range(16, 8192)
          .Unit("px")
          .Doc("frame width asked of the camera (it may pick the nearest mode it has)"),
      CustomOption<P>(
          "height", OptionKind::kInt,
          [](const P& p) -> std::optional<OptionValue> {
            if (!p.height) return std::nullopt;
            return OptionValue(static_cast<int64_t>(*p.height));
          },
          [](P& p, const std::optional<OptionValue>& v) {
            if (v) {
              p.height = static_cast<int>(std::get<int64_t>(*v));
            } else {
              p.height.reset();
            }
          },
          true)
          .Range(16, 8192)
          .Unit("px")
          .Doc("frame height asked of the camera"),
      DoubleOption<P>("fps", &P::fps)
          .Range(1, 1000)
          .Unit("1/s")
          .Doc("frame rate asked of the camera; MJPG usually allows more at large sizes"),
      EnumOption<P>("pixel_format", &P::pixel_format,
                    std::vector<std::pair<std::string, PixelFormat>>{
                        {"any", PixelFormat::kAny},
                        {"MJPG", PixelFormat::kMjpg},
                        {"YUYV", PixelFormat::kYuyv},
                        {"Mono8", PixelFormat::kMono8},
                        {"RGB8", PixelFormat::kRgb8},
                        {"Bayer8", PixelFormat::kBayer8}})
          .Doc("V4L2: MJPG (compressed: high rates at high resolution) or YUYV (raw, no JPEG "
               "artefacts in the colours); Aravis: Mono8, RGB8 or Bayer8 (the sensor's 8-bit "
               "Bayer layout, demosaiced here); any: the camera's choice (Aravis: a colour one "
               "it has)"),
      DoubleOption<P>("exposure", &P::exposure)
          .Range(-100000, 100000)
          .Doc("manual exposure in the driver's units (V4L2: often 100 us steps; Aravis: "
               "ExposureTime in us); given, auto exposure is off, so the colours do not drift "
               "with the scene"),
      DoubleOption<P>("gain", &P::gain)
          .Range(-100000, 100000)
          .Doc("manual gain in the driver's units (Aravis: Gain, usually dB); given, automatic "
               "gain is off"),
      DoubleOption<P>("white_balance", &P::white_balance_k)
          .Range(1000, 20000)
          .Unit("K")
          .Doc("white balance colour temperature; given, auto white balance is off (it moves "
               "the hues the thresholds depend on)"),
      DoubleOption<P>("focus", &P::focus)
          .Range(-100000, 100000)
          .Doc("manual focus in the driver's units; given, autofocus is off"),
      StringOption<P>("trigger", &P::trigger)
          .Doc("Aravis cameras: off (free running at fps), or the TriggerSource that starts "
               "each frame: Line0, Line1... (a hardware trigger) or Software (each frame "
               "triggered as it is read); not given: the camera's own setting"),
  };
}


std::string FourccText(double fourcc) {
  const auto code = static_cast<uint32_t>(fourcc);
  if (code == 0) return "?";
  std::string text;
  for (int i = 0; i < 4; ++i) text += static_cast<char>((code >> (8 * i)) & 0xFF);
  return text;
}

}  // namespace

const OptionTable<CameraSettings>& CameraSettingsTable() {
  static const OptionTable<CameraSettings> table = MakeTable();
  return table;
}

std::string PixelFormatName(CameraSettings::PixelFormat format) {
  const std::optional<OptionValue> name = [&] {
    CameraSettings settings;
    settings.pixel_format = format;
    for (const Option<CameraSettings>& option : CameraSettingsTable()) {
      if (option.key == "pixel_format") return option.get(settings);
    }
    return std::optional<OptionValue>();
  }();
  return name ? std::get<std::string>(*name) : "?";
}

bool CameraSettings::Check(std::string* error) const {
  if (const auto problem = CheckOptions(CameraSettingsTable(), *this)) return Fail(error, *problem);
  return true;
}

bool CameraSettings::empty() const {
  return !width && !height && !fps && pixel_format == PixelFormat::kAny && !exposure && !gain &&
         !white_balance_k && !focus && trigger.empty();
}

std::optional<std::string> CameraIdProblem(const std::string& text) {
  if (text.rfind(kAravisPrefix, 0) == 0) {
    for (const char c : text) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
        return "'" + text + "': a device id has no control characters";
      }
    }
    return std::nullopt;
  }
  const bool digits = !text.empty() && text.size() <= 2 &&
                      std::all_of(text.begin(), text.end(),
                                  [](char c) { return c >= '0' && c <= '9'; });
  if (digits && std::stoi(text) <= 63) return std::nullopt;
  return "'" + text + "' is no camera: give a V4L2 index (0..63, as `softsight cameras` lists "
         "them), or aravis: (the first GenICam camera) or aravis:DEVICE-ID";
}

CameraId::CameraId(const std::string& text) {
  if (const std::optional<std::string> problem = CameraIdProblem(text)) {
    throw InputError("--camera " + *problem);
  }
  if (text.rfind(kAravisPrefix, 0) == 0) {
    aravis_device = text.substr(std::string(kAravisPrefix).size());
  } else {
    index = std::stoi(text);
  }
}

std::string CameraId::text() const {
  return aravis_device ? kAravisPrefix + *aravis_device : std::to_string(index);
}

CameraSettingsReport ApplyCameraSettings(CaptureBackend& backend, const CameraSettings& settings,
                                         const std::string& camera_name) {
  CameraSettingsReport report;
  report.accepted = settings;
  // Each value asked: set it, read it back; a refusal or a different value read back is one line.
  const auto apply = [&](const char* name, int property, double value,
                         std::optional<double>* accepted, double tolerance) {
    const bool took = backend.set(property, value);
    const double now = backend.get(property);
    if (!took || !(std::abs(now - value) <= tolerance)) {
      report.refused.push_back(camera_name + ": " + name + " " + ShortNumber(value) + " refused, kept " +
                               ShortNumber(now));
    }
    if (accepted) *accepted = now;
  };
  const auto apply_int = [&](const char* name, int property, int value, std::optional<int>* out) {
    std::optional<double> now;
    apply(name, property, value, &now, 0.5);
    *out = static_cast<int>(std::lround(*now));
  };
  // V4L2 switches a mode with these values (OpenCV's V4L2 backend passes them through).
  constexpr double kManualExposure = 1.0, kOff = 0.0;
  const bool genicam_format = settings.pixel_format == PixelFormat::kMono8 ||
                              settings.pixel_format == PixelFormat::kRgb8 ||
                              settings.pixel_format == PixelFormat::kBayer8;
  if (genicam_format) {
    // A GenICam format asked of a V4L2 camera (a config written for an Aravis camera).
    report.refused.push_back(camera_name + ": pixel_format " + PixelFormatName(settings.pixel_format) +
                             " refused (a GenICam format, for aravis: cameras), kept " +
                             FourccText(backend.get(cv::CAP_PROP_FOURCC)));
    report.accepted.pixel_format = PixelFormat::kAny;
  }
  if (!settings.trigger.empty()) {
    report.refused.push_back(camera_name + ": trigger " + settings.trigger +
                             " refused (V4L2 cameras have no trigger; aravis: cameras do)");
    report.accepted.trigger.clear();
  }
  if (settings.pixel_format != PixelFormat::kAny && !genicam_format) {
    const char* code = settings.pixel_format == PixelFormat::kMjpg ? "MJPG" : "YUYV";
    const double fourcc = cv::VideoWriter::fourcc(code[0], code[1], code[2], code[3]);
    const bool took = backend.set(cv::CAP_PROP_FOURCC, fourcc);
    const double now = backend.get(cv::CAP_PROP_FOURCC);
    if (!took || static_cast<uint32_t>(now) != static_cast<uint32_t>(fourcc)) {
      report.refused.push_back(camera_name + ": pixel_format " + code + " refused, kept " +
                               FourccText(now));
      report.accepted.pixel_format = FourccText(now) == "MJPG"   ? PixelFormat::kMjpg
                                     : FourccText(now) == "YUYV" ? PixelFormat::kYuyv
                                                                 : PixelFormat::kAny;
    }
  }
  if (settings.width) apply_int("width", cv::CAP_PROP_FRAME_WIDTH, *settings.width, &report.accepted.width);
  if (settings.height) apply_int("height", cv::CAP_PROP_FRAME_HEIGHT, *settings.height, &report.accepted.height);
  if (settings.fps) apply("fps", cv::CAP_PROP_FPS, *settings.fps, &report.accepted.fps, 0.05 * *settings.fps);
  if (settings.exposure) {
    apply("auto exposure off", cv::CAP_PROP_AUTO_EXPOSURE, kManualExposure, nullptr, 0.0);
    apply("exposure", cv::CAP_PROP_EXPOSURE, *settings.exposure, &report.accepted.exposure, 1e-6);
  }
  if (settings.gain) {
    apply("gain", cv::CAP_PROP_GAIN, *settings.gain, &report.accepted.gain, 1e-6);
  }
  if (settings.white_balance_k) {
    apply("auto white balance off", cv::CAP_PROP_AUTO_WB, kOff, nullptr, 0.0);
    apply("white_balance", cv::CAP_PROP_WB_TEMPERATURE, *settings.white_balance_k,
          &report.accepted.white_balance_k, 1e-6);
  }
  if (settings.focus) {
    apply("autofocus off", cv::CAP_PROP_AUTOFOCUS, kOff, nullptr, 0.0);
    apply("focus", cv::CAP_PROP_FOCUS, *settings.focus, &report.accepted.focus, 1e-6);
  }
  // What the camera runs at now, given or not.
  report.summary = camera_name + ": " + ShortNumber(backend.get(cv::CAP_PROP_FRAME_WIDTH)) + "x" +
                   ShortNumber(backend.get(cv::CAP_PROP_FRAME_HEIGHT)) + " " +
                   ShortNumber(backend.get(cv::CAP_PROP_FPS)) + " fps " +
                   FourccText(backend.get(cv::CAP_PROP_FOURCC));
  if (report.accepted.exposure) report.summary += " exposure " + ShortNumber(*report.accepted.exposure);
  if (report.accepted.gain) report.summary += " gain " + ShortNumber(*report.accepted.gain);
  if (report.accepted.white_balance_k) {
    report.summary += " white_balance " + ShortNumber(*report.accepted.white_balance_k) + " K";
  }
  if (report.accepted.focus) report.summary += " focus " + ShortNumber(*report.accepted.focus);
  return report;
}

std::vector<std::string> ListCameras() {
  namespace fs = std::filesystem;
  std::vector<std::string> devices;
  std::error_code error;
  for (fs::directory_iterator it("/dev", error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (name.rfind("video", 0) == 0) devices.push_back(it->path().string());
  }
  std::sort(devices.begin(), devices.end());
  std::vector<std::string> lines;
  for (const std::string& path : devices) {
    const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK);
    if (fd < 0) continue;
    v4l2_capability caps{};
    if (ioctl(fd, VIDIOC_QUERYCAP, &caps) != 0 ||
        !((caps.device_caps ? caps.device_caps : caps.capabilities) & V4L2_CAP_VIDEO_CAPTURE)) {
      ::close(fd);
      continue;  // Metadata nodes and output devices.
    }
    lines.push_back(path + ": " + reinterpret_cast<const char*>(caps.card) + " (--camera " +
                    path.substr(std::string("/dev/video").size()) + ")");
    v4l2_fmtdesc format{};
    format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    for (format.index = 0; ioctl(fd, VIDIOC_ENUM_FMT, &format) == 0; ++format.index) {
      std::string line = "  " + FourccText(format.pixelformat) + ":";
      v4l2_frmsizeenum size{};
      size.pixel_format = format.pixelformat;
      for (size.index = 0; ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &size) == 0; ++size.index) {
        if (size.type != V4L2_FRMSIZE_TYPE_DISCRETE) {
          line += cv::format(" %ux%u..%ux%u", size.stepwise.min_width, size.stepwise.min_height,
                             size.stepwise.max_width, size.stepwise.max_height);
          break;
        }
        line += cv::format(" %ux%u", size.discrete.width, size.discrete.height);
        v4l2_frmivalenum interval{};
        interval.pixel_format = format.pixelformat;
        interval.width = size.discrete.width;
        interval.height = size.discrete.height;
        std::string rates;
        for (interval.index = 0; ioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &interval) == 0;
             ++interval.index) {
          if (interval.type != V4L2_FRMIVAL_TYPE_DISCRETE || interval.discrete.numerator == 0) break;
          if (!rates.empty()) rates += '/';
          rates += ShortNumber(static_cast<double>(interval.discrete.denominator) /
                        interval.discrete.numerator);
        }
        if (!rates.empty()) line += "@" + rates;
      }
      lines.push_back(line);
    }
    ::close(fd);
  }
  return lines;
}

}  // namespace softsight
