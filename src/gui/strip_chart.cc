#include "gui/strip_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "gui/overlay.h"  // ReadsStraight
#include "softsight/io/plot.h"

namespace softsight {
namespace {

constexpr double kFontScale = 0.4;
constexpr int kLeft = 40;      // The least room for value labels; more when they are wider.
constexpr int kLabelPad = 4;  // Between a value label and the lane, and the chart's edge.
constexpr int kRight = 8;
const cv::Scalar kBackground(32, 32, 32);
const cv::Scalar kGridColour(70, 70, 70);
const cv::Scalar kLabel(220, 220, 220);

// The lane's value range [lo, hi] as shown: 0..1 without values, a fixed span around a
// near-constant value (so that rounding noise stays flat), else the values' padded by 8%.
void ShownRange(double* lo, double* hi) {
  if (*lo > *hi) {
    *lo = 0;
    *hi = 1;
  } else if (const double min_span = std::max(1.0, 0.05 * std::max(std::abs(*lo), std::abs(*hi)));
             *hi - *lo < min_span) {
    const double centre = (*lo + *hi) / 2;
    *lo = centre - min_span / 2;
    *hi = centre + min_span / 2;
  } else {
    const double pad = 0.08 * (*hi - *lo);
    *lo -= pad;
    *hi += pad;
  }
}

// A curve's part of its lane's label: after the lane's label (the first curve's), its current
// value (null: no samples yet), named when the lane has several curves.
std::string CurveLabel(std::string text, const std::string& name, int count,
                       const std::optional<double>* current) {
  if (current != nullptr) {
    char value[32];
    if (*current) {
      std::snprintf(value, sizeof(value), "%.1f", **current);
    } else {
      std::snprintf(value, sizeof(value), "--");
    }
    text += "  ";
    if (count > 1) text += name + " ";
    text += value;
  } else if (count > 1) {
    text += "  " + name;
  }
  return text;
}

// One unbroken run of a curve (a lone sample: a dot), then an empty run for the next.
void DrawRun(cv::Mat& lane_area, const cv::Scalar& colour, std::vector<cv::Point>* run) {
  if (run->size() == 1) {
    cv::circle(lane_area, (*run)[0], 2 << kSubPixelShift, colour, cv::FILLED, cv::LINE_AA,
               kSubPixelShift);
  } else if (run->size() > 1) {
    cv::polylines(lane_area, *run, false, colour, 1, cv::LINE_AA, kSubPixelShift);
  }
  run->clear();
}

}  // namespace

// Same hues as the plot command's series, brightened for a dark background.
const cv::Scalar StripChart::kColours[kLanes] = {
    {255, 170, 60}, {120, 220, 60}, {220, 150, 240}, {80, 200, 255}};

bool StripChartOptions::Check(std::string* error) const {
  if (!(window_s > 0.1 && window_s <= 3600)) {
    *error = "window_s must be in (0.1, 3600] s, got " + std::to_string(window_s);
    return false;
  }
  if (height_px < 60 || height_px > 2000) {
    *error = "height_px must be in 60..2000, got " + std::to_string(height_px);
    return false;
  }
  return true;
}

StripChart::StripChart(StripChartOptions options)
    : StripChart(options, {{"angle", "deg", {{"", kColours[0]}}, false},
                           {"bending dist", "px", {{"", kColours[1]}}, true},
                           {"arc length", "px", {{"", kColours[2]}}, true},
                           {"radius", "px", {{"", kColours[3]}}, true}}) {}

StripChart::StripChart(StripChartOptions options, std::vector<LaneSpec> lanes)
    : options_(options), specs_(std::move(lanes)) {
  std::string error;
  CV_Assert(options_.Check(&error));
  int series = 0;
  for (const LaneSpec& lane : specs_) {
    CV_Assert(!lane.series.empty());
    first_series_.push_back(series);
    series += static_cast<int>(lane.series.size());
  }
  CV_Assert(!specs_.empty() && series <= static_cast<int>(kMaxSeries));
  lanes_.resize(specs_.size());
}

void StripChart::add(const FrameResult& result) {
  const Measurement& m = result.measurement;
  const bool metric = m.tip_disp_mm.has_value() || m.arc_length_mm.has_value();
  // A radius too large to tell from straight is a gap, as the overlay reads it "straight": its
  // thousands of px would flatten the lane.
  std::optional<double> radius = metric ? m.radius_mm : m.radius_px;
  if (ReadsStraight(m)) radius.reset();
  add(result.time_s,
      {m.angle_deg, metric ? m.tip_disp_mm : m.tip_disp_px,
       metric ? m.arc_length_mm : m.arc_length_px, radius},
      metric);
}

void StripChart::add(double time_s, std::initializer_list<std::optional<double>> values,
                     bool metric) {
  CV_Assert(values.size() <= kMaxSeries);
  if (!samples_.empty() && time_s < samples_.back().time_s) samples_.clear();
  if (!samples_.empty() && time_s == samples_.back().time_s) samples_.pop_back();
  Sample& sample = samples_.emplace_back();
  sample.time_s = time_s;
  sample.metric = metric;
  std::copy(values.begin(), values.end(), sample.values.begin());
  while (!samples_.empty() && samples_.front().time_s < time_s - options_.window_s) {
    samples_.pop_front();
  }
}

void StripChart::clear() { samples_.clear(); }

double StripChart::x_of(double time_s) const {
  // The newest sample on the lane's last column (x_left_ + x_width_ is past it: clipped).
  return x_left_ +
         (time_s - (t_right_ - options_.window_s)) / options_.window_s * (x_width_ - 1);
}

double StripChart::y_of(int i, double value) const {
  const Lane& lane = lanes_[i];
  return lane.rect.y + (lane.y_max - value) / (lane.y_max - lane.y_min) * (lane.rect.height - 1);
}

void StripChart::draw(cv::Mat& area) const {
  CV_Assert(area.type() == CV_8UC3);
  area.setTo(kBackground);
  const bool metric = !samples_.empty() && samples_.back().metric;
  const int lanes = lane_count();
  const int lane_height = area.rows / lanes;
  t_right_ = samples_.empty() ? 0.0 : samples_.back().time_s;

  // The value ranges and tick labels of all lanes first: the left margin is as wide as the
  // widest label (a 5-digit arc length or a negative distance is not cut off).
  std::vector<std::vector<double>> ticks(lanes);
  std::vector<std::vector<std::string>> tick_text(lanes);
  int label_width = 0, baseline = 0;
  const int text_height = cv::getTextSize("0", kGuiFont, kFontScale, 1, &baseline).height;
  for (int i = 0; i < lanes; ++i) {
    const LaneSpec& spec = specs_[i];
    Lane& lane = lanes_[i];
    lane.label = spec.name + " [" + (spec.length && metric ? "mm" : spec.unit) + "]";
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    const int first = first_series_[i], end = first + static_cast<int>(spec.series.size());
    for (const Sample& s : samples_) {
      for (int k = first; k < end; ++k) {
        if (s.values[k]) {
          lo = std::min(lo, *s.values[k]);
          hi = std::max(hi, *s.values[k]);
        }
      }
    }
    ShownRange(&lo, &hi);
    lane.y_min = lo;
    lane.y_max = hi;
    ticks[i] = NiceTicks(lo, hi, 3);
    const double step = ticks[i].size() > 1 ? ticks[i][1] - ticks[i][0] : 1.0;
    for (double v : ticks[i]) {
      tick_text[i].push_back(FormatTick(v, step));
      label_width = std::max(
          label_width, cv::getTextSize(tick_text[i].back(), kGuiFont, kFontScale, 1, &baseline).width);
    }
  }
  const int left = std::clamp(label_width + 2 * kLabelPad, kLeft, std::max(kLeft, area.cols / 3));
  x_left_ = left;
  x_width_ = std::max(1, area.cols - left - kRight);

  std::vector<cv::Point> run;
  for (int i = 0; i < lanes; ++i) {
    const LaneSpec& spec = specs_[i];
    Lane& lane = lanes_[i];
    lane.rect = cv::Rect(left, i * lane_height + 3, static_cast<int>(x_width_), lane_height - 6);
    const cv::Rect& r = lane.rect;

    cv::rectangle(area, r, kGridColour, 1);
    lane.tick_labels.clear();
    for (size_t k = 0; k < ticks[i].size(); ++k) {
      const int y = cvRound(y_of(i, ticks[i][k]));
      cv::line(area, {r.x, y}, {r.x + r.width - 1, y}, kGridColour, 1);
      // Centred on its grid line, but kept inside the lane (a tick at the lane's edge).
      const int text_y = std::clamp(y + text_height / 2, r.y + text_height, r.y + r.height - 1);
      const int width = cv::getTextSize(tick_text[i][k], kGuiFont, kFontScale, 1, &baseline).width;
      const int text_x = left - kLabelPad - width;  // Right-aligned against the lane.
      cv::putText(area, tick_text[i][k], {text_x, text_y}, kGuiFont, kFontScale, kLabel, 1,
                  cv::LINE_AA);
      lane.tick_labels.emplace_back(text_x, text_y - text_height, width, text_height + baseline);
    }
    // Current values in the lane's label, so the chart reads without the overlay: after the
    // label, each curve's (named when the lane has several) in its colour.
    const int first = first_series_[i];
    const int count = static_cast<int>(spec.series.size());
    cv::Point at(r.x + 6, r.y + 14);
    for (int k = 0; k < count; ++k) {
      const std::optional<double>* current =
          samples_.empty() ? nullptr : &samples_.back().values[first + k];
      const std::string text =
          CurveLabel(k == 0 ? lane.label : "", spec.series[k].name, count, current);
      cv::putText(area, text, at, kGuiFont, kFontScale, spec.series[k].colour, 1, cv::LINE_AA);
      at.x += cv::getTextSize(text, kGuiFont, kFontScale, 1, &baseline).width;
    }

    cv::Mat lane_area = area(r);
    // The first curve last, on top of the others.
    for (int k = count - 1; k >= 0; --k) {
      const cv::Scalar& colour = spec.series[k].colour;
      run.clear();
      const auto flush = [&] { DrawRun(lane_area, colour, &run); };
      for (const Sample& s : samples_) {
        const std::optional<double>& v = s.values[first + k];
        if (!v) {
          flush();
          continue;
        }
        run.emplace_back(cvRound((x_of(s.time_s) - r.x) * (1 << kSubPixelShift)),
                         cvRound((y_of(i, *v) - r.y) * (1 << kSubPixelShift)));
      }
      flush();
    }
  }
  char span[32];
  std::snprintf(span, sizeof(span), "last %g s", options_.window_s);
  cv::putText(area, span, {area.cols - kRight - 70, area.rows - 6}, kGuiFont, kFontScale, kLabel, 1,
              cv::LINE_AA);
}

}  // namespace softsight
