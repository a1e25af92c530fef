#include "gui/live_layout.h"

#include <algorithm>
#include <cmath>

namespace softsight {

cv::Point2d LiveLayout::to_image(const cv::Point2d& view) const {
  return {(view.x - image.x + 0.5) / scale_x() - 0.5, (view.y - image.y + 0.5) / scale_y() - 0.5};
}

cv::Point2d LiveLayout::to_view(const cv::Point2d& p) const {
  return {(p.x + 0.5) * scale_x() - 0.5 + image.x, (p.y + 0.5) * scale_y() - 0.5 + image.y};
}

cv::Size MaxCanvasForScreen(cv::Size screen_px) {
  return {std::max(160, screen_px.width - kScreenMarginWidthPx),
          std::max(160, screen_px.height - kScreenMarginHeightPx)};
}

LiveLayout ComputeLiveLayout(cv::Size image_px, int chart_height_px, int help_width_px,
                             cv::Size max_canvas) {
  LiveLayout layout;
  layout.image_px = image_px;
  int chart_height = chart_height_px;
  double scale = 1.0;
  const bool fits = image_px.width + help_width_px <= max_canvas.width &&
                    image_px.height + chart_height_px <= max_canvas.height;
  if (max_canvas.width > 0 && max_canvas.height > 0 && !fits) {
    chart_height = std::min(chart_height_px, std::max(60, max_canvas.height / 4));
    const double room_w = std::max(1, max_canvas.width - help_width_px);
    const double room_h = std::max(1, max_canvas.height - chart_height);
    scale = std::min({1.0, room_w / image_px.width, room_h / image_px.height});
    scale = std::max(scale, 0.05);  // A tiny screen: at least something to click on.
  }
  const cv::Size shown(std::max(1, static_cast<int>(std::floor(image_px.width * scale))),
                       std::max(1, static_cast<int>(std::floor(image_px.height * scale))));
  layout.image = cv::Rect(cv::Point(0, 0), shown);
  layout.chart = cv::Rect(0, shown.height, shown.width, chart_height);
  if (help_width_px > 0) layout.help = cv::Rect(shown.width, 0, help_width_px, shown.height + chart_height);
  layout.canvas = cv::Size(shown.width + std::max(0, help_width_px), shown.height + chart_height);
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
