#include "gui/live_layout.h"

#include <algorithm>
#include <cmath>

namespace softsight {

cv::Point2d LiveLayout::to_image(const cv::Point2d& view) const {
  return {(view.x - image.x + 0.5) / scale_x() + zoom.origin_px.x - 0.5,
          (view.y - image.y + 0.5) / scale_y() + zoom.origin_px.y - 0.5};
}

cv::Point2d LiveLayout::to_view(const cv::Point2d& p) const {
  return {(p.x + 0.5 - zoom.origin_px.x) * scale_x() - 0.5 + image.x,
          (p.y + 0.5 - zoom.origin_px.y) * scale_y() - 0.5 + image.y};
}

cv::Matx23d LiveLayout::view_from_image() const {
  const double sx = scale_x(), sy = scale_y();
  return {sx, 0.0, (0.5 - zoom.origin_px.x) * sx - 0.5, 0.0, sy, (0.5 - zoom.origin_px.y) * sy - 0.5};
}

namespace {

// Keeps the shown part, image_px / zoom, inside the image.
cv::Point2d ClampOrigin(const cv::Point2d& origin, double zoom, cv::Size image_px) {
  const double w = image_px.width / zoom, h = image_px.height / zoom;
  return {std::clamp(origin.x, 0.0, image_px.width - w), std::clamp(origin.y, 0.0, image_px.height - h)};
}

}  // namespace

ViewZoom ViewZoom::about(const cv::Point2d& about_px, double factor, cv::Size image_px) const {
  ViewZoom next;
  next.zoom = std::clamp(zoom * factor, 1.0, kMax);
  // The point's pixel-edge coordinate keeps its place: (a - origin) * zoom is constant.
  const cv::Point2d a(about_px.x + 0.5, about_px.y + 0.5);
  next.origin_px = ClampOrigin(a - (a - origin_px) * (zoom / next.zoom), next.zoom, image_px);
  return next;
}

ViewZoom ViewZoom::panned(const cv::Point2d& delta_px, cv::Size image_px) const {
  ViewZoom next = *this;
  next.origin_px = ClampOrigin(origin_px + delta_px, zoom, image_px);
  return next;
}

cv::Size MaxCanvasForScreen(cv::Size screen_px) {
  return {std::max(160, screen_px.width - kScreenMarginWidthPx),
          std::max(160, screen_px.height - kScreenMarginHeightPx)};
}

LiveLayout ComputeLiveLayout(cv::Size image_px, int chart_height_px, int help_width_px,
                             cv::Size max_canvas, int status_height_px, bool timeline,
                             ViewZoom zoom) {
  LiveLayout layout;
  layout.image_px = image_px;
  layout.zoom = zoom;
  const int timeline_height = timeline ? kTimelineHeightPx : 0;
  const int bands = std::max(0, status_height_px) + timeline_height;  // Fixed heights.
  int chart_height = chart_height_px;
  double scale = 1.0;
  const bool fits = image_px.width + help_width_px <= max_canvas.width &&
                    image_px.height + bands + chart_height_px <= max_canvas.height;
  if (max_canvas.width > 0 && max_canvas.height > 0 && !fits) {
    chart_height = std::min(chart_height_px, std::max(60, max_canvas.height / 4));
    const double room_w = std::max(1, max_canvas.width - help_width_px);
    const double room_h = std::max(1, max_canvas.height - chart_height - bands);
    scale = std::min({1.0, room_w / image_px.width, room_h / image_px.height});
    scale = std::max(scale, 0.05);  // A tiny screen: at least something to click on.
  }
  const cv::Size shown(std::max(1, static_cast<int>(std::floor(image_px.width * scale))),
                       std::max(1, static_cast<int>(std::floor(image_px.height * scale))));
  layout.image = cv::Rect(cv::Point(0, 0), shown);
  layout.status = cv::Rect(0, shown.height, status_height_px > 0 ? shown.width : 0,
                           std::max(0, status_height_px));
  layout.timeline = cv::Rect(0, layout.status.br().y, timeline ? shown.width : 0, timeline_height);
  layout.chart = cv::Rect(0, layout.status.br().y + timeline_height, shown.width, chart_height);
  const int bottom = layout.chart.br().y;
  if (help_width_px > 0) layout.help = cv::Rect(shown.width, 0, help_width_px, bottom);
  layout.canvas = cv::Size(shown.width + std::max(0, help_width_px), bottom);
  return layout;
}

cv::Point TrackbarWindowPlace(cv::Size screen_px, cv::Size canvas_px) {
  const cv::Size room(kTrackbarWindowPx.width + kScreenMarginWidthPx,
                      kTrackbarWindowPx.height + kScreenMarginHeightPx);
  if (canvas_px.width + room.width <= screen_px.width) {
    return {canvas_px.width + kScreenMarginWidthPx / 2, 0};
  }
  if (canvas_px.height + room.height <= screen_px.height) {
    return {0, canvas_px.height + kScreenMarginHeightPx / 2};
  }
  return {std::max(0, screen_px.width - room.width), std::max(0, screen_px.height - room.height)};
}

}  // namespace softsight
