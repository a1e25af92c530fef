#include "io/aravis_camera.h"

#include <arv.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "io/camera_options.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"

namespace softsight {
namespace {

using PixelFormat = CameraSettings::PixelFormat;

// The pixel formats softsight turns into BGR, and how (GenICam names each Bayer layout by its
// first row, OpenCV by the second row's second and third pixels: GenICam's BayerRG is OpenCV's
// BayerBG). `code` -1: the bytes already are BGR.
struct Conversion {
  ArvPixelFormat format;
  const char* name;
  int cv_type;
  int code;
  bool bayer;
};
constexpr Conversion kConversions[] = {
    {ARV_PIXEL_FORMAT_RGB_8_PACKED, "RGB8", CV_8UC3, cv::COLOR_RGB2BGR, false},
    {ARV_PIXEL_FORMAT_BGR_8_PACKED, "BGR8", CV_8UC3, -1, false},
    {ARV_PIXEL_FORMAT_BAYER_RG_8, "BayerRG8", CV_8UC1, cv::COLOR_BayerBG2BGR, true},
    {ARV_PIXEL_FORMAT_BAYER_BG_8, "BayerBG8", CV_8UC1, cv::COLOR_BayerRG2BGR, true},
    {ARV_PIXEL_FORMAT_BAYER_GB_8, "BayerGB8", CV_8UC1, cv::COLOR_BayerGR2BGR, true},
    {ARV_PIXEL_FORMAT_BAYER_GR_8, "BayerGR8", CV_8UC1, cv::COLOR_BayerGB2BGR, true},
    {ARV_PIXEL_FORMAT_MONO_8, "Mono8", CV_8UC1, cv::COLOR_GRAY2BGR, false},
};  // In the order `pixel_format: any` prefers them when the camera's own is none of these.

const Conversion* FindConversion(ArvPixelFormat format) {
  for (const Conversion& c : kConversions) {
    if (c.format == format) return &c;
  }
  return nullptr;
}

// Whether a format fits what the settings ask (any: every one softsight converts).
bool Fits(const Conversion& c, PixelFormat asked) {
  switch (asked) {
    case PixelFormat::kAny: return true;
    case PixelFormat::kMono8: return c.format == ARV_PIXEL_FORMAT_MONO_8;
    case PixelFormat::kRgb8: return c.format == ARV_PIXEL_FORMAT_RGB_8_PACKED;
    case PixelFormat::kBayer8: return c.bayer;
    default: return false;  // MJPG, YUYV: V4L2's.
  }
}

PixelFormat SettingOf(const Conversion& c) {
  if (c.bayer) return PixelFormat::kBayer8;
  if (c.format == ARV_PIXEL_FORMAT_MONO_8) return PixelFormat::kMono8;
  if (c.format == ARV_PIXEL_FORMAT_RGB_8_PACKED) return PixelFormat::kRgb8;
  return PixelFormat::kAny;  // BGR8 has no name of its own in the settings: the camera's choice.
}

void ToBgr(const Conversion& c, const cv::Mat& raw, cv::Mat& bgr) {
  if (c.code < 0) {
    raw.copyTo(bgr);
  } else {
    cv::cvtColor(raw, bgr, c.code);
  }
}

// One GError, freed with the scope; `text()` is Aravis' message.
class Error {
 public:
  ~Error() { g_clear_error(&error_); }
  GError** out() {
    g_clear_error(&error_);
    return &error_;
  }
  explicit operator bool() const { return error_ != nullptr; }
  std::string text() const { return error_ != nullptr ? error_->message : "unknown error"; }

