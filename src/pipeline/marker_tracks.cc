#include "pipeline/marker_tracks.h"

#include <algorithm>
#include <cmath>

#include "track/repeated_frames.h"

namespace softsight {
namespace {

// The gate: a squared Mahalanobis distance of 16 is 4 sigma (2 degrees of freedom: a report
// inside it by chance 1 time in 3000).
constexpr double kGate2 = 16.0;
// Candidates within this of each other are one blob seen by several trackers.
constexpr double kSamePlacePx = 1.0;
// Costs (unitless): an allowed pair costs its distance2 / kGate2 (at most 1) plus a little of
// the tracker's misfit; a first acquisition (no track yet) costs more than any allowed pair, so
// a candidate a started track explains goes to that track; leaving a marker unassigned costs
// more than both, so a marker takes a candidate whenever one is allowed.
constexpr double kMisfitWeight = 0.05;
constexpr double kFirstAcquisitionCost = 1.2;
constexpr double kUnassignedCost = 1.5;
// Rejected reports in a row, on one smooth motion, that restart a track: 0.1 s at 30 fps.
constexpr int kReacquireFrames = 3;
// How far a rejected report may lie from where the run's constant velocity puts it: the
// marker's size plus this fraction of the run's step (it may be slowing down or speeding up).
constexpr double kRunStepTolerance = 0.5;
// A run must start where it could have left the marker's last believed place at the run's own
// speed: within twice the marker's size plus this many of its steps per frame since (counted up
// to kReacquireFrames). A look-alike that stands still, or moves, far from there starts no run.
constexpr double kRunStartSteps = 1.5;

double DistanceToSegment(const cv::Point2d& p, const cv::Point2d& a, const cv::Point2d& b) {
  const cv::Point2d ab = b - a;
  const double len2 = ab.dot(ab);
  const double u = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return cv::norm(p - (a + u * ab));
}

}  // namespace

// A report at `p` is a repeated frame of track `t`: the marker exactly where it was last
// believed while moving (track/repeated_frames.h); its motion waits for the next new frame.
bool MarkerTracks::IsRepeat(const Track& t, const cv::Point2d& p) {
  return t.last_px && IsRepeatedFrame(p - *t.last_px, t.motion.velocity(), t.repeats);
}

namespace {

bool Fits(CandidateVerdict v) {
  return v == CandidateVerdict::kFits || v == CandidateVerdict::kChosen;
}

}  // namespace

MarkerTracks::MarkerTracks(std::vector<double> size_px, MotionModelOptions motion)
    : size_px_(std::move(size_px)) {
  for (size_t i = 0; i < size_px_.size(); ++i) {
    Track track;
    track.motion = MotionModel(motion);
    tracks_.push_back(track);
  }
  decisions_.resize(size_px_.size());
  entries_.resize(size_px_.size());
  cost_.resize(size_px_.size());
  unassigned_.resize(size_px_.size());
  report_pooled_.resize(size_px_.size());
}

void MarkerTracks::forget(size_t i) {
  Track& t = tracks_.at(i);
  t.motion.clear();
  t.pending_px.reset();
  t.restart = false;
  t.last_px.reset();
  t.repeats = 0;
  t.misses = 0;
}

void MarkerTracks::predict_all() {
  for (Track& t : tracks_) {
    if (!t.predicted) t.motion.predict();
    t.predicted = true;
  }
}

void MarkerTracks::skip() {
  predict_all();
  for (Track& t : tracks_) t.predicted = false;
}

size_t MarkerTracks::pool(const cv::Point2d& p) {
  for (size_t k = 0; k < pooled_.size(); ++k) {
    if (cv::norm(pooled_[k].position_px - p) <= kSamePlacePx) return k;
  }
  pooled_.push_back({p});
  return pooled_.size() - 1;
}

const std::vector<MarkerTracks::Decision>& MarkerTracks::associate(
    std::vector<MarkerObservation>& markers,
    const std::vector<const std::vector<MarkerCandidate>*>& candidates) {
  CV_Assert(markers.size() == tracks_.size() && candidates.size() == tracks_.size());
  predict_all();
  pooled_.clear();
  for (size_t i = 0; i < markers.size(); ++i) {
    decisions_[i] = Decision{};
    entries_[i].clear();
    report_pooled_[i].reset();
    tracks_[i].repeated = false;
    const Observation& o = markers[i].observation;
    if (o.found()) {
      // The report, with its candidate's misfit when the tracker lists it.
      double misfit = 0.0;
      std::optional<size_t> index;
      const std::vector<MarkerCandidate>* list = candidates[i];
      for (size_t c = 0; list && c < list->size(); ++c) {
        if ((*list)[c].verdict == CandidateVerdict::kChosen &&
            cv::norm((*list)[c].position_px - *o.position_px) <= kSamePlacePx) {
          misfit = (*list)[c].misfit;
          index = c;
        }
      }
      report_pooled_[i] = pool(*o.position_px);
      entries_[i].push_back({*report_pooled_[i], index, misfit});
    }
    // The other candidates that fit the marker: the one the tracker did not choose (a twin it
    // could not tell apart, or one farther from its own prediction) may be the marker.
    if (!tracks_[i].motion.started() || !candidates[i]) continue;
    const std::vector<MarkerCandidate>& list = *candidates[i];
    for (size_t c = 0; c < list.size(); ++c) {
      if (!Fits(list[c].verdict)) continue;
      const size_t k = pool(list[c].position_px);
      if (report_pooled_[i] && k == *report_pooled_[i]) continue;
      entries_[i].push_back({k, c, list[c].misfit});
    }
  }
  // The cost matrix.
  for (size_t i = 0; i < markers.size(); ++i) {
    cost_[i].assign(pooled_.size(), kForbidden);
    unassigned_[i] = kUnassignedCost;
    const Track& t = tracks_[i];
    for (const Entry& e : entries_[i]) {
      const cv::Point2d p = pooled_[e.pooled].position_px;
      if (!t.motion.started()) {
        // No track yet: the tracker's own first acquisition (its report only).
        if (report_pooled_[i] && e.pooled == *report_pooled_[i]) {
          cost_[i][e.pooled] = kFirstAcquisitionCost;
        }
        continue;
      }
      const bool repeated = IsRepeat(t, p);
      const double d2 = t.motion.distance2(p);
      const double dist = cv::norm(p - t.motion.position());
      // Inside the gate, or within what the marker covers in a frame at its speed plus its own
      // size (it may stop or turn sharply within one frame: a bounce, a start).
      bool inside = d2 <= kGate2 || dist <= size_px_[i] + cv::norm(t.motion.velocity()) || repeated;
      if (!inside && t.misses > 0 && t.last_px) {
        // Coasting: the marker may have stopped, slowed or kept going since it was last seen.
        // Its reach is anywhere between where it was and where it would be now, plus the
        // gate's radius.
        inside = DistanceToSegment(p, *t.last_px, t.motion.position()) <=
                 size_px_[i] + std::sqrt(kGate2) * t.motion.sigma_px();
      }
      if (!inside) continue;
      cost_[i][e.pooled] =
          (repeated ? 0.0 : std::min(d2, kGate2) / kGate2) + kMisfitWeight * std::min(e.misfit, 2.0);
    }
  }
  const std::vector<int>& assigned = solver_.solve(cost_, unassigned_);
  for (size_t i = 0; i < markers.size(); ++i) {
    Observation& o = markers[i].observation;
    tracks_[i].restart = false;
    if (assigned[i] < 0) {
      if (o.found()) {
        if (tracks_[i].motion.started() && report_pooled_[i] &&
            ExtendsARejectedRun(i, *o.position_px)) {
          tracks_[i].restart = true;  // kKeep: the report stands, the track restarts on it.
          continue;
        }
        decisions_[i].action = Decision::Action::kReject;
        o = Observation::NotFound(MarkerStatus::kImplausible);
      } else {
        tracks_[i].pending_px.reset();  // The run is broken.
      }
      continue;
    }
    tracks_[i].pending_px.reset();
    const size_t k = static_cast<size_t>(assigned[i]);
    if (report_pooled_[i] && k == *report_pooled_[i]) {
      tracks_[i].repeated = IsRepeat(tracks_[i], *o.position_px);
      continue;  // kKeep.
    }
    for (const Entry& e : entries_[i]) {
      if (e.pooled != k || !e.tracker_index) continue;
      decisions_[i].action = Decision::Action::kAdopt;
      decisions_[i].candidate = *e.tracker_index;
    }
    if (decisions_[i].action != Decision::Action::kAdopt && o.found()) {
      decisions_[i].action = Decision::Action::kReject;
      o = Observation::NotFound(MarkerStatus::kImplausible);
    }
  }
  return decisions_;
}

bool MarkerTracks::ExplainedByAnother(size_t i, const cv::Point2d& p) const {
  for (size_t j = 0; j < tracks_.size(); ++j) {
    const Track& t = tracks_[j];
    if (j == i || !t.motion.started()) continue;
    const double reach = size_px_[j] + cv::norm(t.motion.velocity()) +
                         std::sqrt(kGate2) * t.motion.sigma_px();
    if (cv::norm(p - t.motion.position()) <= reach ||
        (t.last_px && cv::norm(p - *t.last_px) <= reach)) {
      return true;
    }
  }
  return false;
}

bool MarkerTracks::ExtendsARejectedRun(size_t i, const cv::Point2d& p) {
  Track& t = tracks_[i];
  // A look-alike another marker's track could take is that marker's business, not a run.
  if (ExplainedByAnother(i, p)) {
    t.pending_px.reset();
    return false;
  }
  bool extends = false;
  if (t.pending_px) {
    if (!t.pending_step_px) {
      // The second report of a run: its step is the run's first velocity, and the run must have
      // been able to leave the marker's last place at that speed.
      const double step_px = cv::norm(p - *t.pending_px);
      extends = t.last_px && cv::norm(*t.pending_px - *t.last_px) <=
                                 2.0 * size_px_[i] + kRunStartSteps * t.pending_gap * step_px;
    } else {
      const cv::Point2d expected = *t.pending_px + *t.pending_step_px;
      extends = cv::norm(p - expected) <=
                size_px_[i] + kRunStepTolerance * cv::norm(*t.pending_step_px);
    }
  }
  if (!extends) {
    t.pending_px = p;
    t.pending_step_px.reset();
    t.pending_reports = 1;
    t.pending_gap = std::min(1 + t.misses, kReacquireFrames);
    return false;
  }
  t.pending_step_px = p - *t.pending_px;
  t.pending_px = p;
  ++t.pending_reports;
  if (t.pending_reports < kReacquireFrames) return false;
  t.pending_px.reset();
  return true;
}

void MarkerTracks::commit(const std::vector<MarkerObservation>& markers) {
  CV_Assert(markers.size() == tracks_.size());
  for (size_t i = 0; i < markers.size(); ++i) {
    Track& t = tracks_[i];
    if (!t.predicted) t.motion.predict();
    t.predicted = false;
    const Observation& o = markers[i].observation;
    if (!o.found()) {
      t.repeats = 0;
      ++t.misses;
      continue;
    }
    t.misses = 0;
    const cv::Point2d p = *o.position_px;
    if (t.repeated && t.last_px && cv::norm(p - *t.last_px) <= kRepeatStillPx) {
      ++t.repeats;  // The prediction has moved on a frame, as the marker did behind the repeat.
      continue;
    }
    t.repeats = 0;
    if (!t.motion.started() || t.restart) {
      t.motion.start(p);
      t.restart = false;
    } else {
      t.motion.update(p);
    }
    t.last_px = p;
  }
}

}  // namespace softsight
