#include "gui/overlay.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace softsight {

static_assert(kGuiFont == cv::FONT_HERSHEY_SIMPLEX);

namespace {

// A file shown at less than this fraction of its own speed is said to play slower than real time
// (a loaded machine, a large frame): its figures come from every frame, only later.
constexpr double kSlowPlaybackSpeed = 0.9;
// A radius of this many arc lengths or more reads "straight". The arc then turns by less than
// 1/25 rad (2.3 deg) and its sagitta is under 1/200 of its length (s = L^2 / 8R): 0.5 px on a
// 100 px actuator, only a few times the centroid noise (0.03-0.1 px). The radius's digits would
// be mostly that noise (a 0.06 px sagitta error is 12 % of R there), growing without bound as
// the actuator straightens ("84178 px"). The CSV keeps the number; this is what the eye reads.
constexpr double kStraightRadiusPerArcLength = 25.0;

cv::Point Fixed(const cv::Point2d& p) {
  return {cvRound(p.x * (1 << kSubPixelShift)), cvRound(p.y * (1 << kSubPixelShift))};
}

const std::optional<cv::Point2d>* Find(const FrameResult& result, const std::string& name) {
  for (const MarkerObservation& m : result.markers) {
    if (m.name == name) return &m.observation.position_px;
  }
  return nullptr;
}

std::string Value(const char* label, const std::optional<double>& value_mm,
                  const std::optional<double>& value_px, const char* format = "%.1f") {
  char number[32];
  std::string text = label;
  if (value_mm) {
    std::snprintf(number, sizeof(number), format, *value_mm);
    text += std::string(number) + " mm";
  } else if (value_px) {
    std::snprintf(number, sizeof(number), format, *value_px);
    text += std::string(number) + " px";
  } else {
    text += "--";
  }
  return text;
}

// One line of text with a dark outline so it stays readable on any background.
void OutlinedText(cv::Mat& image, const std::string& text, cv::Point origin, double scale,
                  const cv::Scalar& colour) {
  const int thickness = std::max(1, cvRound(scale * 2));
  cv::putText(image, text, origin, kGuiFont, scale, cv::Scalar(0, 0, 0), thickness + 2, cv::LINE_AA);
  cv::putText(image, text, origin, kGuiFont, scale, colour, thickness, cv::LINE_AA);
}

}  // namespace

bool ReadsStraight(const Measurement& m) {
  return m.radius_px && m.arc_length_px &&
         *m.radius_px >= kStraightRadiusPerArcLength * *m.arc_length_px;
}

bool OverlayOptions::Check(std::string* error) const {
  if (marker_ring_px < 2 || marker_ring_px > 200) {
    *error = "marker_ring_px must be in 2..200, got " + std::to_string(marker_ring_px);
    return false;
  }
  if (text_scale < 0 || text_scale > 10) {
    *error = "text_scale must be in 0..10 (0: automatic), got " + std::to_string(text_scale);
    return false;
  }
  return true;
}

OverlayOptions OverlayOptionsFor(const MeasureOptions& measure) {
  OverlayOptions options;
  options.base = measure.base;
  options.middle = measure.middle;
  options.tip = measure.tip;
  return options;
}

