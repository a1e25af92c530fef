// Internal. GenICam cameras (GigE Vision, USB3 Vision) through Aravis, as a FrameSource:
// `--camera aravis:` (the first camera found) or `--camera aravis:DEVICE-ID`. Compiled from
// aravis_camera.cc when CMake finds aravis-0.8, from aravis_camera_none.cc (every call says
// "this build has no Aravis support") otherwise; nothing outside io/ sees an Aravis type.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "softsight/io/camera_settings.h"
#include "softsight/io/frame_source.h"

namespace softsight {

// Opens the camera, applies `settings` (exposure, gain, frame rate, size, pixel format, trigger)
// before the first frame and reads them back into `report` (when given), starts acquisition.
// Frames arrive as 8-bit BGR whatever the camera sends (Mono8, RGB8, BGR8, 8-bit Bayer). Throws
// InputError naming the device when it cannot be opened or set up. `id.aravis_device` must be set.
std::unique_ptr<FrameSource> OpenAravisCamera(const CameraId& id, const CameraSettings& settings,
                                              CameraSettingsReport* report);

// How long read() waits for a frame before it gives up with an error naming the camera (a
// camera unplugged, a cable pulled, a hardware trigger that never comes). Below the 5 s after
// which NewestFrameSource reports a stall, so the camera's own, more precise message is the one
// a person sees, and a grabber thread stuck in read() is joined within this long.
inline constexpr int kAravisFrameTimeoutMs = 2000;

// One frame's pixels as the camera sent them (`raw`: 8-bit, one channel for Mono8 and the Bayer
// layouts, three for RGB8 and BGR8), by the format's GenICam name ("BayerRG8"), as BGR into `bgr`,
// whose buffer is reused when the size allows. False for a format softsight does not convert.
bool AravisImageToBgr(const cv::Mat& raw, const std::string& pixel_format, cv::Mat& bgr);

// Tests: draws every frame of Aravis' simulated camera (aravis:Fake_1) opened from now on, in
// place of its built-in ramp, so a test can show the pipeline a picture with known markers. Called
// in Aravis' stream thread with the frame's bytes as the camera sends them (rows of `width`
// pixels in `pixel_format`: "Mono8", "RGB8", "BayerRG8", ...). Empty: Aravis' own pattern.
using FakeCameraPainter = std::function<void(uint8_t* data, size_t size, int width, int height,
                                             const std::string& pixel_format)>;
void SetFakeCameraPainter(FakeCameraPainter painter);

}  // namespace softsight
