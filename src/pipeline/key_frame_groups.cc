#include "pipeline/key_frame_groups.h"

#include <algorithm>

namespace softsight {

namespace {

// A jump smaller than this is within what a lossy codec does to a marker's edge anyway.
constexpr double kMinJumpPx = 3.0;
// A jump is damage only when this many times the group's own frame-to-frame scatter.
constexpr double kNoiseFactor = 6.0;
// The jump back at the key frame must undo the earlier one to within this share of its size.
constexpr double kUndoTolerance = 0.5;

double MedianOf(std::vector<double>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

void KeyFrameGroups::add(const Frame& frame, const FrameResult& result, const Release& release) {
  if (!frame.key_frame) predicted_seen_ = true;
  if (!predicted_seen_) {
    release(frame, result);
    tail_index_ = result.frame_index;
    tail_px_.resize(result.markers.size());
    for (size_t m = 0; m < result.markers.size(); ++m) {
      tail_px_[m] = result.markers[m].observation.position_px;
    }
    return;
  }
  if (frame.key_frame && count_ > 0) {
    check(result);
    release_held(release, /*checked=*/true);
  }
  const size_t bytes = frame.image.total() * frame.image.elemSize();
  if (count_ > 0 && held_bytes_ + bytes > max_held_bytes_) release_held(release, /*checked=*/false);
  hold(frame, result);
}

void KeyFrameGroups::flush(const Release& release) { release_held(release, /*checked=*/false); }

void KeyFrameGroups::hold(const Frame& frame, const FrameResult& result) {
  if (count_ == held_.size()) held_.emplace_back();
  Held& slot = held_[count_++];
  frame.image.copyTo(slot.frame.image);  // Into the slot's own buffer: no allocation once sized.
  slot.frame.index = frame.index;
  slot.frame.time_s = frame.time_s;
  slot.frame.captured = frame.captured;
  slot.frame.key_frame = frame.key_frame;
  slot.result = result;
  held_bytes_ += frame.image.total() * frame.image.elemSize();
}

void KeyFrameGroups::release_held(const Release& release, bool checked) {
  for (size_t i = 0; i < count_; ++i) release(held_[i].frame, held_[i].result);
  if (count_ > 0) {
    const FrameResult& last = held_[count_ - 1].result;
    tail_index_ = last.frame_index;
    tail_px_.resize(last.markers.size());
    for (size_t m = 0; m < last.markers.size(); ++m) {
      tail_px_[m] = last.markers[m].observation.position_px;
    }
  }
  if (!checked) unchecked_frames_ += static_cast<int64_t>(count_);
  count_ = 0;
  held_bytes_ = 0;
}

void KeyFrameGroups::check(const FrameResult& next) {
  for (size_t m = 0; m < next.markers.size(); ++m) {
    if (!next.markers[m].observation.found()) continue;
    // The marker's track: the frame before the group, the group, the key frame after it.
    indices_.clear();
    points_.clear();
    if (tail_index_ >= 0 && m < tail_px_.size() && tail_px_[m]) {
      indices_.push_back(tail_index_);
      points_.push_back(*tail_px_[m]);
    }
    for (size_t i = 0; i < count_; ++i) {
      const Observation& o = held_[i].result.markers[m].observation;
      if (!o.found()) continue;
      indices_.push_back(held_[i].result.frame_index);
      points_.push_back(*o.position_px);
    }
    indices_.push_back(next.frame_index);
    points_.push_back(*next.markers[m].observation.position_px);
    const size_t n = points_.size();
    if (n < 4) continue;  // Too few steps to know the group's own motion.
    // The group's motion: the median velocity per frame; each step's residual from it.
    scratch_.clear();
    for (size_t k = 1; k < n; ++k) {
      scratch_.push_back((points_[k].x - points_[k - 1].x) / double(indices_[k] - indices_[k - 1]));
    }
    const double vx = MedianOf(scratch_);
    scratch_.clear();
    for (size_t k = 1; k < n; ++k) {
      scratch_.push_back((points_[k].y - points_[k - 1].y) / double(indices_[k] - indices_[k - 1]));
    }
    const double vy = MedianOf(scratch_);
    residuals_.assign(n, cv::Point2d(0, 0));
    scratch_.clear();
    for (size_t k = 1; k < n; ++k) {
      const double frames = double(indices_[k] - indices_[k - 1]);
      residuals_[k] = points_[k] - points_[k - 1] - cv::Point2d(vx * frames, vy * frames);
      scratch_.push_back(cv::norm(residuals_[k]));
    }
    const double threshold = std::max(kMinJumpPx, kNoiseFactor * MedianOf(scratch_));
    const cv::Point2d back = residuals_[n - 1];
    const double back_px = cv::norm(back);
    if (back_px <= threshold) continue;
    // Where the damage began: the step the jump back undoes best.
    std::optional<size_t> onset;
    double best = kUndoTolerance * back_px;
    for (size_t k = 1; k + 1 < n; ++k) {
      const double undone = cv::norm(residuals_[k] + back);
      if (cv::norm(residuals_[k]) > threshold && undone < best) {
        best = undone;
        onset = k;
      }
    }
    if (!onset) continue;  // A real change of motion at the key frame (a bounce): believed.
    const int64_t first_damaged = indices_[*onset];
    for (size_t i = 0; i < count_; ++i) {
      FrameResult& held = held_[i].result;
      Observation& o = held.markers[m].observation;
      if (held.frame_index < first_damaged || !o.found()) continue;
      o = Observation::NotFound(MarkerStatus::kImplausible);
      held.measurement = Measurement{};  // Measured with the damaged marker.
      ++demoted_;
    }
  }
}

}  // namespace softsight
