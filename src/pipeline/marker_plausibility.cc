#include "pipeline/marker_plausibility.h"

#include <algorithm>
#include <cmath>

#include "track/repeated_frames.h"

namespace softsight {
namespace {

// A marker not believed for more frames than this has no usable motion history: its next
// report is a re-acquisition.
constexpr int64_t kMotionMemoryFrames = 2;
// A segment between neighbours may change by these factors in one frame (a soft body bends,
// its segments do not stretch 1.5x between two frames).
constexpr double kMaxStretch = 1.5;
constexpr double kMinStretch = 0.6;
// ... and by this factor for a marker whose motion does not vouch for it (re-acquired).
constexpr double kMaxStretchUnsupported = 1.25;
// The arrangement is learned from this many consecutive frames in which every body marker was
// found and believed, with each segment agreeing within kLearnAgreement across them.
constexpr size_t kLearnFrames = 3;
constexpr double kLearnAgreement = 1.2;
// How fast learned segments follow the body (per believed frame): slow enough that one bad
// frame barely moves them, fast enough to follow bending and perspective over a second.
constexpr double kSegmentFollow = 0.1;
// Smoothing of the velocity and of the usual prediction error.
constexpr double kVelocityFollow = 0.5;
constexpr double kResidualFollow = 0.1;
// Repeated frames (track/repeated_frames.h) leave a marker's motion history as it was, so the
// step after them is predicted and bounded over all the frames it took: they must fit in the
// motion's memory.
static_assert(kMaxRepeatedFrames <= kMotionMemoryFrames);

}  // namespace

MarkerPlausibility::MarkerPlausibility(std::vector<double> size_px, std::vector<size_t> body)
    : size_px_(std::move(size_px)), body_(std::move(body)), tracks_(size_px_.size()),
      ratio_(size_px_.size()), supported_(size_px_.size(), false) {
  for (size_t i : body_) CV_Assert(i < size_px_.size());
  if (body_.size() < 3) body_.clear();
  rejected_.reserve(size_px_.size());
}

void MarkerPlausibility::forget(size_t i) { tracks_.at(i) = Track(); }

std::optional<double> MarkerPlausibility::motion_ratio(size_t i, int64_t frame,
                                                       const cv::Point2d& p) const {
  const Track& t = tracks_[i];
  // One believed position gives no velocity: the first step of a fast marker cannot be told
  // from a jump, so it is checked against the arrangement only (and starts the velocity).
  if (t.reacquiring || !t.last || !t.has_velocity) return std::nullopt;
  const int64_t gap = frame - t.last_frame;
  if (gap < 1 || gap > kMotionMemoryFrames + 1) return std::nullopt;
  const double frames = static_cast<double>(gap);
  const cv::Point2d velocity = t.has_velocity ? t.velocity : cv::Point2d(0, 0);
  const cv::Point2d predicted = *t.last + velocity * frames;
  // The bound: the marker's size (a start, a stop, a sharp turn within a frame), the distance
  // it travels at its speed (it may reverse: a bounce), and its usual prediction error; each
  // over the frames since it was last believed.
  const double bound =
      std::max(3.0, (size_px_[i] + cv::norm(velocity)) * frames + 4.0 * t.residual_px);
  return cv::norm(p - predicted) / bound;
}

void MarkerPlausibility::reject(size_t i, std::vector<MarkerObservation>& markers) {
  markers[i].observation = Observation::NotFound(MarkerStatus::kImplausible);
  rejected_.push_back(i);
}

void MarkerPlausibility::check_arrangement(std::vector<MarkerObservation>& markers) {
  if (segment_px_.empty()) return;
  // Repeat until no found pair along the body breaks the arrangement: dropping a culprit makes
  // its neighbours a new (longer) pair.
  for (size_t round = 0; round < body_.size(); ++round) {
    bool dropped = false;
    std::optional<size_t> previous;  // Position along the body of the last found marker.
    for (size_t k = 0; k < body_.size(); ++k) {
      const size_t b = body_[k];
      if (!markers[b].observation.found()) continue;
      if (!previous) {
        previous = k;
        continue;
      }
      const size_t a = body_[*previous];
      double span = 0.0;
      for (size_t s = *previous; s < k; ++s) span += segment_px_[s];
      const double d =
          cv::norm(*markers[a].observation.position_px - *markers[b].observation.position_px);
      // Neighbours keep their spacing within the stretch factors; markers with others lost
      // between them are at most as far apart as the segments between them stretched.
      // A marker the motion does not vouch for (just re-acquired) must fit more closely: its
      // report is all there is.
      const bool adjacent = k == *previous + 1;
      const bool unsupported = !supported_[a] || !supported_[b];
      const double max_stretch = unsupported ? kMaxStretchUnsupported : kMaxStretch;
      const double min_stretch = unsupported ? 1.0 / kMaxStretchUnsupported : kMinStretch;
      const bool broken = d > max_stretch * span || (adjacent && d < min_stretch * span);
      if (!broken) {
        previous = k;
        continue;
      }
      // The culprit: the one the motion supports less. No history is no support, and nor is a
      // report after frames in which the marker was not believed.
      const std::optional<double> ra = supported_[a] ? ratio_[a] : std::nullopt;
      const std::optional<double> rb = supported_[b] ? ratio_[b] : std::nullopt;
      if (!ra && !rb) {
        reject(a, markers);
        reject(b, markers);
      } else if (!ra || (rb && *ra > *rb)) {
        reject(a, markers);
      } else {
        reject(b, markers);
      }
      dropped = true;
      break;
    }
    if (!dropped) return;
  }
}

void MarkerPlausibility::check_suspects(std::vector<MarkerObservation>& markers) {
  // Only a learned arrangement can vouch; without one a suspect is believed as before.
  if (segment_px_.empty()) return;
  const auto found = [&](size_t k) { return markers[body_[k]].observation.found(); };
  for (size_t k = 0; k < body_.size(); ++k) {
    const size_t b = body_[k];
    if (!tracks_[b].suspect || !found(k)) continue;
    const cv::Point2d p = *markers[b].observation.position_px;
    bool vouched = false;
    for (const size_t n : {k - 1, k + 1}) {  // k - 1 wraps past the first: out of range.
      if (n >= body_.size() || !found(n)) continue;
      const double span = segment_px_[std::min(k, n)];
      const double d = cv::norm(p - *markers[body_[n]].observation.position_px);
      vouched = vouched || (d <= kMaxStretchUnsupported * span && d * kMaxStretchUnsupported >= span);
    }
    if (!vouched) reject(b, markers);
  }
}

void MarkerPlausibility::learn(const std::vector<MarkerObservation>& markers) {
  if (body_.empty()) return;
  const auto position = [&](size_t k) { return markers[body_[k]].observation.position_px; };
  if (!segment_px_.empty()) {
    for (size_t k = 0; k + 1 < body_.size(); ++k) {
      if (position(k) && position(k + 1)) {
        const double d = cv::norm(*position(k) - *position(k + 1));
        segment_px_[k] += kSegmentFollow * (d - segment_px_[k]);
      }
    }
    return;
  }
  std::vector<double> lengths;
  for (size_t k = 0; k + 1 < body_.size(); ++k) {
    if (!position(k) || !position(k + 1)) {
      learning_.clear();  // Learned only from consecutive frames with every marker.
      return;
    }
    lengths.push_back(cv::norm(*position(k) - *position(k + 1)));
  }
  learning_.push_back(lengths);
  if (learning_.size() < kLearnFrames) return;
  for (size_t s = 0; s < lengths.size(); ++s) {
    double lo = learning_[0][s], hi = learning_[0][s];
    for (const std::vector<double>& frame : learning_) {
      lo = std::min(lo, frame[s]);
      hi = std::max(hi, frame[s]);
    }
    if (!(lo > 0.0) || hi > kLearnAgreement * lo) {
      learning_.erase(learning_.begin());  // Not yet consistent: slide the window on.
      return;
    }
  }
  segment_px_ = learning_.back();
  learning_.clear();
}

const std::vector<size_t>& MarkerPlausibility::check(int64_t frame_index,
                                                     std::vector<MarkerObservation>& markers) {
  CV_Assert(markers.size() == tracks_.size());
  rejected_.clear();
  for (size_t i = 0; i < markers.size(); ++i) {
    ratio_[i].reset();
    supported_[i] = false;
    if (!markers[i].observation.found()) continue;
    ratio_[i] = motion_ratio(i, frame_index, *markers[i].observation.position_px);
    // The motion vouches for a report only from one frame to the next: across frames in which
    // the marker was not believed (covered, lost) its bound grows with the gap, and a look-alike
    // that appeared meanwhile nearby fits it; such a report is checked like a re-acquisition.
    supported_[i] = ratio_[i].has_value() && frame_index - tracks_[i].last_frame == 1;
    if (ratio_[i] && *ratio_[i] > 1.0) reject(i, markers);
  }
  check_arrangement(markers);
  check_suspects(markers);
  std::sort(rejected_.begin(), rejected_.end());
  rejected_.erase(std::unique(rejected_.begin(), rejected_.end()), rejected_.end());

  // What is believed now becomes the history.
  for (size_t i = 0; i < markers.size(); ++i) {
    Track& t = tracks_[i];
    if (std::binary_search(rejected_.begin(), rejected_.end(), i)) {
      t = Track();  // Its tracker searches afresh: the next report is a re-acquisition ...
      t.suspect = true;  // ... that the arrangement must vouch for.
      continue;
    }
    if (markers[i].observation.found()) t.suspect = false;
    if (!markers[i].observation.found()) {
      if (t.last && frame_index - t.last_frame > kMotionMemoryFrames) t.reacquiring = true;
      continue;
    }
    const cv::Point2d p = *markers[i].observation.position_px;
    const int64_t gap = frame_index - t.last_frame;
    const bool still =
        t.last && !t.reacquiring && gap >= 1 && cv::norm(p - *t.last) <= kRepeatStillPx;
    if (still && t.has_velocity && IsRepeatedFrame(p - *t.last, t.velocity, t.still_frames)) {
      ++t.still_frames;  // A repeated frame, perhaps: the history waits.
      continue;
    }
    t.still_frames = still ? t.still_frames + 1 : 0;
    if (t.last && !t.reacquiring && gap >= 1) {
      const cv::Point2d step = (p - *t.last) * (1.0 / static_cast<double>(gap));
      const cv::Point2d predicted = *t.last + (t.has_velocity ? t.velocity : step) *
                                                  static_cast<double>(gap);
      t.residual_px += kResidualFollow * (cv::norm(p - predicted) - t.residual_px);
      t.velocity = t.has_velocity ? t.velocity + kVelocityFollow * (step - t.velocity) : step;
      t.has_velocity = true;
    } else {
      t.has_velocity = false;
      t.velocity = {0, 0};
      t.residual_px = 0.0;
    }
    t.last = p;
    t.last_frame = frame_index;
    t.reacquiring = false;
  }
  learn(markers);
  return rejected_;
}

}  // namespace softsight
