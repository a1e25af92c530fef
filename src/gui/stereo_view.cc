#include "gui/stereo_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "gui/live_view.h"  // StatusBandHeight, DrawStatusLines

namespace softsight {
namespace {

// The chart's curves: the 3D angle on top in the angle lane's colour, each camera's own dimmer.
const cv::Scalar kLeftAngle(150, 150, 150), kRightAngle(90, 170, 210);
const cv::Scalar kOutOfPlane(80, 200, 255);
const cv::Scalar kBand(28, 28, 28);

std::vector<StripChart::LaneSpec> StereoLanes() {
  return {{"angle", "deg",
           {{"3D", StripChart::kColours[0]}, {"left", kLeftAngle}, {"right", kRightAngle}},
           false},
          {"out of plane", "deg", {{"", kOutOfPlane}}, false}};
}

void Append(std::string& line, const char* label, const std::optional<double>& value,
            const char* unit) {
  char number[48];
  if (value) {
    std::snprintf(number, sizeof(number), "%s %.1f%s", label, *value, unit);
  } else {
    std::snprintf(number, sizeof(number), "%s --", label);
  }
  if (!line.empty()) line += "  ";
  line += number;
}

}  // namespace

StereoView::StereoView(StereoViewOptions options)
    : options_(options), chart_(options.chart, StereoLanes()) {
  for (OverlayOptions& overlay : overlay_) overlay.show_measurements = false;
}

void StereoView::set_configs(const TrackingConfig& left, const TrackingConfig& right) {
  overlay_[kLeft] = OverlayOptionsFor(left.measure);
  overlay_[kRight] = OverlayOptionsFor(right.measure);
  for (OverlayOptions& overlay : overlay_) overlay.show_measurements = false;
}

void StereoView::add(const StereoFrameResult& result) {
  chart_.add(result.time_s, {result.shape.angle_deg, result.left_angle_deg, result.right_angle_deg,
                             result.shape.out_of_plane_deg});
}

void StereoStatusLines(const StereoFrameResult& result, std::vector<std::string>& lines) {
  std::string line = "3D:";
  const Shape3d& shape = result.shape;
  Append(line, "angle", shape.angle_deg, " deg");
  Append(line, "out of plane", shape.out_of_plane_deg, " deg");
  Append(line, "radius", shape.radius, " mm");
  Append(line, "arc", shape.arc_length, " mm");
  Append(line, "tip", shape.tip_disp, " mm");
  lines.push_back(line);
  line = "each camera:";
  Append(line, "left", result.left_angle_deg, " deg");
  Append(line, "right", result.right_angle_deg, " deg");
  std::string missing;
  for (const StereoMarkerResult& m : result.markers) {
    if (!m.point.found()) missing += (missing.empty() ? "" : ", ") + m.name + " (" + m.status + ")";
  }
  if (!missing.empty()) line += "  not in 3D: " + missing;
  lines.push_back(line);
}

void StereoView::draw_view(Side side, const Frame& frame, const FrameResult& view,
                           const StereoFrameResult& result) {
  // A marker this view found that is not found in 3D is crossed out, with why.
  status_.refused.assign(view.markers.size(), std::string());
  for (size_t i = 0; i < view.markers.size(); ++i) {
    for (const StereoMarkerResult& m : result.markers) {
      if (m.name == view.markers[i].name && !m.point.found()) status_.refused[i] = m.status;
    }
  }
  cv::Mat shown = canvas_(views_[side]);
  const cv::Mat& image = frame.image;
  cv::Mat* target = &shown;
  if (shown.size() != image.size() || image.type() != CV_8UC3) {
    target = &annotated_[side];  // Drawn at full size, then scaled down.
  }
  if (image.type() == CV_8UC3) {
    image.copyTo(*target);
  } else {
    cv::cvtColor(image, *target, cv::COLOR_GRAY2BGR);
  }
  DrawOverlay(*target, view, overlay_[side], status_);
  const char* name = side == kLeft ? "left" : "right";
  char label[64];
  std::snprintf(label, sizeof(label), "%s  frame %lld", name, static_cast<long long>(frame.index));
  const double scale = std::max(0.45, target->cols / 640.0 * 0.5);
  const cv::Point at(8, cvRound(24 * scale / 0.5));
  cv::putText(*target, label, at, kGuiFont, scale, cv::Scalar(0, 0, 0), 4, cv::LINE_AA);
  cv::putText(*target, label, at, kGuiFont, scale, overlay_colour::kText, 1, cv::LINE_AA);
  if (target != &shown) cv::resize(*target, shown, shown.size(), 0, 0, cv::INTER_AREA);
}

const cv::Mat& StereoView::compose(const FramePair& pair, const StereoFrameResult& result,
                                   const FrameResult& left, const FrameResult& right,
                                   const std::string& state) {
  const cv::Size l = pair.left.image.size(), r = pair.right.image.size();
  const cv::Size both(l.width + r.width, std::max(l.height, r.height));
  if (layout_.image_px != both || canvas_.empty()) {
    layout_ = ComputeLiveLayout(both, options_.chart.height_px, 0, options_.max_canvas,
                                StatusBandHeight());
    const double scale = static_cast<double>(layout_.image.width) / both.width;
    const int left_width = std::min(layout_.image.width, cvRound(l.width * scale));
    views_[kLeft] = cv::Rect(layout_.image.x, layout_.image.y, left_width,
                             std::min(layout_.image.height, cvRound(l.height * scale)));
    views_[kRight] = cv::Rect(layout_.image.x + left_width, layout_.image.y,
                              layout_.image.width - left_width,
                              std::min(layout_.image.height, cvRound(r.height * scale)));
    canvas_.create(layout_.canvas, CV_8UC3);
    canvas_.setTo(cv::Scalar(0, 0, 0));
  }
  draw_view(kLeft, pair.left, left, result);
  draw_view(kRight, pair.right, right, result);
  lines_.clear();
  std::string first = state;
  char text[96];
  std::snprintf(text, sizeof(text), "%sframe %lld / %lld  %.3f s", state.empty() ? "" : "  ",
                static_cast<long long>(result.frame_index),
                static_cast<long long>(result.right_frame_index), result.time_s);
  first += text;
  if (result.pair_dt_ms) {
    std::snprintf(text, sizeof(text), "  pair dt %.1f ms", *result.pair_dt_ms);
    first += text;
  }
  std::snprintf(text, sizeof(text), "  proc %.1f ms", result.proc_ms);
  first += text;
  lines_.push_back(first);
  StereoStatusLines(result, lines_);
  cv::Mat band = canvas_(layout_.status);
  band.setTo(kBand);
  DrawStatusLines(band, lines_, false, kStatusRows);
  cv::Mat bottom = canvas_(layout_.chart);
  chart_.draw(bottom);
  return canvas_;
}

}  // namespace softsight