 private:
  GError* error_ = nullptr;
};

struct Unref {
  void operator()(gpointer object) const { g_object_unref(object); }
};

std::mutex painter_mutex;
FakeCameraPainter& Painter() {
  static FakeCameraPainter painter;
  return painter;
}

// Aravis' fake camera calls this for each frame it fills (in its stream thread).
void PaintFakeFrame(ArvBuffer* buffer, void* data, guint32 /*exposure_us*/, guint32 /*gain*/,
                    ArvPixelFormat format) {
  const auto* painter = static_cast<const FakeCameraPainter*>(data);
  // The fake camera hands its own buffer to be written: Aravis' API only has a const view. The
  // fake camera checked that it holds the frame it asked for (width x height at the format's
  // bits per pixel) before calling.
  auto* bytes = static_cast<uint8_t*>(const_cast<void*>(arv_buffer_get_data(buffer, nullptr)));
  const int width = arv_buffer_get_image_width(buffer);
  const int height = arv_buffer_get_image_height(buffer);
  const size_t size = static_cast<size_t>(width) * static_cast<size_t>(height) *
                      ARV_PIXEL_FORMAT_BIT_PER_PIXEL(format) / 8;
  const Conversion* c = FindConversion(format);
  (*painter)(bytes, size, width, height, c != nullptr ? c->name : "?");
}

class AravisCameraSource : public FrameSource {
 public:
  AravisCameraSource(const CameraId& id, const CameraSettings& settings,
                     CameraSettingsReport* report)
      : name_("camera " + id.text()) {
    const std::string& device = *id.aravis_device;
    Error error;
    // Aravis' simulated camera lives in its Fake interface, which Aravis leaves disabled (it
    // would be "the first camera"): asked by name, it is opened from that interface alone, so no
    // other interface looks for it (GigE Vision would broadcast a discovery on every network).
    const bool fake = device.rfind("Fake_", 0) == 0;
    ArvDevice* opened = nullptr;
    if (fake) {
      opened = arv_interface_open_device(arv_fake_interface_get_instance(), device.c_str(),
                                         error.out());
      if (opened == nullptr && !error) {
        throw InputError(name_ + ": cannot open: no such simulated camera (Aravis' Fake "
                         "interface has Fake_1)");
      }
    } else {
      opened = arv_open_device(device.empty() ? nullptr : device.c_str(), error.out());
    }
    if (opened == nullptr) {
      throw InputError(name_ + ": cannot open (" +
                       (error ? error.text()
                              : device.empty() ? "no GenICam camera found" : "not found") +
                       "; try `softsight cameras`)");
    }
    std::unique_ptr<ArvDevice, Unref> device_ref(opened);
    camera_.reset(arv_camera_new_with_device(opened, error.out()));
    if (!camera_) throw InputError(name_ + ": cannot open (" + error.text() + ")");
    if (device.empty()) {
      // Named after the camera it found, so the summary and every message say which.
      const char* serial = arv_camera_get_device_serial_number(camera_.get(), nullptr);
      const char* model = arv_camera_get_model_name(camera_.get(), nullptr);
      name_ += std::string(" (") + (model ? model : "?") + " " + (serial ? serial : "?") + ")";
    }
    if (fake) {
      std::lock_guard<std::mutex> lock(painter_mutex);
      painter_ = Painter();
      if (painter_) {
        arv_fake_camera_set_fill_pattern(
            arv_fake_device_get_fake_camera(ARV_FAKE_DEVICE(arv_camera_get_device(camera_.get()))),
            PaintFakeFrame, &painter_);
      }
    }
    CameraSettingsReport applied = apply(settings);
    note_ = applied.summary;
    for (const std::string& line : applied.refused) note_ += "\n" + line;
    if (report) *report = std::move(applied);
    start();
  }

  ~AravisCameraSource() override {
    if (stream_) arv_camera_stop_acquisition(camera_.get(), nullptr);
    stream_.reset();  // Its thread stops here, before the painter it may call goes.
    camera_.reset();
  }