std::vector<cv::Point2d> ArcPoints(const cv::Point2d& base, const cv::Point2d& middle,
                                   const cv::Point2d& tip, double radius_px, int count) {
  std::vector<cv::Point2d> points;
  const cv::Point2d chord = tip - base;
  const double c = std::hypot(chord.x, chord.y);
  if (!(c > 0) || !(radius_px >= c / 2 * (1 - 1e-9)) || !std::isfinite(radius_px) || count < 2) {
    return points;
  }
  const cv::Point2d mid = (base + tip) * 0.5;
  cv::Point2d normal(-chord.y / c, chord.x / c);
  double sagitta = (middle - mid).dot(normal);
  if (sagitta < 0) {
    normal = -normal;
    sagitta = -sagitta;
  }
  if (sagitta == 0) return points;  // Collinear: no side to bend to.
  const double h = std::sqrt(std::max(0.0, radius_px * radius_px - c * c / 4));
  // Minor arc: the centre lies across the chord from the middle marker; major arc: on its side.
  const cv::Point2d centre = sagitta <= radius_px ? mid - normal * h : mid + normal * h;
  const double a_base = std::atan2(base.y - centre.y, base.x - centre.x);
  const double a_tip = std::atan2(tip.y - centre.y, tip.x - centre.x);
  double sweep = std::fmod(a_tip - a_base + 4 * CV_PI, 2 * CV_PI);  // Counter-clockwise, [0, 2pi).
  const double a_half = a_base + sweep / 2;
  const cv::Point2d halfway = centre + radius_px * cv::Point2d(std::cos(a_half), std::sin(a_half));
  if ((halfway - mid).dot(normal) < 0) sweep -= 2 * CV_PI;  // The other way round.
  points.reserve(count);
  for (int k = 0; k < count; ++k) {
    const double a = a_base + sweep * k / (count - 1);
    points.push_back(centre + radius_px * cv::Point2d(std::cos(a), std::sin(a)));
  }
  return points;
}

