// The Aravis camera source against Aravis' own simulated camera (aravis:Fake_1, its Fake
// interface, in this process: no network, no daemon): frames of the size and format asked,
// settings set and read back, triggers, errors naming the device, and the conversion of every
// pixel format to BGR against a picture with known colours.
#include "io/aravis_camera.h"

#include <arv.h>

#include <atomic>
#include <condition_variable>
#include <chrono>
#include <cstdio>
#include <mutex>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "io/aravis_test_util.h"
#include "softsight/core/error.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/run_source.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;

// GigE Vision finds cameras by a broadcast on every network interface: no test may send one.
// Disabled before any test opens a camera, and only Aravis' Fake interface lists anything.
class NoNetworkInterfaces : public ::testing::Environment {
 public:
  void SetUp() override {
    arv_disable_interface("GigEVision");
    arv_disable_interface("USB3Vision");
  }
};
const auto* const kNoNetwork = ::testing::AddGlobalTestEnvironment(new NoNetworkInterfaces);

// The fake camera at 320x240 and 200 fps: frames every 5 ms, so tests take milliseconds.
CameraSettings Fast() {
  CameraSettings settings;
  settings.width = 320;
  settings.height = 240;
  settings.fps = 200;
  return settings;
}

std::unique_ptr<FrameSource> OpenFake(const CameraSettings& settings,
                                      CameraSettingsReport* report = nullptr) {
  FrameSourceSpec spec;
  spec.camera = CameraId("aravis:Fake_1");
  spec.capture = settings;
  spec.capture_report = report;
  return OpenFrameSource(spec);
}

TEST(AravisCamera, CameraIdsReadAsTheCommandLineWritesThem) {
  EXPECT_EQ(CameraId("aravis:Fake_1").aravis_device, "Fake_1");
  EXPECT_EQ(CameraId("aravis:").aravis_device, "");
  EXPECT_EQ(CameraId("3").index, 3);
  EXPECT_FALSE(CameraId("3").aravis_device);
  EXPECT_EQ(CameraId("aravis:Fake_1").text(), "aravis:Fake_1");
  EXPECT_EQ(CameraId(2).text(), "2");
  EXPECT_THROW(CameraId("Fake_1"), InputError);
  EXPECT_THROW(CameraId("64"), InputError);
  EXPECT_THROW(CameraId("-1"), InputError);
  EXPECT_THAT(*CameraIdProblem("gige"), HasSubstr("aravis:DEVICE-ID"));
}

TEST(AravisCamera, FakeCameraGivesChangingBgrFramesOfTheSizeAsked) {
  CameraSettingsReport report;
  const std::unique_ptr<FrameSource> source = OpenFake(Fast(), &report);
  EXPECT_EQ(source->description(), "camera aravis:Fake_1");
  EXPECT_TRUE(source->is_live());
  EXPECT_THAT(report.summary, HasSubstr("camera aravis:Fake_1: 320x240 200 fps"));
  EXPECT_TRUE(report.refused.empty()) << report.refused.front();
  constexpr int kFrames = 20;
  Frame frame;
  cv::Mat first;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kFrames; ++i) {
    ASSERT_TRUE(source->read(frame));
    EXPECT_EQ(frame.index, i);
    ASSERT_EQ(frame.image.size(), cv::Size(320, 240));
    ASSERT_EQ(frame.image.type(), CV_8UC3);
    if (i == 0) frame.image.copyTo(first);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("fake camera: %d frames of 320x240 in %.3f s (%.0f fps)\n", kFrames, seconds,
              kFrames / seconds);
  // Aravis' test pattern moves from frame to frame; time comes from the camera's clock.
  EXPECT_GT(cv::norm(frame.image, first, cv::NORM_L1), 0.0);
  EXPECT_GT(frame.time_s, 0.0);
  EXPECT_LT(frame.time_s, 5.0);
}

TEST(AravisCamera, ExposureGainAndFrameRateAreSetAndReadBack) {
  CameraSettings settings = Fast();
  settings.fps = 150;
  settings.exposure = 2500;
  settings.gain = 3;
  settings.trigger = "off";
  CameraSettingsReport report;
  const std::unique_ptr<FrameSource> source = OpenFake(settings, &report);
  EXPECT_TRUE(report.refused.empty()) << report.refused.front();
  // The fake camera keeps a frame period in whole microseconds.
  EXPECT_NEAR(*report.accepted.fps, 150, 0.05);
  EXPECT_EQ(report.accepted.exposure, 2500);
  EXPECT_EQ(report.accepted.gain, 3);
  EXPECT_EQ(report.accepted.width, 320);
  EXPECT_EQ(report.accepted.trigger, "off");
  // pixel_format any: a colour format the camera offers (markers are told by colour).
  EXPECT_EQ(report.accepted.pixel_format, CameraSettings::PixelFormat::kAny);
  EXPECT_THAT(report.summary, HasSubstr("fps RGB8 exposure 2500 us gain 3 trigger off"));
  EXPECT_NEAR(source->fps().value_or(0), 150, 0.05);
  Frame frame;
  EXPECT_TRUE(source->read(frame));
}

