#include "pipeline/key_frame_groups.h"

#include <algorithm>
#include <limits>
#include <optional>

namespace softsight {

namespace {

// A jump smaller than this is within what a lossy codec does to a marker's edge anyway.
constexpr double kMinJumpPx = 3.0;
// A jump is damage only when this many times the group's own frame-to-frame scatter.
constexpr double kNoiseFactor = 6.0;
// The jump back at the key frame must undo the earlier one to within this share of its size.
constexpr double kUndoTolerance = 0.5;
// A group's track starts at the marker's last believed position when it is in one of this many
// frames handed on last (a marker hidden for a frame or two still ties the group to its past;
// frames the decoder left out do not count).
constexpr int kAnchorFrames = 3;

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
    remember(result);
    return;
  }
  if (frame.key_frame && count_ > 0) {
    check(result);
    release_held(release, /*checked=*/true);
  }
  const size_t bytes = hold_images_ ? frame.image.total() * frame.image.elemSize() : 0;
  if (count_ > 0 && (held_bytes_ + bytes > max_held_bytes_ || count_ >= max_held_frames_)) {
    release_held(release, /*checked=*/false);
  }
  hold(frame, result);
}

void KeyFrameGroups::flush(const Release& release, bool damaged) {
  if (damaged && count_ > 0 && predicted_seen_) {
    // The damage the run ended with may be in this group too, and no key frame follows it.
    for (size_t m = 0; m < held_[0].result.markers.size(); ++m) check_unverified(m);
  }
  release_held(release, /*checked=*/false);
}

void KeyFrameGroups::hold(const Frame& frame, const FrameResult& result) {
  if (count_ == held_.size()) held_.emplace_back();
  Held& slot = held_[count_++];
  if (hold_images_) {
    frame.image.copyTo(slot.frame.image);  // Into the slot's own buffer: no allocation once sized.
    held_bytes_ += frame.image.total() * frame.image.elemSize();
  } else {
    slot.frame.image.release();
  }
  slot.frame.index = frame.index;
  slot.frame.time_s = frame.time_s;
  slot.frame.captured = frame.captured;
  slot.frame.key_frame = frame.key_frame;
  slot.result = result;
}

void KeyFrameGroups::release_held(const Release& release, bool checked) {
  for (size_t i = 0; i < count_; ++i) {
    release(held_[i].frame, held_[i].result);
    remember(held_[i].result);
  }
  if (!checked) unchecked_frames_ += static_cast<int64_t>(count_);
  count_ = 0;
  held_bytes_ = 0;
}

void KeyFrameGroups::remember(const FrameResult& result) {
  if (tail_.size() < result.markers.size()) tail_.resize(result.markers.size());
  for (size_t m = 0; m < result.markers.size(); ++m) {
    const Observation& o = result.markers[m].observation;
    if (o.found()) {
      tail_[m] = Anchor{result.frame_index, *o.position_px, 1};
    } else if (tail_[m] && ++tail_[m]->frames_since > kAnchorFrames) {
      tail_[m].reset();
    }
  }
}

const KeyFrameGroups::Anchor* KeyFrameGroups::anchor(size_t m) const {
  return m < tail_.size() && tail_[m] ? &*tail_[m] : nullptr;
}

// The marker's track through the held group: its position in the frame before the group (when
// it was found there and believed), the group's frames that found it, and `key`, the key frame after it, when given.
// Fills indices_, points_ and residuals_ (each step's departure from the track's median
// velocity); returns the jump threshold, or nothing when the track is too short to know the
// group's own motion.
std::optional<double> KeyFrameGroups::track(size_t m, const Observation* key, int64_t key_index) {
  indices_.clear();
  points_.clear();
  const Anchor* before = anchor(m);
  if (before) {
    indices_.push_back(before->index);
    points_.push_back(before->px);
  }
  for (size_t i = 0; i < count_; ++i) {
    const Observation& o = held_[i].result.markers[m].observation;
    if (!o.found()) continue;
    indices_.push_back(held_[i].result.frame_index);
    points_.push_back(*o.position_px);
  }
  if (key) {
    indices_.push_back(key_index);
    points_.push_back(*key->position_px);
  }
  const size_t n = points_.size();
  if (n < 4) return std::nullopt;  // Too few steps to know the group's own motion.
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
  return std::max(kMinJumpPx, kNoiseFactor * MedianOf(scratch_));
}

void KeyFrameGroups::demote_from(size_t m, int64_t first_damaged) {
  for (size_t i = 0; i < count_; ++i) {
    FrameResult& held = held_[i].result;
    Observation& o = held.markers[m].observation;
    if (held.frame_index < first_damaged || !o.found()) continue;
    o = Observation::NotFound(MarkerStatus::kImplausible);
    held.measurement = Measurement{};  // Measured with the damaged marker.
    ++demoted_;
  }
}

