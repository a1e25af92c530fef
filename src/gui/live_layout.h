// Internal to gui (and the tests). Where the parts of the live window go, and how its pixels map
// to the image's: the image scaled down (never up) so that the whole window fits the screen,
// the strip chart under it, and the help panel, when shown, to the right of both, so the help
// never covers a marker. The controller composes the canvas with it and maps mouse positions
// back to image pixels with it.
#pragma once

#include <opencv2/core.hpp>

namespace softsight {

// Zoom and pan: the part of the image the view shows. `zoom` 1 is the whole image; at zoom z
// the view shows 1/z of its width and height, from `origin_px` (the image point, pixel-edge
// coordinates, at the view's top-left corner).
struct ViewZoom {
  double zoom = 1.0;
  cv::Point2d origin_px{0.0, 0.0};

  static constexpr double kMax = 16.0;
  // Zoomed by `factor` (clamped to 1..kMax) so that image point `about_px` stays where it is on
  // screen, and kept inside an image of `image_px`.
  ViewZoom about(const cv::Point2d& about_px, double factor, cv::Size image_px) const;
  // Moved by `delta_px` image pixels, kept inside the image.
  ViewZoom panned(const cv::Point2d& delta_px, cv::Size image_px) const;
};

struct LiveLayout {
  cv::Size image_px;  // The frame's own size.
  cv::Rect image;     // Where the (scaled) frame is in the canvas.
  cv::Rect status;    // The status and message lines, under the image (never over a marker).
  cv::Rect timeline;  // The scrub bar under them, as wide as the image; empty for a camera.
  cv::Rect chart;     // The strip chart, under the timeline, as wide as the image.
  cv::Rect help;      // The help panel right of image and chart; empty when hidden.
  cv::Size canvas;
  ViewZoom zoom;      // The part of the image shown in `image`.

  // View pixels per image pixel (1: not scaled, not zoomed).
  double scale_x() const { return zoom.zoom * image.width / image_px.width; }
  double scale_y() const { return zoom.zoom * image.height / image_px.height; }
  // A canvas position in image pixels (pixel centres map to pixel centres), and back; through
  // the zoom, so a click on a zoomed view lands on the image pixel under it.
  cv::Point2d to_image(const cv::Point2d& view) const;
  cv::Point2d to_view(const cv::Point2d& image_point) const;
  // The 2x3 matrix from image to view pixels (cv::warpAffine), the same mapping as to_view
  // relative to `image`'s top-left corner.
  cv::Matx23d view_from_image() const;
};

// The scrub bar's height, px.
inline constexpr int kTimelineHeightPx = 18;

// The window on the screen leaves room for what the window system adds: a title bar, a panel or
// taskbar, borders (px). A generous allowance for common desktops, not measured here: this
// machine has no window manager (Xvfb places the window at 0,0 without decorations).
inline constexpr int kScreenMarginWidthPx = 32, kScreenMarginHeightPx = 100;

// `max_canvas`: the largest canvas that fits (empty: no limit, nothing is scaled). The chart
// keeps `chart_height_px` unless the screen is small (at most a quarter of the height, at least
// 60 px); `help_width_px` 0 hides the help panel.
// `status_height_px`: the band of status lines under the image (0: none, the lines go over the
// image); `timeline`: a scrub bar under it (a file: it can seek).
LiveLayout ComputeLiveLayout(cv::Size image_px, int chart_height_px, int help_width_px,
                             cv::Size max_canvas, int status_height_px = 0, bool timeline = false,
                             ViewZoom zoom = {});

// The largest canvas for a screen of `screen_px` (the margins above taken off).
cv::Size MaxCanvasForScreen(cv::Size screen_px);

// Where the trackbar window's top-left corner goes, with the main window at the screen's
// top-left: right of the canvas when it fits there, else under it, else in the screen's
// bottom-right corner (away from the text block at the image's top-left). About the size six
// OpenCV trackbars take.
inline const cv::Size kTrackbarWindowPx{360, 280};
cv::Point TrackbarWindowPlace(cv::Size screen_px, cv::Size canvas_px);

}  // namespace softsight
