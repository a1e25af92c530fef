// The live window's scrub bar, under the image (Kinovea's and Tracker's timeline): where the frame
// on screen is in the file, with marks where edits were made, where recordings ran and where a
// marker was not found, so a researcher sees at a glance which stretches to look at again. A
// click or drag on it is a seek (the controller maps it with position_at). Positions count
// frames from the file's first (SeekableSource's). Internal to gui (and its tests).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace softsight {

class Timeline {
 public:
  enum Mark : uint8_t { kLost = 1, kEdit = 2, kRecorded = 4 };

  // The number of frames (known for files from their header; checked at the end).
  void set_length(int64_t frames);
  std::optional<int64_t> length() const { return length_; }
  // The frame on screen.
  void set_position(int64_t position) { position_ = position; }
  int64_t position() const { return position_; }

  // Sets (or, for kLost, also clears: a frame tracked again may find every marker) a mark at
  // `position`.
  void mark(int64_t position, Mark mark, bool on = true);
  bool marked(int64_t position, Mark mark) const;

  // The position under horizontal pixel `x` of a bar `width_px` wide (clamped to the file).
  int64_t position_at(double x, int width_px) const;
  // The pixel column of `position` in a bar `width_px` wide.
  int x_of(int64_t position, int width_px) const;

  // Draws the bar into `bar` (CV_8UC3): recordings as a green band along the top, edits as
  // yellow ticks, frames with a marker not found in red along the bottom, the frame on screen as
  // a white cursor with its number.
  void draw(cv::Mat& bar) const;

 private:
  std::optional<int64_t> length_;
  int64_t position_ = 0;
  std::vector<uint8_t> marks_;  // Per position, Mark bits; grows to the length once.
};

}  // namespace softsight
