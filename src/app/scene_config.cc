#include "app/scene_config.h"

#include <opencv2/imgproc.hpp>

namespace softsight {

ColourParams ThresholdsFor(const cv::Vec3b& bgr) {
  cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar(bgr[0], bgr[1], bgr[2])), hsv;
  cv::cvtColor(pixel, hsv, cv::COLOR_BGR2HSV);
  const int hue = hsv.at<cv::Vec3b>(0, 0)[0];
  ColourParams params;
  params.h = HsvRange::HueAround(hue, 12);
  params.s = {80, 255};
  params.v = {40, 255};
  params.filter = ColourParams::Filter::kNone;
  return params;
}

}  // namespace softsight
