// Internal. The capture settings' option table (key, unit, range, doc of every field), from
// which the config's `capture:` reader and writer, Check() and the --camera-* options come; and
// the OpenCV capture as a CaptureBackend.
#pragma once

#include <string>

#include <opencv2/videoio.hpp>

#include "softsight/core/option_table.h"
#include "softsight/io/camera_settings.h"

namespace softsight {

const OptionTable<CameraSettings>& CameraSettingsTable();

// The pixel format's name in the table ("MJPG", "Bayer8").
std::string PixelFormatName(CameraSettings::PixelFormat format);

class OpenCvCaptureBackend : public CaptureBackend {
 public:
  explicit OpenCvCaptureBackend(cv::VideoCapture& capture) : capture_(capture) {}
  bool set(int property, double value) override { return capture_.set(property, value); }
  double get(int property) const override { return capture_.get(property); }

 private:
  cv::VideoCapture& capture_;
};

}  // namespace softsight
