// A scrolling strip chart of the last seconds: angle, bending distance, arc length and radius of
// curvature, one lane each, drawn under the live image. Keeps the recent samples; absent values are gaps. Internal
// to gui (and its tests).
#pragma once

#include <deque>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gui/live_options.h"  // StripChartOptions
#include "softsight/pipeline/tracking_session.h"

namespace softsight {

class StripChart {
 public:
  explicit StripChart(StripChartOptions options = {});

  // Appends a frame's measurements (mm when the frame has them, else px) and forgets samples
  // older than the window. Time going backwards (a new source) restarts the chart; the frame of
  // the newest sample measured again (a paused re-track) replaces it.
  void add(const FrameResult& result);
  void clear();

  // Draws into `area` (CV_8UC3, any size; usually width of the image x options.height_px).
  void draw(cv::Mat& area) const;

  // The lane rectangles and value ranges of the last draw(), for tests: lane 0 angle,
  // 1 bending distance, 2 arc length, 3 radius.
  struct Lane {
    cv::Rect rect;
    double y_min = 0, y_max = 1;
    std::string label;
    std::vector<cv::Rect> tick_labels;  // Where each value label's text went.
  };
  const Lane& lane(int i) const { return lanes_[i]; }
  // Horizontal pixel of time `time_s` in the last draw() (the newest sample at the right edge).
  double x_of(double time_s) const;

  size_t size() const { return samples_.size(); }
  // The newest sample's value in lane `i` (what its label reads), absent when not measured.
  std::optional<double> newest(int i) const {
    return samples_.empty() ? std::nullopt : samples_.back().values[i];
  }
  const StripChartOptions& options() const { return options_; }

  static constexpr int kLanes = 4;
  static const cv::Scalar kColours[kLanes];

 private:
  struct Sample {
    double time_s;
    std::optional<double> values[kLanes];
    bool metric;
  };
  StripChartOptions options_;
  std::deque<Sample> samples_;
  mutable Lane lanes_[kLanes];
  mutable double x_left_ = 0, x_width_ = 1, t_right_ = 0;
};

}  // namespace softsight
