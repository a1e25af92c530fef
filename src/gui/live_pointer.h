// The mouse as gestures, internal to gui: a press and release closer than the click slop is a
// click, farther a drag with its box; the pointer between them is view state (the rubber band, the
// line to the first scale point). The controller decides what a gesture does.
#pragma once

#include <opencv2/core.hpp>
#include <optional>

namespace softsight {

struct PointerGesture {
  enum class Kind { kNone, kClick, kDrag };
  Kind kind = Kind::kNone;
  cv::Point2d press;    // Where the button went down.
  cv::Point2d release;  // Where it came up, or the press when that was outside the image.
  cv::Rect box;         // kDrag: the box between the two, integer pixels.
};

class LivePointer {
 public:
  explicit LivePointer(int click_slop_px) : click_slop_px_(click_slop_px) {}

  // A press inside the image starts a gesture; returns true when the view must be redrawn.
  bool down(const cv::Point2d& p, bool in_image);
  // Follows the pointer while a button is down, or always when `follow_without_button` (scale
  // mode's line to the first point). Returns true when the view must be redrawn.
  bool move(const cv::Point2d& p, bool follow_without_button);
  // The gesture the release completes (kNone without a press inside the image).
  PointerGesture up(const cv::Point2d& p, bool in_image);
  void forget_pointer() { pointer_.reset(); }

  const std::optional<cv::Point2d>& press() const { return press_; }
  const std::optional<cv::Point2d>& pointer() const { return pointer_; }

 private:
  int click_slop_px_;
  std::optional<cv::Point2d> press_, pointer_;
};

}  // namespace softsight