  bool read(Frame& frame) override {
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(kAravisFrameTimeoutMs);
    int64_t incomplete = 0;
    while (true) {
      if (software_trigger_) arv_camera_software_trigger(camera_.get(), nullptr);
      const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
          deadline - std::chrono::steady_clock::now());
      ArvBuffer* buffer =
          left.count() > 0 ? arv_stream_timeout_pop_buffer(stream_.get(), left.count()) : nullptr;
      if (buffer == nullptr) {
        throw InputError(name_ + ": no frame for " + ShortNumber(kAravisFrameTimeoutMs / 1000.0) +
                         " s " +
                         (next_index_ == 0 ? std::string("since it started")
                                           : "after frame " + std::to_string(next_index_ - 1)) +
                         (incomplete > 0 ? " (" + std::to_string(incomplete) +
                                               " arrived incomplete: packets lost?)"
                                         : " (unplugged, or no trigger came?)"));
      }
      const bool converted = arv_buffer_get_status(buffer) == ARV_BUFFER_STATUS_SUCCESS &&
                             convert(buffer, frame);
      // Back to the stream at once: the same few buffers go round, nothing is allocated.
      arv_stream_push_buffer(stream_.get(), buffer);
      if (converted) break;
      // A frame that arrived damaged (packets lost on the network) is lost: its number is a gap.
      ++incomplete;
      ++lost_;
      ++next_index_;
    }
    frame.captured = std::chrono::steady_clock::now();
    frame.index = next_index_++;
    frame.repeated = false;  // Aravis hands out each buffer once.
    return true;
  }

  std::string description() const override { return name_; }
  std::optional<int64_t> frame_count() const override { return std::nullopt; }
  std::optional<double> fps() const override { return fps_; }
  bool is_live() const override { return true; }
  std::optional<std::string> note() const override {
    std::string note = note_;
    if (const int64_t lost = lost_.load(); lost > 0) {
      note += "\n" + name_ + ": " + std::to_string(lost) + " frame" + (lost == 1 ? "" : "s") +
              " arrived incomplete and were left out (gaps in `frame`)";
    }
    return note;
  }

 private:
  // Settings in the order a GenICam camera takes them (the format and size fix the payload; the
  // trigger decides whether the frame rate applies), each read back.
  CameraSettingsReport apply(const CameraSettings& settings) {
    ArvCamera* camera = camera_.get();
    CameraSettingsReport report;
    report.accepted = settings;
    Error error;
    const auto refuse = [&](const std::string& what, const std::string& kept) {
      add_refusal(what, error, kept, &report);
    };
    const auto close = [](double a, double b, double relative) {
      return std::abs(a - b) <= relative * std::max(std::abs(b), 1.0);
    };

    if (!settings.trigger.empty()) choose_trigger(settings.trigger, &report, error);

    choose_pixel_format(settings.pixel_format, &report, error);

    const auto apply_int = [&](const char* name, const char* feature, int value,
                               std::optional<int>* accepted) {
      arv_camera_set_integer(camera, feature, value, error.out());
      const auto now = static_cast<int>(arv_camera_get_integer(camera, feature, nullptr));
      if (error || now != value) refuse(std::string(name) + " " + std::to_string(value), std::to_string(now));
      *accepted = now;
    };
    if (settings.width) apply_int("width", "Width", *settings.width, &report.accepted.width);
    if (settings.height) apply_int("height", "Height", *settings.height, &report.accepted.height);

    // A value set, read back, refused when the camera keeps another (beyond `relative`).
    using Set = void (*)(ArvCamera*, double, GError**);
    using Get = double (*)(ArvCamera*, GError**);
    const auto apply = [&](const char* name, const std::optional<double>& value, Set set, Get get,
                           double relative, std::optional<double>* accepted) {
      if (!value) return;
      set(camera, *value, error.out());
      const double now = get(camera, nullptr);
      if (error || !close(now, *value, relative)) {
        refuse(std::string(name) + " " + ShortNumber(*value), ShortNumber(now));
      }
      *accepted = now;
    };
    apply("fps", settings.fps, arv_camera_set_frame_rate, arv_camera_get_frame_rate, 0.05,
          &report.accepted.fps);
    // Exposure and gain: the automatic mode off first, so the value set is the one that stays
    // (colour thresholds need the same brightness all session). Cameras round both to their
    // steps (a sensor's row time): within 1 % is taken as accepted.
    if (settings.exposure && arv_camera_is_exposure_auto_available(camera, nullptr)) {
      arv_camera_set_exposure_time_auto(camera, ARV_AUTO_OFF, nullptr);
    }
    apply("exposure", settings.exposure, arv_camera_set_exposure_time,
          arv_camera_get_exposure_time, 0.01, &report.accepted.exposure);
    if (settings.gain && arv_camera_is_gain_auto_available(camera, nullptr)) {
      arv_camera_set_gain_auto(camera, ARV_AUTO_OFF, nullptr);
    }
    apply("gain", settings.gain, arv_camera_set_gain, arv_camera_get_gain, 0.01,
          &report.accepted.gain);
    refuse_v4l2_only(settings, &report);

    report.summary = read_back();
    return report;
  }