TEST(AravisCamera, WhatTheCameraCannotDoIsOneLineEachNamingItAndWhatItKept) {
  CameraSettings settings = Fast();
  settings.trigger = "Line7";    // It has Line0 and Software.
  settings.pixel_format = CameraSettings::PixelFormat::kMjpg;  // V4L2's.
  settings.white_balance_k = 4500;  // No GenICam feature softsight sets.
  CameraSettingsReport report;
  const std::unique_ptr<FrameSource> source = OpenFake(settings, &report);
  ASSERT_EQ(report.refused.size(), 3u);
  EXPECT_THAT(report.refused[0],
              HasSubstr("camera aravis:Fake_1: trigger Line7 (it has: Line0, Software) refused"));
  EXPECT_THAT(report.refused[0], HasSubstr("kept off"));
  EXPECT_EQ(report.refused[1],
            "camera aravis:Fake_1: pixel_format MJPG refused (not offered), kept Mono8");
  EXPECT_THAT(report.refused[2], HasSubstr("white_balance 4500 refused"));
  EXPECT_THAT(source->note().value_or(""), HasSubstr("trigger Line7"));
  Frame frame;
  EXPECT_TRUE(source->read(frame));  // Refusals leave a working camera.
}

TEST(AravisCamera, AnUnknownDeviceIsOneErrorNamingIt) {
  try {
    OpenFake(Fast()).reset();
    FrameSourceSpec spec;
    spec.camera = CameraId("aravis:Fake_9");
    OpenFrameSource(spec);
    FAIL() << "opened";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("camera aravis:Fake_9: cannot open"));
  }
  try {
    FrameSourceSpec spec;
    spec.camera = CameraId("aravis:NoSuchCamera-42");
    OpenFrameSource(spec);
    FAIL() << "opened";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("camera aravis:NoSuchCamera-42: cannot open ("));
    EXPECT_THAT(e.what(), HasSubstr("softsight cameras"));
  }
}

// A camera that stops sending (unplugged, a trigger that never comes; here the fake camera's
// stream thread held in its painter until the test ends): read() gives up with an error naming
// the camera within its timeout (2 s), through the run's grabber thread too, never hanging.
TEST(AravisCamera, NoFrameWithinTheTimeoutIsAnErrorNotAHang) {
  std::mutex mutex;
  std::condition_variable released;
  bool release = false;
  SetFakeCameraPainter([&](uint8_t*, size_t, int, int, const std::string&) {
    std::unique_lock<std::mutex> lock(mutex);
    released.wait(lock, [&] { return release; });
  });
  std::unique_ptr<FrameSource> source = SourceForRun(OpenFake(Fast()), FilePacing::kReadAhead);
  SetFakeCameraPainter(nullptr);
  const auto let_go = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    release = true;
    released.notify_all();
  };
  Frame frame;
  const auto start = std::chrono::steady_clock::now();
  try {
    source->read(frame);
    FAIL() << "a frame came without a trigger";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("camera aravis:Fake_1: no frame for 2 s since it started"));
    EXPECT_THAT(e.what(), HasSubstr("no trigger came?"));
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(4500));
  let_go();  // Before the source goes: closing its stream joins the thread the painter holds.
  source.reset();
}

// Software trigger: each read() triggers one frame and gets that one (the painter numbers them).
TEST(AravisCamera, SoftwareTriggerTakesOneFramePerRead) {
  std::atomic<int> painted{0};
  SetFakeCameraPainter([&](uint8_t* data, size_t size, int, int, const std::string&) {
    const int n = painted++;
    std::fill(data, data + size, static_cast<uint8_t>(n * 10));
  });
  CameraSettings settings = Fast();
  settings.trigger = "Software";
  CameraSettingsReport report;
  const std::unique_ptr<FrameSource> source = OpenFake(settings, &report);
  EXPECT_EQ(report.accepted.trigger, "Software");
  Frame frame;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(source->read(frame));
    EXPECT_EQ(frame.index, i);
    EXPECT_EQ(frame.image.at<cv::Vec3b>(10, 10), cv::Vec3b::all(static_cast<uint8_t>(i * 10)));
  }
  SetFakeCameraPainter(nullptr);
}

