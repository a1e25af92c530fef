// Test code only: a BGR picture as a GenICam camera sends it (Mono8, RGB8, BGR8, or one of the
// four 8-bit Bayer layouts), for the painter of Aravis' simulated camera (io/aravis_camera.h).
#pragma once

#include <string>

#include <opencv2/imgproc.hpp>

namespace softsight::testing {

// GenICam names a Bayer layout by its first row: BayerRG8 is R G / G B.
inline cv::Mat AsSentByCamera(const cv::Mat& bgr, const std::string& format) {
  cv::Mat sent;
  if (format == "Mono8") {
    cv::cvtColor(bgr, sent, cv::COLOR_BGR2GRAY);
  } else if (format == "RGB8") {
    cv::cvtColor(bgr, sent, cv::COLOR_BGR2RGB);
  } else if (format == "BGR8") {
    sent = bgr.clone();
  } else {
    // The channel (B 0, G 1, R 2) under each pixel of the 2x2 tile.
    const std::string layout = format.substr(5, 2);
    const int rg[2][2] = {{2, 1}, {1, 0}}, bg[2][2] = {{0, 1}, {1, 2}},
              gb[2][2] = {{1, 0}, {2, 1}}, gr[2][2] = {{1, 2}, {0, 1}};
    const auto& tile = layout == "RG" ? rg : layout == "BG" ? bg : layout == "GB" ? gb : gr;
    sent.create(bgr.size(), CV_8UC1);
    for (int y = 0; y < bgr.rows; ++y) {
      for (int x = 0; x < bgr.cols; ++x) {
        sent.at<uint8_t>(y, x) = bgr.at<cv::Vec3b>(y, x)[tile[y % 2][x % 2]];
      }
    }
  }
  return sent;
}

}  // namespace softsight::testing
