#include "pipeline/arrangement_check.h"

#include <algorithm>
#include <cmath>

namespace softsight {
namespace {

// A segment between neighbours may change by these factors in one frame (a soft body bends,
// its segments do not stretch 1.5x between two frames).
constexpr double kMaxStretch = 1.5;
constexpr double kMinStretch = 0.6;
// ... and by this factor for a marker whose motion does not support it (re-acquired).
constexpr double kMaxStretchUnsupported = 1.25;
// The arrangement is learned from this many consecutive frames in which every body marker was
// found and believed, with each segment agreeing within kLearnAgreement across them.
constexpr size_t kLearnFrames = 3;
constexpr double kLearnAgreement = 1.2;
// How fast learned segments follow the body (per believed frame): slow enough that one bad
// frame barely moves them, fast enough to follow bending and perspective over a second.
constexpr double kSegmentFollow = 0.1;

}  // namespace

ArrangementCheck::ArrangementCheck(size_t markers, std::vector<size_t> body)
    : body_(std::move(body)), suspect_(markers, false) {
  for (size_t i : body_) CV_Assert(i < markers);
  if (body_.size() < 3) body_.clear();
  rejected_.reserve(markers);
}

void ArrangementCheck::forget(size_t i) { suspect_.at(i) = false; }

void ArrangementCheck::reject(size_t i, std::vector<MarkerObservation>& markers) {
  markers[i].observation = Observation::NotFound(MarkerStatus::kImplausible);
  rejected_.push_back(i);
}

void ArrangementCheck::check_segments(std::vector<MarkerObservation>& markers,
                                      const std::vector<std::optional<double>>& motion_support) {
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
      // A marker its motion does not support (just re-acquired) must fit more closely: its
      // report is all there is.
      const std::optional<double>& ra = motion_support[a];
      const std::optional<double>& rb = motion_support[b];
      const bool adjacent = k == *previous + 1;
      const bool unsupported = !ra || !rb;
      const double max_stretch = unsupported ? kMaxStretchUnsupported : kMaxStretch;
      const double min_stretch = unsupported ? 1.0 / kMaxStretchUnsupported : kMinStretch;
      const bool broken = d > max_stretch * span || (adjacent && d < min_stretch * span);
      if (!broken) {
        previous = k;
        continue;
      }
      // The culprit: the one its motion supports less.
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

void ArrangementCheck::check_suspects(std::vector<MarkerObservation>& markers) {
  // Only a learned arrangement can vouch; without one a suspect is believed as before.
  if (segment_px_.empty()) return;
  const auto found = [&](size_t k) { return markers[body_[k]].observation.found(); };
  for (size_t k = 0; k < body_.size(); ++k) {
    const size_t b = body_[k];
    if (!suspect_[b] || !found(k)) continue;
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

void ArrangementCheck::learn(const std::vector<MarkerObservation>& markers) {
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

const std::vector<size_t>& ArrangementCheck::check(
    std::vector<MarkerObservation>& markers,
    const std::vector<std::optional<double>>& motion_support) {
  CV_Assert(markers.size() == suspect_.size() && motion_support.size() == suspect_.size());
  rejected_.clear();
  check_segments(markers, motion_support);
  check_suspects(markers);
  std::sort(rejected_.begin(), rejected_.end());
  rejected_.erase(std::unique(rejected_.begin(), rejected_.end()), rejected_.end());
  for (size_t i = 0; i < markers.size(); ++i) {
    if (std::binary_search(rejected_.begin(), rejected_.end(), i)) {
      suspect_[i] = true;  // Its next reports must be vouched for by a neighbour.
    } else if (markers[i].observation.found()) {
      suspect_[i] = false;
    }
  }
  learn(markers);
  return rejected_;
}

}  // namespace softsight
