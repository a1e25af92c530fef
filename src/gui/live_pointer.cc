#include "gui/live_pointer.h"

#include <algorithm>
#include <cmath>

namespace softsight {

bool LivePointer::down(const cv::Point2d& p, bool in_image) {
  if (!in_image) return false;
  press_ = pointer_ = p;
  return true;
}

bool LivePointer::move(const cv::Point2d& p, bool follow_without_button) {
  if (!press_ && !follow_without_button) return false;
  pointer_ = p;
  return true;
}

PointerGesture LivePointer::up(const cv::Point2d& p, bool in_image) {
  PointerGesture gesture;
  if (!press_) return gesture;
  gesture.press = *press_;
  gesture.release = in_image ? p : *press_;
  press_.reset();
  pointer_.reset();
  if (std::hypot(p.x - gesture.press.x, p.y - gesture.press.y) <= click_slop_px_) {
    gesture.kind = PointerGesture::Kind::kClick;
    return gesture;
  }
  gesture.kind = PointerGesture::Kind::kDrag;
  const cv::Point2d& q = gesture.press;
  const cv::Point a(cvRound(std::min(q.x, p.x)), cvRound(std::min(q.y, p.y)));
  const cv::Point b(cvRound(std::max(q.x, p.x)), cvRound(std::max(q.y, p.y)));
  gesture.box = cv::Rect(a, b);
  return gesture;
}

}  // namespace softsight
