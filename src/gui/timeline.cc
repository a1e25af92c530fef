#include "gui/timeline.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <string>

#include "gui/overlay.h"  // kGuiFont

namespace softsight {

void Timeline::set_length(int64_t frames) {
  length_ = std::max<int64_t>(1, frames);
  if (static_cast<int64_t>(marks_.size()) < *length_) marks_.resize(static_cast<size_t>(*length_));
}

void Timeline::mark(int64_t position, Mark mark, bool on) {
  if (position < 0) return;
  if (position >= static_cast<int64_t>(marks_.size())) {
    if (!on) return;
    marks_.resize(static_cast<size_t>(position) + 1);  // Past a header's count: rare, grows once.
  }
  uint8_t& bits = marks_[static_cast<size_t>(position)];
  bits = on ? (bits | mark) : (bits & ~mark);
}

bool Timeline::marked(int64_t position, Mark mark) const {
  return position >= 0 && position < static_cast<int64_t>(marks_.size()) &&
         (marks_[static_cast<size_t>(position)] & mark) != 0;
}

int64_t Timeline::position_at(double x, int width_px) const {
  const int64_t frames = length_.value_or(position_ + 1);
  if (width_px <= 1 || frames <= 1) return 0;
  const double fraction = std::clamp(x / (width_px - 1), 0.0, 1.0);
  return std::llround(fraction * (frames - 1));
}

int Timeline::x_of(int64_t position, int width_px) const {
  const int64_t frames = length_.value_or(position_ + 1);
  if (frames <= 1) return 0;
  return static_cast<int>(std::llround(static_cast<double>(position) * (width_px - 1) / (frames - 1)));
}

void Timeline::draw(cv::Mat& bar) const {
  bar.setTo(cv::Scalar(40, 40, 40));
  const int w = bar.cols, h = bar.rows;
  const int64_t frames = length_.value_or(position_ + 1);
  // Each column shows the marks of every frame it stands for (a long file: many per column).
  for (int x = 0; x < w; ++x) {
    const int64_t first = position_at(x - 0.5, w);
    const int64_t last = std::min<int64_t>(frames - 1, position_at(x + 0.5, w));
    uint8_t bits = 0;
    for (int64_t p = first; p <= last && p < static_cast<int64_t>(marks_.size()); ++p) {
      bits |= marks_[static_cast<size_t>(p)];
    }
    if (bits & kRecorded) cv::line(bar, {x, 0}, {x, h / 4}, cv::Scalar(60, 200, 60));
    if (bits & kLost) cv::line(bar, {x, h - h / 4}, {x, h - 1}, cv::Scalar(60, 60, 230));
    if (bits & kEdit) cv::line(bar, {x, h / 4}, {x, h - h / 4 - 1}, cv::Scalar(0, 220, 255));
  }
  const int cursor = x_of(position_, w);
  cv::rectangle(bar, cv::Rect(cursor - 1, 0, 3, h), cv::Scalar(255, 255, 255), cv::FILLED);
  const std::string label = std::to_string(position_) +
                            (length_ ? " / " + std::to_string(*length_ - 1) : std::string());
  int baseline = 0;
  const double scale = 0.38;
  const cv::Size text = cv::getTextSize(label, kGuiFont, scale, 1, &baseline);
  // Beside the cursor, on the side with room.
  const int tx = cursor + 6 + text.width < w ? cursor + 6 : std::max(0, cursor - 6 - text.width);
  const cv::Point origin(tx, (h + text.height) / 2);
  cv::putText(bar, label, origin, kGuiFont, scale, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(bar, label, origin, kGuiFont, scale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
}

}  // namespace softsight
