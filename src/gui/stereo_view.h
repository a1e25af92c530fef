// Drawing of the stereo window (`track-stereo --window`): the two views side by side, each with
// its camera's overlay (gui/overlay.h: rings where the view found a marker; a marker not found
// in 3D crossed out in red with why), the pair's status lines in a band under them
// (gui/live_view.h), and a strip chart of the 3D angle beside each camera's own and of the
// out-of-plane angle (gui/strip_chart.h), laid out as the live window is (gui/live_layout.h).
// Drawing only, no window: the window (gui/stereo_window.h) shows the canvas. Internal to gui.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gui/live_layout.h"
#include "gui/overlay.h"
#include "gui/strip_chart.h"
#include "softsight/config/config.h"
#include "softsight/io/stereo_input.h"
#include "softsight/pipeline/stereo_session.h"

namespace softsight {

struct StereoViewOptions {
  StripChartOptions chart;
  // The largest canvas (the screen's, less its margins: MaxCanvasForScreen); the views are
  // scaled down (never up) to fit. Empty: no limit.
  cv::Size max_canvas;
};

class StereoView {
 public:
  enum Side { kLeft = 0, kRight = 1 };

  explicit StereoView(StereoViewOptions options = {});

  // Which markers each view's triangle joins (each config's measure).
  void set_configs(const TrackingConfig& left, const TrackingConfig& right);
  // The pair's angles into the chart: the 3D angle with each camera's own, the out-of-plane
  // angle. Once per pair.
  void add(const StereoFrameResult& result);
  // Draws the canvas (reusing its buffers) for the pair and returns it: both frames with their
  // view's overlay, `state` (e.g. "PAUSED") and the pair's status in the band, the chart.
  const cv::Mat& compose(const FramePair& pair, const StereoFrameResult& result,
                         const FrameResult& left, const FrameResult& right,
                         const std::string& state);
  const cv::Mat& canvas() const { return canvas_; }

  // Of the last compose(): the layout (its `image` holds both views) and where each view is.
  const LiveLayout& layout() const { return layout_; }
  const cv::Rect& view_rect(Side side) const { return views_[side]; }
  const StripChart& chart() const { return chart_; }

  // The chart's curves, in StripChart::newest's numbering.
  enum Curve { kAngle3d = 0, kAngleLeft = 1, kAngleRight = 2, kOutOfPlane = 3 };

 private:
  void draw_view(Side side, const Frame& frame, const FrameResult& view,
                 const StereoFrameResult& result);

  StereoViewOptions options_;
  std::array<OverlayOptions, 2> overlay_;
  StripChart chart_;
  LiveLayout layout_;
  std::array<cv::Rect, 2> views_;
  cv::Mat canvas_;
  std::array<cv::Mat, 2> annotated_;  // A view drawn at full size before scaling down.
  OverlayStatus status_;              // Reused: its `refused` per view.
  std::vector<std::string> lines_;
};

// The pair's status lines under the views: the 3D measurements, then each camera's own angle
// and the markers not found in 3D with why.
void StereoStatusLines(const StereoFrameResult& result, std::vector<std::string>& lines);

}  // namespace softsight
