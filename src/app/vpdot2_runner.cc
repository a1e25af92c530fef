#include "vpdot2_runner.h"

#include <algorithm>
#include <chrono>

#include <visp3/blob/vpDot2.h>
#include <visp3/core/vpImage.h>

namespace softsight {

struct Dot2Sequence::Images {
  std::vector<vpImage<unsigned char>> frames;
};

Dot2Sequence::Dot2Sequence(const std::vector<cv::Mat>& gray) : images_(std::make_unique<Images>()) {
  for (const cv::Mat& g : gray) {
    CV_Assert(g.type() == CV_8UC1);
    vpImage<unsigned char> image(static_cast<unsigned>(g.rows), static_cast<unsigned>(g.cols));
    for (int y = 0; y < g.rows; ++y) std::copy_n(g.ptr<unsigned char>(y), g.cols, image[y]);
    images_->frames.push_back(std::move(image));
  }
}

Dot2Sequence::~Dot2Sequence() = default;

void Dot2Sequence::run(const std::vector<cv::Point2d>& starts, std::vector<double>& ms,
                       std::vector<std::vector<std::optional<cv::Point2d>>>& found) const {
  using Clock = std::chrono::steady_clock;
  ms.clear();
  found.clear();
  std::vector<vpDot2> dots(starts.size());
  std::vector<bool> alive(starts.size(), true);
  const std::vector<vpImage<unsigned char>>& frames = images_->frames;
  for (size_t f = 0; f < frames.size(); ++f) {
    const Clock::time_point start = Clock::now();
    if (f == 0) {
      for (size_t k = 0; k < dots.size(); ++k) {
        dots[k].setGraphics(false);
        dots[k].setComputeMoments(true);
        dots[k].setGrayLevelPrecision(0.9);
        try {
          dots[k].initTracking(frames[f], vpImagePoint(starts[k].y, starts[k].x));
        } catch (...) {
          alive[k] = false;
        }
      }
    }
    std::vector<std::optional<cv::Point2d>> row(dots.size());
    for (size_t k = 0; k < dots.size(); ++k) {
      if (!alive[k]) continue;
      try {
        dots[k].track(frames[f]);
        const vpImagePoint c = dots[k].getCog();
        row[k] = cv::Point2d(c.get_u(), c.get_v());
      } catch (...) {
        alive[k] = false;
      }
    }
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    found.push_back(std::move(row));
  }
}

}  // namespace softsight