void KeyFrameGroups::check(const FrameResult& next) {
  for (size_t m = 0; m < next.markers.size(); ++m) {
    const Observation& key = next.markers[m].observation;
    if (!key.found()) {
      // The key frame cannot vouch for the group: its tracker refused what it saw there as a
      // jump, or the marker is not there at all.
      check_unverified(m);
      continue;
    }
    const std::optional<double> threshold = track(m, &key, next.frame_index);
    if (!threshold) {
      // Found in too few of the group's frames to know its motion there: nothing to check
      // those positions against (after damage the tracker often finds a marker only here and
      // there in a group, each time somewhere else).
      demote_from(m, std::numeric_limits<int64_t>::min());
      continue;
    }
    const size_t n = points_.size();
    const cv::Point2d back = residuals_[n - 1];
    const double back_px = cv::norm(back);
    if (back_px <= *threshold) continue;
    // Where the damage began: the step the jump back undoes best.
    std::optional<size_t> onset;
    double best = kUndoTolerance * back_px;
    for (size_t k = 1; k + 1 < n; ++k) {
      const double undone = cv::norm(residuals_[k] + back);
      if (cv::norm(residuals_[k]) > *threshold && undone < best) {
        best = undone;
        onset = k;
      }
    }
    if (onset) {
      demote_from(m, indices_[*onset]);
      continue;
    }
    // A group that jumps away from the marker's past at its own key frame and back at the next
    // one is the picture of a damaged key frame, even when the damage also changed how the
    // marker moves in it (so the jumps do not cancel). Real motion does not jump exactly at
    // two key frames in a row; a single change of motion at a key frame (a bounce) is believed.
    const bool entered_at_key_frame =
        anchor(m) != nullptr && indices_[1] == held_[0].result.frame_index;
    if (entered_at_key_frame && jumps_at_both_ends(*threshold)) {
      demote_from(m, std::numeric_limits<int64_t>::min());
    }
  }
}

// Whether the track's first step (into the group's key frame) and its last (to the next key
// frame) are both jumps. Judged against the group's own frames when it has enough of them
// (their motion and scatter, which the two jumps would otherwise inflate: a damaged group's
// track is short and erratic), else against `threshold`, the whole track's.
bool KeyFrameGroups::jumps_at_both_ends(double threshold) {
  const size_t n = points_.size();
  if (n < 5) return cv::norm(residuals_[1]) > threshold && cv::norm(residuals_[n - 1]) > threshold;
  // Steps 2 .. n-2 lie inside the group.
  cv::Point2d velocity;
  scratch_.clear();
  for (size_t k = 2; k + 1 < n; ++k) {
    scratch_.push_back((points_[k].x - points_[k - 1].x) / double(indices_[k] - indices_[k - 1]));
  }
  velocity.x = MedianOf(scratch_);
  scratch_.clear();
  for (size_t k = 2; k + 1 < n; ++k) {
    scratch_.push_back((points_[k].y - points_[k - 1].y) / double(indices_[k] - indices_[k - 1]));
  }
  velocity.y = MedianOf(scratch_);
  const auto residual = [&](size_t k) {
    return cv::norm(points_[k] - points_[k - 1] - velocity * double(indices_[k] - indices_[k - 1]));
  };
  scratch_.clear();
  for (size_t k = 2; k + 1 < n; ++k) scratch_.push_back(residual(k));
  const double inner = std::max(kMinJumpPx, kNoiseFactor * MedianOf(scratch_));
  return residual(1) > inner && residual(n - 1) > inner;
}

void KeyFrameGroups::check_unverified(size_t m) {
  if (!anchor(m)) {
    // Not in the frame before the group (or not believed there), and not at the key frame after
    // it: nothing ties the group's positions to the marker's (a key frame the damage moved it
    // in, or the group after such a group).
    demote_from(m, std::numeric_limits<int64_t>::min());
    return;
  }
  const std::optional<double> threshold = track(m, nullptr, 0);
  if (!threshold) {
    demote_from(m, std::numeric_limits<int64_t>::min());  // Too few positions to check: as above.
    return;
  }
  // Without a key frame to undo it, a jump in the group is not told from real motion: the
  // marker is believed up to the biggest one and not after it.
  std::optional<size_t> onset;
  double biggest = *threshold;
  for (size_t k = 1; k < points_.size(); ++k) {
    const double jump = cv::norm(residuals_[k]);
    if (jump > biggest) {
      biggest = jump;
      onset = k;
    }
  }
  if (onset) demote_from(m, indices_[*onset]);
}

}  // namespace softsight

