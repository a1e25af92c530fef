// ViSP's vpDot2 over preloaded gray frames, for softsight_vpdot2_compare (vpdot2_compare.cc).
// ViSP 3.5's headers do not compile as C++20, so they stay in vpdot2_runner.cc (C++17); this
// header names no ViSP type.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

class Dot2Sequence {
 public:
  // The frames (8-bit gray) copied once into ViSP's images, before any timing.
  explicit Dot2Sequence(const std::vector<cv::Mat>& gray);
  ~Dot2Sequence();
  Dot2Sequence(const Dot2Sequence&) = delete;
  Dot2Sequence& operator=(const Dot2Sequence&) = delete;

  // One pass of fresh vpDot2 trackers, set up as the mire-2 reference was made (dot2ref.cpp:
  // moments on, gray-level precision 0.9), dot k started on the first frame at starts[k]; a dot
  // whose track() throws is lost for good. Per frame: its time in ms (the first frame's includes
  // initTracking) and each dot's centre of gravity (x right, y down), none once lost.
  void run(const std::vector<cv::Point2d>& starts, std::vector<double>& ms,
           std::vector<std::vector<std::optional<cv::Point2d>>>& found) const;

 private:
  struct Images;
  std::unique_ptr<Images> images_;
};

}  // namespace softsight
