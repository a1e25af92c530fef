#include "app/scene_config.h"

#include <algorithm>
#include <numeric>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace softsight {

ColourParams ThresholdsFor(const cv::Vec3b& bgr) {
  cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar(bgr[0], bgr[1], bgr[2])), hsv;
  cv::cvtColor(pixel, hsv, cv::COLOR_BGR2HSV);
  const int hue = hsv.at<cv::Vec3b>(0, 0)[0];
  ColourParams params;
  params.h = {(hue + 180 - 12) % 180, (hue + 12) % 180};
  params.s = {80, 255};
  params.v = {40, 255};
  params.filter = ColourParams::Filter::kNone;
  return params;
}

MeasureOptions MeasureFor(const SceneOptions& scene) {
  std::vector<size_t> order(scene.markers.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return scene.markers[a].body_fraction < scene.markers[b].body_fraction;
  });
  MeasureOptions options;
  if (order.empty()) return options;
  options.base = scene.markers[order.front()].name;
  options.middle = scene.markers[order[order.size() / 2]].name;
  options.tip = scene.markers[order.back()].name;
  if (order.size() > 3) {
    for (size_t i : order) options.chain.push_back(scene.markers[i].name);
  }
  return options;
}

}  // namespace softsight