  // "<camera>: <what> refused (<the camera's error>), kept <kept>".
  void add_refusal(const std::string& what, const Error& error, const std::string& kept,
                   CameraSettingsReport* report) const {
    report->refused.push_back(name_ + ": " + what + " refused" +
                              (error ? " (" + error.text() + ")" : std::string()) + ", kept " +
                              kept);
  }

  // The trigger: "off", or one of the camera's sources (a name it does not have is refused,
  // naming those it has).
  void choose_trigger(const std::string& trigger, CameraSettingsReport* report, Error& error) {
    ArvCamera* camera = camera_.get();
    if (trigger == "off") {
      arv_camera_clear_triggers(camera, error.out());
      if (error) add_refusal("trigger off", error, TriggerText(), report);
    } else {
      guint count = 0;
      const char** sources = arv_camera_dup_available_trigger_sources(camera, &count, error.out());
      std::string names;
      bool known = false;
      for (guint i = 0; i < count; ++i) {
        names += (i ? ", " : "") + std::string(sources[i]);
        known = known || trigger == sources[i];
      }
      g_free(sources);
      if (!known) {
        add_refusal("trigger " + trigger + " (it has: " + (names.empty() ? "none" : names) + ")",
                    error, TriggerText(), report);
      } else {
        arv_camera_set_trigger(camera, trigger.c_str(), error.out());
        if (error) add_refusal("trigger " + trigger, error, TriggerText(), report);
      }
    }
    report->accepted.trigger = TriggerText();
  }

  // V4L2's controls, which GenICam has no standard feature for softsight to set.
  void refuse_v4l2_only(const CameraSettings& settings, CameraSettingsReport* report) const {
    if (settings.white_balance_k) {
      report->refused.push_back(name_ + ": white_balance " + ShortNumber(*settings.white_balance_k) +
                                " refused (V4L2 only; set a GenICam camera's balance with its "
                                "vendor's tool)");
      report->accepted.white_balance_k.reset();
    }
    if (settings.focus) {
      report->refused.push_back(name_ + ": focus " + ShortNumber(*settings.focus) +
                                " refused (V4L2 only)");
      report->accepted.focus.reset();
    }
  }

  // What the camera now runs with, read back (its frame rate kept for fps()), in one line.
  std::string read_back() {
    ArvCamera* camera = camera_.get();
    gint x = 0, y = 0, width = 0, height = 0;
    arv_camera_get_region(camera, &x, &y, &width, &height, nullptr);
    fps_ = arv_camera_get_frame_rate(camera, nullptr);
    if (!(fps_ && *fps_ > 0)) fps_.reset();
    const char* format = arv_camera_get_pixel_format_as_string(camera, nullptr);
    return name_ + ": " + std::to_string(width) + "x" + std::to_string(height) + " " +
           (fps_ ? ShortNumber(*fps_) : std::string("?")) + " fps " + (format ? format : "?") +
           " exposure " + ShortNumber(arv_camera_get_exposure_time(camera, nullptr)) +
           " us gain " + ShortNumber(arv_camera_get_gain(camera, nullptr)) + " trigger " +
           TriggerText();
  }