namespace {

// Why the marker at `index` was found but not believed; null when it was believed.
const std::string* RefusalOf(const OverlayStatus& status, size_t index) {
  return index < status.refused.size() && !status.refused[index].empty() ? &status.refused[index]
                                                                         : nullptr;
}

// The text block's lines: the frame, the measurements, the timing, the markers lost or not
// believed, the caller's notes.
std::vector<std::pair<std::string, cv::Scalar>> MeasurementLines(const FrameResult& result,
                                                                 const OverlayStatus& status) {
  const Measurement& m = result.measurement;
  std::string lost, refused;
  for (size_t i = 0; i < result.markers.size(); ++i) {
    const MarkerObservation& marker = result.markers[i];
    if (!marker.observation.found()) {
      lost += (lost.empty() ? "" : ", ") + marker.name;
    } else if (const std::string* why = RefusalOf(status, i)) {
      refused += (refused.empty() ? "" : ", ") + marker.name + " (" + *why + ")";
    }
  }
  std::vector<std::pair<std::string, cv::Scalar>> lines;
  char buffer[96];
  // Which frame this is, as the source numbers and times it (also in annotated video).
  std::snprintf(buffer, sizeof(buffer), "frame %lld  %.3f s",
                static_cast<long long>(result.frame_index), result.time_s);
  lines.emplace_back(buffer, overlay_colour::kText);
  if (m.angle_deg) {
    std::snprintf(buffer, sizeof(buffer), "angle %.1f deg", *m.angle_deg);
    lines.emplace_back(buffer, overlay_colour::kText);
  } else {
    lines.emplace_back("angle --", overlay_colour::kText);
  }
  lines.emplace_back(ReadsStraight(m) ? std::string("radius straight")
                                      : Value("radius ", m.radius_mm, m.radius_px),
                     overlay_colour::kText);
  lines.emplace_back(Value("arc length ", m.arc_length_mm, m.arc_length_px),
                     overlay_colour::kText);
  lines.emplace_back(Value("bending dist ", m.tip_disp_mm, m.tip_disp_px), overlay_colour::kText);
  std::string timing;
  if (status.fps) {
    std::snprintf(buffer, sizeof(buffer), "%.1f fps  ", *status.fps);
    timing += buffer;
  }
  std::snprintf(buffer, sizeof(buffer), "proc %.2f ms", result.proc_ms);
  timing += buffer;
  if (status.latency_ms) {
    // Capture to screen: more than the run summary's capture-to-result latency by the drawing
    // and the window's own wait for the frame.
    std::snprintf(buffer, sizeof(buffer), "  to screen %.0f ms", *status.latency_ms);
    timing += buffer;
  }
  lines.emplace_back(timing, overlay_colour::kText);
  if (status.speed && *status.speed < kSlowPlaybackSpeed) {
    std::snprintf(buffer, sizeof(buffer), "%.2fx real time: slower than the video",
                  *status.speed);
    lines.emplace_back(buffer, overlay_colour::kLost);
  }
  if (!lost.empty()) lines.emplace_back("LOST: " + lost, overlay_colour::kLost);
  if (!refused.empty()) lines.emplace_back("NOT BELIEVED: " + refused, overlay_colour::kLost);
  for (const std::string& note : status.notes) lines.emplace_back(note, overlay_colour::kText);
  return lines;
}

// The lines over a darkened block, so that they read on any background.
void DrawTextBlock(cv::Mat& frame_bgr, const std::vector<std::pair<std::string, cv::Scalar>>& lines,
                   double scale, int line) {
  int baseline = 0;
  const int height = cv::getTextSize("Ag", kGuiFont, scale, line, &baseline).height + baseline + 4;
  int width = 0;
  for (const auto& [text, colour] : lines) {
    width = std::max(width, cv::getTextSize(text, kGuiFont, scale, line, &baseline).width);
  }
  const cv::Rect block = cv::Rect(0, 0, width + 12, height * static_cast<int>(lines.size()) + 8) &
                         cv::Rect(0, 0, frame_bgr.cols, frame_bgr.rows);
  cv::Mat shade = frame_bgr(block);
  shade.convertTo(shade, -1, 0.4, 0);
  for (size_t i = 0; i < lines.size(); ++i) {
    OutlinedText(frame_bgr, lines[i].first,
                 cv::Point(6, 4 + height * static_cast<int>(i + 1) - baseline), scale,
                 lines[i].second);
  }
}

// The triangle of the three markers and the arc through them.
void DrawTriangleAndArc(cv::Mat& frame_bgr, const FrameResult& result,
                        const OverlayOptions& options, int line) {
  const Measurement& m = result.measurement;
  const auto* base = Find(result, options.base);
  const auto* middle = Find(result, options.middle);
  const auto* tip = Find(result, options.tip);
  if (base && middle && tip && *base && *middle && *tip) {
    const cv::Point2d b = **base, md = **middle, t = **tip;
    cv::line(frame_bgr, Fixed(b), Fixed(md), overlay_colour::kTriangle, 1, cv::LINE_AA, kSubPixelShift);
    cv::line(frame_bgr, Fixed(md), Fixed(t), overlay_colour::kTriangle, 1, cv::LINE_AA, kSubPixelShift);
    cv::line(frame_bgr, Fixed(t), Fixed(b), overlay_colour::kTriangle, 1, cv::LINE_AA, kSubPixelShift);
    std::vector<cv::Point2d> arc;
    if (m.radius_px) arc = ArcPoints(b, md, t, *m.radius_px);
    if (arc.empty() && m.sagitta_px && *m.sagitta_px == 0) arc = {b, t};  // Straight.
    if (!arc.empty()) {
      std::vector<cv::Point> fixed;
      fixed.reserve(arc.size());
      for (const cv::Point2d& p : arc) fixed.push_back(Fixed(p));
      cv::polylines(frame_bgr, fixed, false, overlay_colour::kArc, line, cv::LINE_AA, kSubPixelShift);
    }
  }
}

// A found marker: ring, cross and name (a refused one: the lost colour, a slanted cross and why),
// and a template marker's box and score.
void DrawMarker(cv::Mat& frame_bgr, const MarkerObservation& marker, size_t index,
                const OverlayOptions& options, const OverlayStatus& status, double scale,
                int ring_thickness) {
  const cv::Point2d p = *marker.observation.position_px;
  const int r = options.marker_ring_px;
  if (const std::string* why = RefusalOf(status, index)) {
    // Found here, not believed: the lost colour, a slanted cross through a thin ring, and why.
    cv::circle(frame_bgr, Fixed(p), r << kSubPixelShift, overlay_colour::kLost, 1, cv::LINE_AA,
               kSubPixelShift);
    const cv::Point2d d(r * 0.7, r * 0.7), e(r * 0.7, -r * 0.7);
    cv::line(frame_bgr, Fixed(p - d), Fixed(p + d), overlay_colour::kLost, ring_thickness,
             cv::LINE_AA, kSubPixelShift);
    cv::line(frame_bgr, Fixed(p - e), Fixed(p + e), overlay_colour::kLost, ring_thickness,
             cv::LINE_AA, kSubPixelShift);
    OutlinedText(frame_bgr, marker.name + ": " + *why,
                 cv::Point(cvRound(p.x) + r + 3, cvRound(p.y) - r), scale, overlay_colour::kLost);
    return;
  }
  cv::circle(frame_bgr, Fixed(p), r << kSubPixelShift, overlay_colour::kMarker, ring_thickness,
             cv::LINE_AA, kSubPixelShift);
  const cv::Point2d dx(r / 2.0, 0), dy(0, r / 2.0);
  cv::line(frame_bgr, Fixed(p - dx), Fixed(p + dx), overlay_colour::kMarker, 1, cv::LINE_AA,
           kSubPixelShift);
  cv::line(frame_bgr, Fixed(p - dy), Fixed(p + dy), overlay_colour::kMarker, 1, cv::LINE_AA,
           kSubPixelShift);
  OutlinedText(frame_bgr, marker.name, cv::Point(cvRound(p.x) + r + 3, cvRound(p.y) - r), scale,
               overlay_colour::kMarker);
  // A template marker: the template's box where it matched, and the match's score (the
  // paper's display of SAD, SSD and ZNCC).
  if (index < status.template_boxes.size() && status.template_boxes[index]) {
    const OverlayStatus::TemplateBox& box = *status.template_boxes[index];
    const cv::Point2d half(box.size_px.width / 2.0, box.size_px.height / 2.0);
    cv::rectangle(frame_bgr, Fixed(p - half), Fixed(p + half), overlay_colour::kTemplate, 1,
                  cv::LINE_AA, kSubPixelShift);
    std::string label = box.method;
    for (char& c : label) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (marker.observation.score) {
      char number[32];
      std::snprintf(number, sizeof(number), " %.3g", *marker.observation.score);
      label += number;
    }
    const cv::Point under(cvRound(p.x - half.x), cvRound(p.y + half.y) + cvRound(28 * scale));
    OutlinedText(frame_bgr, label, under, scale, overlay_colour::kTemplate);
  }
}

}  // namespace

void DrawOverlay(cv::Mat& frame_bgr, const FrameResult& result, const OverlayOptions& options,
                 const OverlayStatus& status) {
  CV_Assert(frame_bgr.type() == CV_8UC3);
  const double scale =
      options.text_scale > 0 ? options.text_scale : std::max(0.35, frame_bgr.cols / 640.0 * 0.5);
  const int line = std::max(1, cvRound(scale * 2));
  const int ring_thickness = std::max(2, line);  // Thin AA rings vanish on small frames.

  // The text block first, so that markers moving under it stay visible.
  if (options.show_measurements) {
    DrawTextBlock(frame_bgr, MeasurementLines(result, status), scale, line);
  }

  // Then the triangle and the arc, and the marker rings on top of everything.
  DrawTriangleAndArc(frame_bgr, result, options, line);

  // Markers: ring, cross and name at each found centroid; nothing where a marker was not found.
  for (size_t index = 0; index < result.markers.size(); ++index) {
    const MarkerObservation& marker = result.markers[index];
    if (!marker.observation.found()) continue;
    DrawMarker(frame_bgr, marker, index, options, status, scale, ring_thickness);
  }
}

}  // namespace softsight
