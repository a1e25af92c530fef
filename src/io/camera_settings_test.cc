// Camera settings through the seam: a fake capture backend records what was set and answers as
// a camera would, accepting or keeping its own value.
#include "softsight/io/camera_settings.h"

#include <gtest/gtest.h>

#include <map>
#include <opencv2/videoio.hpp>
#include <vector>

namespace softsight {
namespace {

class FakeCapture : public CaptureBackend {
 public:
  bool set(int property, double value) override {
    calls.emplace_back(property, value);
    if (const auto kept = refuses.find(property); kept != refuses.end()) {
      values[property] = kept->second;
      return true;  // V4L2 drivers often say yes and keep their own value.
    }
    values[property] = value;
    return true;
  }
  double get(int property) const override {
    const auto it = values.find(property);
    return it == values.end() ? 0.0 : it->second;
  }
  std::vector<std::pair<int, double>> calls;
  std::map<int, double> values;
  std::map<int, double> refuses;  // Property -> the value it keeps.
};

CameraSettings Everything() {
  CameraSettings s;
  s.width = 1280;
  s.height = 720;
  s.fps = 30;
  s.pixel_format = CameraSettings::PixelFormat::kMjpg;
  s.exposure = 120;
  s.gain = 8;
  s.white_balance_k = 4500;
  s.focus = 30;
  return s;
}

TEST(CameraSettings, EveryConfiguredPropertyReachesTheCaptureWithItsAutoModeOff) {
  FakeCapture camera;
  const CameraSettingsReport report = ApplyCameraSettings(camera, Everything(), "camera 0");
  const std::vector<std::pair<int, double>> expected = {
      {cv::CAP_PROP_FOURCC, cv::VideoWriter::fourcc('M', 'J', 'P', 'G')},
      {cv::CAP_PROP_FRAME_WIDTH, 1280},
      {cv::CAP_PROP_FRAME_HEIGHT, 720},
      {cv::CAP_PROP_FPS, 30},
      {cv::CAP_PROP_AUTO_EXPOSURE, 1},  // V4L2 manual mode.
      {cv::CAP_PROP_EXPOSURE, 120},
      {cv::CAP_PROP_GAIN, 8},
      {cv::CAP_PROP_AUTO_WB, 0},
      {cv::CAP_PROP_WB_TEMPERATURE, 4500},
      {cv::CAP_PROP_AUTOFOCUS, 0},
      {cv::CAP_PROP_FOCUS, 30},
  };
  EXPECT_EQ(camera.calls, expected);
  EXPECT_TRUE(report.refused.empty());
  EXPECT_EQ(report.accepted, Everything());
  EXPECT_EQ(report.summary,
            "camera 0: 1280x720 30 fps MJPG exposure 120 gain 8 white_balance 4500 K focus 30");
}

TEST(CameraSettings, ARefusedPropertyIsOneLineNamingItAndTheValueKept) {
  FakeCapture camera;
  camera.refuses[cv::CAP_PROP_EXPOSURE] = 156;
  camera.refuses[cv::CAP_PROP_FOURCC] = cv::VideoWriter::fourcc('Y', 'U', 'Y', 'V');
  const CameraSettingsReport report = ApplyCameraSettings(camera, Everything(), "camera 2");
  ASSERT_EQ(report.refused.size(), 2u);
  EXPECT_EQ(report.refused[0], "camera 2: pixel_format MJPG refused, kept YUYV");
  EXPECT_EQ(report.refused[1], "camera 2: exposure 120 refused, kept 156");
  // What the camera actually runs at is what a recording saves.
  EXPECT_EQ(report.accepted.exposure, 156);
  EXPECT_EQ(report.accepted.pixel_format, CameraSettings::PixelFormat::kYuyv);
  EXPECT_EQ(report.accepted.width, 1280);
}

TEST(CameraSettings, NothingSetTouchesNothingAndRangesAreChecked) {
  FakeCapture camera;
  const CameraSettingsReport report = ApplyCameraSettings(camera, CameraSettings{}, "camera 0");
  EXPECT_TRUE(camera.calls.empty());
  EXPECT_TRUE(CameraSettings{}.empty());
  CameraSettings bad;
  bad.fps = 0;
  std::string error;
  EXPECT_FALSE(bad.Check(&error));
  EXPECT_EQ(error, "fps: 0 must lie within 1..1000");
  EXPECT_TRUE(Everything().Check(&error)) << error;
}

TEST(CameraSettings, ListingWithoutCamerasIsEmptyNotAnError) {
  // On a machine without /dev/video* (this one) the list is empty; with cameras, each capture
  // device has a line naming its --camera index.
  for (const std::string& line : ListCameras()) {
    if (line.rfind("/dev/video", 0) == 0) {
      EXPECT_NE(line.find("--camera "), std::string::npos) << line;
    }
  }
}

}  // namespace
}  // namespace softsight