  // The format asked; any: the camera's own when softsight converts it and it is in colour
  // (markers are told apart by colour; many colour cameras start in Mono8), else the first
  // format it offers in kConversions' order. A camera with none of them cannot be used.
  void choose_pixel_format(PixelFormat asked, CameraSettingsReport* report, Error& error) {
    ArvCamera* camera = camera_.get();
    const ArvPixelFormat current = arv_camera_get_pixel_format(camera, nullptr);
    const Conversion* now = FindConversion(current);
    const bool mono_for_any = asked == PixelFormat::kAny && current == ARV_PIXEL_FORMAT_MONO_8;
    if (now != nullptr && Fits(*now, asked) && !mono_for_any) {
      report->accepted.pixel_format = asked;
      return;
    }
    guint count = 0;
    gint64* formats = arv_camera_dup_available_pixel_formats(camera, &count, nullptr);
    const Conversion* chosen = nullptr;
    for (const Conversion& c : kConversions) {
      for (guint i = 0; i < count && chosen == nullptr; ++i) {
        if (static_cast<ArvPixelFormat>(formats[i]) == c.format && Fits(c, asked)) chosen = &c;
      }
    }
    g_free(formats);
    if (chosen != nullptr && chosen == now) {
      report->accepted.pixel_format = asked;  // Mono8 is all it has.
      return;
    }
    if (chosen != nullptr) {
      arv_camera_set_pixel_format(camera, chosen->format, error.out());
      if (!error) {
        report->accepted.pixel_format = asked == PixelFormat::kAny ? asked : SettingOf(*chosen);
        return;
      }
    }
    const char* kept = arv_camera_get_pixel_format_as_string(camera, nullptr);
    if (now == nullptr) {
      throw InputError(name_ + ": its pixel format " + (kept ? kept : "?") +
                       " is none softsight converts (Mono8, RGB8, BGR8, 8-bit Bayer), and it "
                       "offers none of those" +
                       (error ? " (" + error.text() + ")" : std::string()));
    }
    report->refused.push_back(name_ + ": pixel_format " + PixelFormatName(asked) + " refused" +
                              (error ? " (" + error.text() + ")" : std::string(" (not offered)")) +
                              ", kept " + (kept ? kept : "?"));
    report->accepted.pixel_format = SettingOf(*now);
  }

  // "off", or the source that triggers each frame.
  std::string TriggerText() {
    ArvCamera* camera = camera_.get();
    if (!arv_camera_is_feature_available(camera, "TriggerMode", nullptr)) return "off";
    const char* mode = arv_camera_get_string(camera, "TriggerMode", nullptr);
    if (mode == nullptr || std::string(mode) != "On") return "off";
    const char* source = arv_camera_get_string(camera, "TriggerSource", nullptr);
    return source != nullptr ? source : "?";
  }

  // A stream with a few buffers of the payload's size, then acquisition on.
  void start() {
    Error error;
    ArvCamera* camera = camera_.get();
    if (arv_camera_is_gv_device(camera)) {
      // The largest packet the path carries: fewer packets per frame (it falls back to the
      // default when it cannot tell).
      arv_camera_gv_auto_packet_size(camera, nullptr);
    }
    software_trigger_ = TriggerText() == "Software";
    payload_ = arv_camera_get_payload(camera, error.out());
    if (error || payload_ == 0) {
      throw InputError(name_ + ": cannot read its payload size (" + error.text() + ")");
    }
    stream_.reset(arv_camera_create_stream(camera, nullptr, nullptr, error.out()));
    if (!stream_) throw InputError(name_ + ": cannot open its stream (" + error.text() + ")");
    // Enough to ride out a consumer's hiccup at a few hundred frames per second; the
    // grabber thread empties the queue as fast as frames come.
    constexpr int kBuffers = 8;
    for (int i = 0; i < kBuffers; ++i) arv_stream_push_buffer(stream_.get(), arv_buffer_new(payload_, nullptr));
    arv_camera_start_acquisition(camera, error.out());
    if (error) throw InputError(name_ + ": cannot start acquisition (" + error.text() + ")");
  }