namespace softsight {

PairKeyFrameGroups::PairKeyFrameGroups(size_t max_held_bytes, bool hold_images)
    : max_held_bytes_(max_held_bytes), hold_images_(hold_images),
      // Each view's check holds only the rows: the pictures are held here, once per pair.
      left_(max_held_bytes, /*hold_images=*/false), right_(max_held_bytes, /*hold_images=*/false),
      left_checked_([this](const Frame&, const FrameResult& result) {
        held_[left_done_++].left = result;
      }),
      right_checked_([this](const Frame&, const FrameResult& result) {
        held_[right_done_++].right = result;
      }),
      pass_([](const Frame&, const FrameResult&) {}) {}

PairKeyFrameGroups::~PairKeyFrameGroups() = default;

namespace {

size_t PairBytes(const FramePair& pair) {
  return pair.left.image.total() * pair.left.image.elemSize() +
         pair.right.image.total() * pair.right.image.elemSize();
}

void CopyFrame(const Frame& from, bool with_image, Frame& to) {
  if (with_image) {
    from.image.copyTo(to.image);  // Into the slot's own buffer: no allocation once sized.
  } else {
    to.image.release();
  }
  to.index = from.index;
  to.time_s = from.time_s;
  to.captured = from.captured;
  to.key_frame = from.key_frame;
}

const Observation* ViewObservation(const FrameResult& view, const std::string& name) {
  for (const MarkerObservation& m : view.markers) {
    if (m.name == name) return &m.observation;
  }
  return nullptr;
}

}  // namespace

void PairKeyFrameGroups::add(const FramePair& pair, const StereoFrameResult& result,
                             const Release& release) {
  CV_Assert(result.left_view != nullptr && result.right_view != nullptr);
  if (!pair.left.key_frame || !pair.right.key_frame) predicted_seen_ = true;
  if (!predicted_seen_) {
    // Only key frames so far (cameras, image sequences, intra-only videos): each view's check
    // passes them through unchanged (it still learns each marker's last position), so the pair
    // goes on as it is, without a copy.
    left_.add(pair.left, *result.left_view, pass_);
    right_.add(pair.right, *result.right_view, pass_);
    release(pair, result);
    return;
  }
  const size_t bytes = hold_images_ ? PairBytes(pair) : 0;
  if (count_ > 0 && held_bytes_ + bytes > max_held_bytes_) {
    // Over the memory limit: what is held goes on unchecked, as one view's group does.
    left_.flush(left_checked_);
    right_.flush(right_checked_);
    release_ready(release);
  }
  if (count_ == held_.size()) held_.emplace_back();
  Held& slot = held_[count_++];
  CopyFrame(pair.left, hold_images_, slot.pair.left);
  CopyFrame(pair.right, hold_images_, slot.pair.right);
  slot.pair.pair_dt_ms = pair.pair_dt_ms;
  slot.result = result;
  held_bytes_ += bytes;
  // Each view's check hands its frames back (checked) into their pair's slot, in order.
  left_.add(pair.left, *result.left_view, left_checked_);
  right_.add(pair.right, *result.right_view, right_checked_);
  release_ready(release);
}

void PairKeyFrameGroups::flush(const Release& release, bool damaged) {
  left_.flush(predicted_seen_ ? left_checked_ : pass_, damaged);
  right_.flush(predicted_seen_ ? right_checked_ : pass_, damaged);
  release_ready(release);
}

void PairKeyFrameGroups::release_ready(const Release& release) {
  const size_t ready = std::min(left_done_, right_done_);
  while (head_ < ready) {
    Held& held = held_[head_++];  // Counted as handed on before release() may throw.
    believe_views(held);
    release(held.pair, held.result);
  }
  // The pairs one view still holds move to the front (their slots' buffers go along).
  if (head_ > 0) {
    std::rotate(held_.begin(), held_.begin() + static_cast<std::ptrdiff_t>(head_),
                held_.begin() + static_cast<std::ptrdiff_t>(count_));
    count_ -= head_;
    left_done_ -= head_;
    right_done_ -= head_;
    head_ = 0;
    held_bytes_ = 0;
    if (hold_images_) {
      for (size_t i = 0; i < count_; ++i) held_bytes_ += PairBytes(held_[i].pair);
    }
  }
}

// The pair's row as its views' checks left them: a marker a view's check did not believe is not
// found in 3D (its status says which view refused it and why, as for a view that lost it), and
// the measurements made with it are absent.
void PairKeyFrameGroups::believe_views(Held& held) {
  StereoFrameResult& result = held.result;
  bool demoted = false;
  for (StereoMarkerResult& m : result.markers) {
    const Observation* left = ViewObservation(held.left, m.name);
    const Observation* right = ViewObservation(held.right, m.name);
    const bool left_refused = left != nullptr && m.left.found() && !left->found();
    const bool right_refused = right != nullptr && m.right.found() && !right->found();
    if (!left_refused && !right_refused) continue;
    if (left_refused) m.left = *left;
    if (right_refused) m.right = *right;
    m.point = StereoPoint{};
    m.status = !m.left.found() ? std::string("left_") + MarkerStatusName(m.left.status())
                               : std::string("right_") + MarkerStatusName(m.right.status());
    demoted = true;
    ++demoted_;
  }
  if (demoted) {
    result.shape = Shape3d{};
    for (Segment3d& segment : result.segments) segment = Segment3d{};
  }
  result.left_angle_deg = held.left.measurement.angle_deg;
  result.right_angle_deg = held.right.measurement.angle_deg;
  // Each view's own tracking of this pair, as checked (the session's is a later pair's by now).
  result.left_view = &held.left;
  result.right_view = &held.right;
}

}  // namespace softsight