// A picture with a colour in each quadrant, as a camera would send it in `format`.
cv::Mat Quadrants() {
  cv::Mat bgr(240, 320, CV_8UC3, cv::Scalar(40, 40, 40));
  bgr(cv::Rect(0, 0, 160, 120)).setTo(cv::Scalar(0, 0, 220));      // red
  bgr(cv::Rect(160, 0, 160, 120)).setTo(cv::Scalar(0, 200, 0));    // green
  bgr(cv::Rect(0, 120, 160, 120)).setTo(cv::Scalar(230, 0, 0));    // blue
  bgr(cv::Rect(160, 120, 160, 120)).setTo(cv::Scalar(200, 200, 200));
  return bgr;
}

TEST(AravisCamera, EveryPixelFormatArrivesAsTheColoursTheSensorSaw) {
  const cv::Mat truth = Quadrants();
  for (const std::string format :
       {"Mono8", "RGB8", "BGR8", "BayerRG8", "BayerBG8", "BayerGB8", "BayerGR8"}) {
    SCOPED_TRACE(format);
    cv::Mat bgr;
    ASSERT_TRUE(AravisImageToBgr(testing::AsSentByCamera(truth, format), format, bgr));
    ASSERT_EQ(bgr.type(), CV_8UC3);
    for (const cv::Point at : {cv::Point(80, 60), cv::Point(240, 60), cv::Point(80, 180)}) {
      const cv::Vec3b want = truth.at<cv::Vec3b>(at);
      const cv::Vec3b got = bgr.at<cv::Vec3b>(at);
      if (format == "Mono8") {
        EXPECT_EQ(got[0], got[2]);  // Gray stays gray.
        continue;
      }
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 2) << at << " channel " << c;
    }
  }
  cv::Mat bgr;
  EXPECT_FALSE(AravisImageToBgr(cv::Mat(4, 4, CV_16UC1), "Mono16", bgr));
}

// The conversion reuses the frame's buffer: the steady state allocates nothing.
TEST(AravisCamera, ConversionReusesTheFramesBuffer) {
  const cv::Mat mosaic = testing::AsSentByCamera(Quadrants(), "BayerRG8");
  cv::Mat bgr;
  ASSERT_TRUE(AravisImageToBgr(mosaic, "BayerRG8", bgr));
  const uint8_t* buffer = bgr.data;
  constexpr int kRounds = 200;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kRounds; ++i) ASSERT_TRUE(AravisImageToBgr(mosaic, "BayerRG8", bgr));
  const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() -
                                                              start).count() / kRounds;
  std::printf("BayerRG8 -> BGR at 320x240: %.1f us per frame\n", us);
  EXPECT_EQ(bgr.data, buffer);
}

// The camera's frames come through Aravis' own stream as RGB8 and Bayer8 too, with the painter's
// picture, in colour.
TEST(AravisCamera, ColourFormatsFromTheCameraShowThePaintersPicture) {
  const cv::Mat truth = Quadrants();
  std::mutex mutex;
  SetFakeCameraPainter([&](uint8_t* data, size_t size, int width, int height,
                           const std::string& format) {
    std::lock_guard<std::mutex> lock(mutex);
    cv::Mat sent = testing::AsSentByCamera(truth, format);
    ASSERT_EQ(cv::Size(width, height), truth.size());
    ASSERT_GE(size, sent.total() * sent.elemSize());
    std::copy(sent.data, sent.data + sent.total() * sent.elemSize(), data);
  });
  for (const auto format : {CameraSettings::PixelFormat::kRgb8, CameraSettings::PixelFormat::kBayer8}) {
    CameraSettings settings = Fast();
    settings.pixel_format = format;
    CameraSettingsReport report;
    const std::unique_ptr<FrameSource> source = OpenFake(settings, &report);
    EXPECT_TRUE(report.refused.empty()) << report.refused.front();
    EXPECT_EQ(report.accepted.pixel_format, format);
    Frame frame;
    ASSERT_TRUE(source->read(frame));
    EXPECT_LT(cv::norm(frame.image(cv::Rect(40, 30, 80, 60)),
                       truth(cv::Rect(40, 30, 80, 60)), cv::NORM_INF), 3)
        << report.summary;
  }
  SetFakeCameraPainter(nullptr);
}

TEST(AravisCamera, ListingNamesEachCamerasOption) {
  arv_enable_interface("Fake");
  const std::vector<std::string> lines = ListAravisCameras();
  arv_disable_interface("Fake");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_THAT(lines[0], HasSubstr("aravis:Fake_1: Aravis Fake"));
  EXPECT_THAT(lines[0], HasSubstr("(--camera aravis:Fake_1)"));
}

}  // namespace
}  // namespace softsight
