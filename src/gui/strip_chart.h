// A scrolling strip chart of the last seconds, drawn under the live image: lanes of curves
// against time, each lane with its own value axis. The live window's chart has four lanes, one
// curve each (angle, bending distance, arc length, radius of curvature); the stereo window's
// has the 3D angle beside each camera's own angle, and the out-of-plane angle. Keeps the recent
// samples; absent values are gaps. Internal to gui (and its tests).
#pragma once

#include <array>
#include <deque>
#include <initializer_list>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gui/live_options.h"  // StripChartOptions
#include "softsight/pipeline/tracking_session.h"

namespace softsight {

class StripChart {
 public:
  // One curve: its name (beside its value in the lane's label, when the lane has more than one
  // curve) and colour.
  struct Series {
    std::string name;
    cv::Scalar colour;
  };
  // One lane: its name and unit ("angle", "deg"), and its curves on one shared value axis, the
  // first drawn on top. `length`: the unit is px, or mm when the newest sample is metric.
  struct LaneSpec {
    std::string name, unit;
    std::vector<Series> series;
    bool length = false;
  };
  static constexpr size_t kMaxSeries = 8;  // Curves of all lanes together.

  // The live window's chart: angle, bending distance, arc length and radius, one curve each.
  explicit StripChart(StripChartOptions options = {});
  // A chart of other lanes (at most kMaxSeries curves in all).
  StripChart(StripChartOptions options, std::vector<LaneSpec> lanes);

  // Appends a frame's measurements (mm when the frame has them, else px) to the live window's
  // four lanes.
  void add(const FrameResult& result);
  // Appends a sample: one value per curve, lane by lane, in the order of the lanes' series
  // (absent: a gap; missing at the end: absent). `metric`: lengths are in mm.
  // Either way, samples older than the window are forgotten; time going backwards (a new source)
  // restarts the chart; the newest sample's time measured again (a paused re-track) replaces it.
  void add(double time_s, std::initializer_list<std::optional<double>> values, bool metric = false);
  void clear();

  // Draws into `area` (CV_8UC3, any size; usually width of the image x options.height_px).
  void draw(cv::Mat& area) const;

  // The lane rectangles and value ranges of the last draw(), for tests: in the live window's
  // chart lane 0 angle, 1 bending distance, 2 arc length, 3 radius.
  struct Lane {
    cv::Rect rect;
    double y_min = 0, y_max = 1;
    std::string label;  // "name [unit]".
    std::vector<cv::Rect> tick_labels;  // Where each value label's text went.
  };
  const Lane& lane(int i) const { return lanes_[i]; }
  int lane_count() const { return static_cast<int>(specs_.size()); }
  // Horizontal pixel of time `time_s` in the last draw() (the newest sample at the right edge).
  double x_of(double time_s) const;
  // The vertical pixel of `value` in lane `i` in the last draw().
  double y_of(int i, double value) const;

  size_t size() const { return samples_.size(); }
  // The newest sample's value of curve `s` (counted over the lanes in order; in the live
  // window's chart the lane's index), absent when not measured.
  std::optional<double> newest(int s) const {
    return samples_.empty() ? std::nullopt : samples_.back().values[s];
  }
  const StripChartOptions& options() const { return options_; }

  // The live window's lanes' colours.
  static constexpr int kLanes = 4;
  static const cv::Scalar kColours[kLanes];

 private:
  struct Sample {
    double time_s;
    std::array<std::optional<double>, kMaxSeries> values;
    bool metric;
  };
  StripChartOptions options_;
  std::vector<LaneSpec> specs_;
  std::vector<int> first_series_;  // Per lane: its first curve's index in Sample::values.
  std::deque<Sample> samples_;
  mutable std::vector<Lane> lanes_;
  mutable double x_left_ = 0, x_width_ = 1, t_right_ = 0;
};

}  // namespace softsight
