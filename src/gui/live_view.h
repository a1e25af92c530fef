// Drawing of the live window: the canvas composed of the annotated frame (or the mask view), the
// window's own layer over it (status lines, the drag box, the scale points), the strip chart
// under it and the key help beside it. Drawing only: the controller decides what to show and
// hands it over as a LiveViewState. Internal to gui.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gui/live_layout.h"
#include "gui/strip_chart.h"
#include "gui/timeline.h"
#include "softsight/core/format.h"
#include "softsight/track/tracker.h"

namespace softsight {

// What one canvas shows, read from the controller (pointers to its members, valid for the call).
struct LiveViewState {
  const cv::Mat* frame = nullptr;      // The frame on screen as captured (the mask view's base).
  const cv::Mat* annotated = nullptr;  // The frame with the overlay; empty: no frame yet.
  std::vector<std::string> lines;      // Status lines, the state line first.
  bool recording = false;              // The state line in red.
  bool mask_view = false;              // The active marker's mask instead of the annotated frame.
  const Tracker* tracker = nullptr;    // Mask view: the active marker's tracker ...
  const MarkerSpec* active = nullptr;  // ... and its spec (for the title).
  bool scale_mode = false;             // The scale points instead of the drag box.
  std::vector<cv::Point2d> scale_points;     // Image pixels.
  std::optional<cv::Point2d> press, pointer;  // The mouse, image pixels (drag box, scale line).
  const StripChart* chart = nullptr;
  const Timeline* timeline = nullptr;  // A file's scrub bar; null for a camera.
};

class LiveView {
 public:
  // Draws the canvas for `layout` (reusing its buffers) and returns it.
  const cv::Mat& compose(const LiveLayout& layout, const LiveViewState& state);
  const cv::Mat& canvas() const { return canvas_; }

 private:
  void draw_mask_view(cv::Mat& top, const LiveLayout& layout, const LiveViewState& state);
  cv::Mat canvas_, mask_, mask_image_;  // Reused buffers: no allocation per frame.
};

// The status band under the image: kStatusRows rows of text, on a dark ground. Under the image,
// not over it, so no message hides a marker at the image's bottom edge.
inline constexpr int kStatusRows = 3;
int StatusBandHeight();

// The lines at the bottom of `area` (the band, or the image when there is none), the first (the
// state line) in red when `first_red` (recording). A line wider than the area wraps at spaces
// onto rows of its own; beyond `max_rows` (0: no limit) the last row shown ends in "..." (every
// message is also on stdout).
void DrawStatusLines(cv::Mat& area, const std::vector<std::string>& lines, bool first_red,
                     size_t max_rows = 0);

// `lines` wrapped at spaces to rows at most `width_px` wide at `text_scale` (outlined, as drawn),
// and `first_rows` set to how many rows the first line took.
std::vector<std::string> WrapStatusLines(const std::vector<std::string>& lines, int width_px,
                                         double text_scale, size_t* first_rows = nullptr);

// Where DrawStatusLines puts its `count` lines on an image of `size` (putText's baseline
// origins): 8 px from the left, spaced by the outlined text's height at `text_scale`, the last at
// the image's bottom.
std::vector<cv::Point> PlaceStatusLines(cv::Size size, size_t count, double* text_scale);

// The key list (kLiveKeys) as a compact panel beside the image (never over it, so no marker is
// hidden): the width it needs, and the drawing into `panel` (text shrinks if it is too low).
int HelpPanelWidth();
void DrawHelpPanel(cv::Mat& panel);


}  // namespace softsight