  // The buffer's image as BGR into `frame` (its buffer reused when the size is the same);
  // false when the buffer holds no usable image.
  bool convert(ArvBuffer* buffer, Frame& frame) {
    if (arv_buffer_get_payload_type(buffer) != ARV_BUFFER_PAYLOAD_TYPE_IMAGE &&
        arv_buffer_get_payload_type(buffer) != ARV_BUFFER_PAYLOAD_TYPE_EXTENDED_CHUNK_DATA) {
      return false;
    }
    const ArvPixelFormat format = arv_buffer_get_image_pixel_format(buffer);
    const Conversion* c = FindConversion(format);
    if (c == nullptr) {
      throw InputError(name_ + ": frame " + std::to_string(next_index_) +
                       " came in pixel format 0x" + cv::format("%08x", format) +
                       ", none softsight converts (Mono8, RGB8, BGR8, 8-bit Bayer)");
    }
    const int width = arv_buffer_get_image_width(buffer);
    const int height = arv_buffer_get_image_height(buffer);
    gint x_padding = 0, y_padding = 0;
    arv_buffer_get_image_padding(buffer, &x_padding, &y_padding);
    size_t size = 0;
    const void* data = arv_buffer_get_image_data(buffer, &size);
    if (painter_) {
      // A painted fake frame: Aravis' fill-pattern API has no way to set the buffer's received
      // size, so the painter filled the payload the camera asked for.
      data = arv_buffer_get_data(buffer, nullptr);
      size = payload_;
    }
    const size_t step = static_cast<size_t>(width) * CV_ELEM_SIZE(c->cv_type) +
                        static_cast<size_t>(std::max(x_padding, 0));
    if (data == nullptr || width <= 0 || height <= 0) return false;
    const size_t needed = step * static_cast<size_t>(height - 1) +
                          static_cast<size_t>(width) * CV_ELEM_SIZE(c->cv_type);
    if (size < needed) return false;  // A short buffer: a frame cut off.
    // A header on Aravis' bytes: no copy until the conversion writes the frame.
    const cv::Mat raw(height, width, c->cv_type, const_cast<void*>(data), step);
    ToBgr(*c, raw, frame.image);
    // The camera's clock when it has one (the exposure's time), else the host's at arrival.
    uint64_t stamp_ns = arv_buffer_get_timestamp(buffer);
    if (stamp_ns == 0) stamp_ns = arv_buffer_get_system_timestamp(buffer);
    if (!first_stamp_ns_) first_stamp_ns_ = stamp_ns;
    frame.time_s = stamp_ns >= *first_stamp_ns_ ? (stamp_ns - *first_stamp_ns_) * 1e-9 : 0.0;
    return true;
  }

  std::string name_;
  std::unique_ptr<ArvCamera, Unref> camera_;
  std::unique_ptr<ArvStream, Unref> stream_;
  FakeCameraPainter painter_;  // The fake camera's, kept here for its callback's lifetime.
  std::string note_;
  std::optional<double> fps_;
  std::optional<uint64_t> first_stamp_ns_;
  bool software_trigger_ = false;
  size_t payload_ = 0;  // Bytes of one frame, as the camera said when acquisition started.
  int64_t next_index_ = 0;
  std::atomic<int64_t> lost_{0};  // Read by note() from the run's thread.
};

}  // namespace

std::unique_ptr<FrameSource> OpenAravisCamera(const CameraId& id, const CameraSettings& settings,
                                              CameraSettingsReport* report) {
  return std::make_unique<AravisCameraSource>(id, settings, report);
}

bool AravisImageToBgr(const cv::Mat& raw, const std::string& pixel_format, cv::Mat& bgr) {
  for (const Conversion& c : kConversions) {
    if (pixel_format == c.name && raw.type() == c.cv_type) {
      ToBgr(c, raw, bgr);
      return true;
    }
  }
  return false;
}

void SetFakeCameraPainter(FakeCameraPainter painter) {
  std::lock_guard<std::mutex> lock(painter_mutex);
  Painter() = std::move(painter);
}

bool HaveAravisSupport() { return true; }

std::vector<std::string> ListAravisCameras() {
  arv_update_device_list();
  std::vector<std::string> lines;
  const auto text = [](const char* s) { return std::string(s != nullptr ? s : "?"); };
  for (unsigned int i = 0; i < arv_get_n_devices(); ++i) {
    const std::string id = text(arv_get_device_id(i));
    std::string line = "aravis:" + id + ": " + text(arv_get_device_vendor(i)) + " " +
                       text(arv_get_device_model(i)) + " (" + text(arv_get_device_protocol(i));
    if (const char* address = arv_get_device_address(i); address != nullptr && *address) {
      line += std::string(" ") + address;
    }
    lines.push_back(line + ", serial " + text(arv_get_device_serial_nbr(i)) + ") (--camera aravis:" +
                    id + ")");
  }
  return lines;
}

}  // namespace softsight
