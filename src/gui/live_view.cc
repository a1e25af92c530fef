#include "gui/live_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "gui/live_controller.h"
#include "gui/overlay.h"
#include "gui/range_edit.h"

#include "softsight/core/format.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {
namespace {

constexpr int kStatusOutline = 4;  // The dark outline under the status lines' text, px.
const cv::Scalar kDragColour(0, 255, 0);
const cv::Scalar kScaleColour(255, 255, 0);  // Cyan: unlike any overlay colour.
// Mask view: the chosen blob, blobs that fit but were not chosen, rejected ones, the window.
const cv::Scalar kMaskChosenColour(0, 255, 0), kMaskFitsColour(0, 255, 255);
const cv::Scalar kMaskRejectedColour(60, 60, 255), kMaskWindowColour(255, 255, 0);

}  // namespace

static void ShowImage(const cv::Mat& image, const LiveLayout& view, cv::Mat& top) {
  if (view.zoom.zoom == 1.0 && top.size() == image.size()) {
    image.copyTo(top);
  } else if (view.zoom.zoom == 1.0) {
    cv::resize(image, top, top.size(), 0, 0, cv::INTER_AREA);
  } else {
    // Zoomed: the part shown, through the layout's own mapping (clicks map back through it).
    // Enlarged pixels stay square blocks, so each one can be told apart and clicked.
    cv::warpAffine(image, top, cv::Mat(view.view_from_image()), top.size(),
                   view.scale_x() >= 1.0 ? cv::INTER_NEAREST : cv::INTER_LINEAR,
                   cv::BORDER_CONSTANT);
  }
}

const cv::Mat& LiveView::compose(const LiveLayout& view, const LiveViewState& state) {
  canvas_.create(view.canvas, CV_8UC3);
  cv::Mat top = canvas_(view.image);
  const cv::Mat& annotated = *state.annotated;
  if (annotated.empty()) {
    top.setTo(cv::Scalar(0, 0, 0));
    cv::putText(top, "waiting for frames...", {20, 40}, kGuiFont, 0.7, cv::Scalar(255, 255, 255), 1,
                cv::LINE_AA);
  } else if (state.mask_view) {
    draw_mask_view(top, view, state);
  } else {
    // Overlay status lines (recording, pause) live on the canvas only, not in recorded video.
    ShowImage(annotated, view, top);
  }
  std::vector<std::string> lines = state.lines;
  if (!lines.empty() && (view.image.size() != view.image_px || view.zoom.zoom != 1.0)) {
    lines.front() += (view.zoom.zoom != 1.0 ? "  zoom " : "  view ") +
                     std::to_string(cvRound(100 * view.scale_x())) + "%";
  }
  if (!view.status.empty()) {
    cv::Mat band = canvas_(view.status);
    band.setTo(cv::Scalar(28, 28, 28));
    DrawStatusLines(band, lines, state.recording, kStatusRows);
  } else {
    DrawStatusLines(top, lines, state.recording);
  }
  if (state.scale_mode) {
    for (const cv::Point2d& clicked : state.scale_points) {
      const cv::Point2d p = view.to_view(clicked);
      cv::drawMarker(top, cv::Point(cvRound(p.x), cvRound(p.y)), kScaleColour, cv::MARKER_CROSS,
                     15, 1, cv::LINE_AA);
    }
    if (state.scale_points.size() == 1 && state.pointer) {
      // The line from the first point to the pointer.
      const cv::Point2d a = view.to_view(state.scale_points[0]), b = view.to_view(*state.pointer);
      cv::line(top, cv::Point(cvRound(a.x), cvRound(a.y)), cv::Point(cvRound(b.x), cvRound(b.y)),
               kScaleColour, 1, cv::LINE_AA);
    }
  } else if (state.press && state.pointer) {
    const cv::Point2d a = view.to_view(*state.press);
    const cv::Point2d b = view.to_view(*state.pointer);
    cv::rectangle(top, cv::Point(cvRound(a.x), cvRound(a.y)), cv::Point(cvRound(b.x), cvRound(b.y)),
                  kDragColour, 1);
  }
  if (state.timeline && !view.timeline.empty()) {
    cv::Mat bar = canvas_(view.timeline);
    state.timeline->draw(bar);
  }
  cv::Mat bottom = canvas_(view.chart);
  state.chart->draw(bottom);
  if (!view.help.empty()) {
    cv::Mat panel = canvas_(view.help);
    DrawHelpPanel(panel);
  }
  return canvas_;
}

