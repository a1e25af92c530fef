// Internal to gui (and the tests). Where the parts of the live window go, and how its pixels map
// to the image's: the image scaled down (never up) so that the whole window fits the screen,
// the strip chart under it, and the help panel, when shown, to the right of both, so the help
// never covers a marker. The controller composes the canvas with it and maps mouse positions
// back to image pixels with it.
#pragma once

#include <opencv2/core.hpp>

namespace softsight {

struct LiveLayout {
  cv::Size image_px;  // The frame's own size.
  cv::Rect image;     // Where the (scaled) frame is in the canvas.
  cv::Rect chart;     // The strip chart, under the image, as wide as it.
  cv::Rect help;      // The help panel right of image and chart; empty when hidden.
  cv::Size canvas;

  // View pixels per image pixel (1: not scaled).
  double scale_x() const { return static_cast<double>(image.width) / image_px.width; }
  double scale_y() const { return static_cast<double>(image.height) / image_px.height; }
  // A canvas position in image pixels (pixel centres map to pixel centres), and back.
  cv::Point2d to_image(const cv::Point2d& view) const;
  cv::Point2d to_view(const cv::Point2d& image_point) const;
};

// The window on the screen leaves room for what the window system adds: a title bar, a panel or
// taskbar, borders (px). A generous allowance for common desktops, not measured here: this
// machine has no window manager (Xvfb places the window at 0,0 without decorations).
inline constexpr int kScreenMarginWidthPx = 32, kScreenMarginHeightPx = 100;

// `max_canvas`: the largest canvas that fits (empty: no limit, nothing is scaled). The chart
// keeps `chart_height_px` unless the screen is small (at most a quarter of the height, at least
// 60 px); `help_width_px` 0 hides the help panel.
LiveLayout ComputeLiveLayout(cv::Size image_px, int chart_height_px, int help_width_px,
                             cv::Size max_canvas);

// The largest canvas for a screen of `screen_px` (the margins above taken off).
cv::Size MaxCanvasForScreen(cv::Size screen_px);

// Where the trackbar window's top-left corner goes, with the main window at the screen's
// top-left: right of the canvas when it fits there, else under it, else in the screen's
// bottom-right corner (away from the text block at the image's top-left). About the size six
// OpenCV trackbars take.
inline const cv::Size kTrackbarWindowPx{360, 280};
cv::Point TrackbarWindowPlace(cv::Size screen_px, cv::Size canvas_px);

}  // namespace softsight
