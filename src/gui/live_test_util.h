// What the live window's tests share (live_controller_test.cc drives the controller, 
// live_window_test.cc the real window under Xvfb): the rendered three-marker scene and its
// config, the video of it, the overlay's ring as the tests find it, and CSV rows without timings.
#pragma once

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <yaml-cpp/yaml.h>

#include "softsight/config/config.h"
#include "softsight/io/frame_writer.h"
#include "softsight/sim/scene.h"

namespace softsight::testing {

// A 320x240 actuator with red (base), blue and green (tip) markers 8 px in radius.
inline SceneOptions LiveTestScene(int frame_count, double max_bend_deg) {
  SceneOptions scene;
  scene.size = cv::Size(320, 240);
  scene.length_px = 160;
  scene.width_px = 24;
  scene.marker_radius_px = 8;
  scene.frame_count = frame_count;
  scene.max_bend_deg = max_bend_deg;
  return scene;
}

// The same actuator at 1280x720 (markers 18 px in radius), taller than a laptop's screen with
// the chart under it.
inline SceneOptions LiveTest720pScene(int frame_count) {
  SceneOptions scene;
  scene.size = cv::Size(1280, 720);
  scene.length_px = 480;
  scene.width_px = 60;
  scene.marker_radius_px = 18;
  scene.frame_count = frame_count;
  return scene;
}

// The scene's markers by hue, and the triple.
inline constexpr const char* kLiveTestMarkersYaml =
    "markers:\n"
    "  - name: red\n    hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}\n"
    "  - name: blue\n    hsv: {h: [95, 125], s: [80, 255], v: [40, 255]}\n"
    "  - name: green\n    hsv: {h: [45, 75], s: [80, 255], v: [40, 255]}\n"
    "triple: [red, blue, green]\n";

inline TrackingConfig LiveTestConfig() {
  return ReadTrackingConfig(YAML::Load(kLiveTestMarkersYaml), "test config");
}

// Frames 0..frames-1 of `scene` as a lossless 30 fps video at `path`; their truth in `truth`
// when given.
inline void WriteSceneVideo(SyntheticScene& scene, int frames, const std::string& path,
                            std::vector<SceneTruth>* truth = nullptr) {
  FrameWriterOptions options;
  options.path = path;
  options.fps = 30.0;
  FrameWriter writer(options);
  cv::Mat image;
  for (int i = 0; i < frames; ++i) {
    SceneTruth t = scene.render(i, image);
    writer.write(image, i);
    if (truth) truth->push_back(std::move(t));
  }
  writer.close();
}

// How many of 24 points on a circle of `radius` around `centre` have a pixel of the overlay's
// yellow ring (overlay_colour::kMarker) within one pixel.
inline int RingPoints(const cv::Mat& image, const cv::Point2d& centre, double radius = 12) {
  int ring = 0;
  for (int deg = 0; deg < 360; deg += 15) {
    const cv::Point p(cvRound(centre.x + radius * std::cos(deg * CV_PI / 180)),
                      cvRound(centre.y + radius * std::sin(deg * CV_PI / 180)));
    bool yellow = false;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const cv::Point q = p + cv::Point(dx, dy);
        if (q.x < 0 || q.y < 0 || q.x >= image.cols || q.y >= image.rows) continue;
        const cv::Vec3b px = image.at<cv::Vec3b>(q);
        yellow |= px[0] < 80 && px[1] > 200 && px[2] > 200;
      }
    }
    ring += yellow;
  }
  return ring;
}

// The lines of a CSV without its timing columns (they differ from run to run): the timings end
// every row (latency_result_ms, latency_row_ms, proc_ms).
inline std::vector<std::string> CsvRowsWithoutTiming(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);) {
    for (int timing = 0; timing < 3; ++timing) line.erase(line.rfind(','));
    rows.push_back(line);
  }
  return rows;
}

}  // namespace softsight::testing