void LiveView::draw_mask_view(cv::Mat& top, const LiveLayout& view, const LiveViewState& state) {
  // The active marker's member pixels in their own colours, everything else dimmed to a quarter:
  // what the ranges take in, on the frame on screen.
  const Tracker& tracker = *state.tracker;
  const cv::Mat& frame = *state.frame;
  const bool has_mask = tracker.membership(frame, mask_);
  frame.convertTo(mask_image_, -1, 0.25, 0);
  if (has_mask) frame.copyTo(mask_image_, mask_);
  ShowImage(mask_image_, view, top);
  const double scale = view.scale_x();
  const double text = std::max(0.4, top.cols / 640.0 * 0.45);
  if (const std::optional<cv::Rect> region = tracker.search_region()) {
    const cv::Point2d a = view.to_view(cv::Point2d(region->tl()) - cv::Point2d(0.5, 0.5));
    const cv::Point2d b = view.to_view(cv::Point2d(region->br()) - cv::Point2d(0.5, 0.5));
    cv::rectangle(top, cv::Point(cvRound(a.x), cvRound(a.y)), cv::Point(cvRound(b.x), cvRound(b.y)),
                  kMaskWindowColour, 1);
    cv::putText(top, "searched", {cvRound(a.x) + 3, cvRound(b.y) - 4}, kGuiFont, text * 0.8,
                kMaskWindowColour, 1, cv::LINE_AA);
  }
  // Each candidate blob: a circle of its area, green chosen, yellow fitting, red rejected, with
  // the verdict and what it was judged on.
  for (const MarkerCandidate& c : tracker.candidates()) {
    const cv::Point2d at = view.to_view(c.position_px);
    const int radius = std::max(4, cvRound(std::sqrt(c.area_px / CV_PI) * scale) + 3);
    const cv::Scalar colour = c.verdict == CandidateVerdict::kChosen ? kMaskChosenColour
                              : c.verdict == CandidateVerdict::kFits ? kMaskFitsColour
                                                                     : kMaskRejectedColour;
    cv::circle(top, cv::Point(cvRound(at.x), cvRound(at.y)), radius, colour, 1, cv::LINE_AA);
    const std::string label = std::string(CandidateVerdictName(c.verdict)) + " " +
                              FixedNumber(c.area_px, 0) + " px2 circ " + FixedNumber(c.circularity, 2) +
                              " misfit " + FixedNumber(c.misfit, 2);
    const cv::Point origin(cvRound(at.x) + radius + 3, cvRound(at.y) + 4);
    cv::putText(top, label, origin, kGuiFont, text * 0.8, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(top, label, origin, kGuiFont, text * 0.8, colour, 1, cv::LINE_AA);
  }
  const auto* c = state.active->params.get_if<ColourParams>();  // A mask is a colour's.
  const std::string title =
      "MASK " + state.active->name +
      (has_mask && c ? ": h " + RangeText(c->h) + " s " + RangeText(c->s) + " v " + RangeText(c->v)
                     : ": " + TrackerMethodName(state.active->params) + " has no colour mask");
  cv::putText(top, title, {8, 22}, kGuiFont, text, cv::Scalar(0, 0, 0), 4, cv::LINE_AA);
  cv::putText(top, title, {8, 22}, kGuiFont, text, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
}


// One size at every image size: the band's height is fixed.
constexpr double kStatusTextScale = 0.45;

int StatusBandHeight() {
  int baseline = 0;
  const int height = cv::getTextSize("Ag", kGuiFont, kStatusTextScale, kStatusOutline, &baseline).height;
  return kStatusRows * (height + baseline + 4) + 4;
}

std::vector<std::string> WrapStatusLines(const std::vector<std::string>& lines, int width_px,
                                         double text_scale, size_t* first_rows) {
  std::vector<std::string> rows;
  const int room = std::max(1, width_px - 16);  // 8 px margins.
  const auto width_of = [text_scale](const std::string& text) {
    int baseline = 0;
    return cv::getTextSize(text, kGuiFont, text_scale, 1, &baseline).width + kStatusOutline;
  };
  for (size_t i = 0; i < lines.size(); ++i) {
    const size_t before = rows.size();
    std::string row;
    size_t start = 0;
    const std::string& line = lines[i];
    while (start <= line.size()) {
      size_t end = line.find(' ', start);
      if (end == std::string::npos) end = line.size();
      const std::string word = line.substr(start, end - start);
      const std::string joined = row.empty() ? word : row + " " + word;
      if (!row.empty() && width_of(joined) > room) {
        rows.push_back(row);
        row = word;
      } else {
        row = joined;
      }
      start = end + 1;
    }
    rows.push_back(row);
    if (i == 0 && first_rows) *first_rows = rows.size() - before;
  }
  return rows;
}

std::vector<cv::Point> PlaceStatusLines(cv::Size size, size_t count, double* text_scale) {
  const double scale = kStatusTextScale;
  *text_scale = scale;
  int baseline = 0;
  const int height = cv::getTextSize("Ag", kGuiFont, scale, kStatusOutline, &baseline).height;
  const int row_height = height + baseline + 4;  // Outlined rows never touch.
  std::vector<cv::Point> origins;
  int y = size.height - baseline - 4 - row_height * (static_cast<int>(count) - 1);
  for (size_t i = 0; i < count; ++i, y += row_height) origins.emplace_back(8, y);
  return origins;
}

void DrawStatusLines(cv::Mat& top, const std::vector<std::string>& lines, bool first_red,
                     size_t max_rows) {
  size_t red_rows = 0;
  std::vector<std::string> rows = WrapStatusLines(lines, top.cols, kStatusTextScale, &red_rows);
  if (max_rows > 0 && rows.size() > max_rows) {
    rows.resize(max_rows);
    rows.back() += " ...";
  }
  double scale = 1;
  const std::vector<cv::Point> origins = PlaceStatusLines(top.size(), rows.size(), &scale);
  for (size_t i = 0; i < rows.size(); ++i) {
    cv::putText(top, rows[i], origins[i], kGuiFont, scale, cv::Scalar(0, 0, 0), kStatusOutline,
                cv::LINE_AA);
    cv::putText(top, rows[i], origins[i], kGuiFont, scale,
                first_red && i < red_rows ? cv::Scalar(80, 80, 255) : cv::Scalar(255, 255, 255),
                1, cv::LINE_AA);
  }
}

namespace {

constexpr double kHelpScale = 0.42;
constexpr int kHelpLine = 17;    // px between lines at kHelpScale.
constexpr int kHelpKeyColumn = 58;  // px for the key names at kHelpScale.
constexpr int kHelpMargin = 8;

std::string KeyName(int key) {
  switch (key) {
    case 0:
      return "mouse";
    case ' ':
      return "space";
    default:
      return std::string(1, static_cast<char>(key));
  }
}

}  // namespace

int HelpPanelWidth() {
  int width = 0, baseline = 0;
  for (const LiveKey& k : kLiveKeys) {
    width = std::max(width, cv::getTextSize(k.what, kGuiFont, kHelpScale, 1, &baseline).width);
  }
  return 2 * kHelpMargin + kHelpKeyColumn + width;
}

void DrawHelpPanel(cv::Mat& panel) {
  panel.setTo(cv::Scalar(24, 24, 24));
  const int lines = static_cast<int>(kLiveKeys.size()) + 1;
  // Shrink the text when the panel is lower than the list (a small frame on a small screen).
  const double fit = std::min(1.0, (panel.rows - 2.0 * kHelpMargin) / (kHelpLine * lines));
  const double scale = kHelpScale * fit;
  const int line = std::max(6, cvRound(kHelpLine * fit));
  int y = kHelpMargin + line;
  cv::putText(panel, "keys (h hides)", {kHelpMargin, y}, kGuiFont, scale, cv::Scalar(120, 220, 255), 1,
              cv::LINE_AA);
  for (const LiveKey& k : kLiveKeys) {
    y += line;
    cv::putText(panel, KeyName(k.key), {kHelpMargin, y}, kGuiFont, scale, cv::Scalar(120, 220, 255),
                1, cv::LINE_AA);
    cv::putText(panel, k.what, {kHelpMargin + cvRound(kHelpKeyColumn * fit), y}, kGuiFont, scale,
                cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
  }
}

}  // namespace softsight
