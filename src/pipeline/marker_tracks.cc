#include "pipeline/marker_tracks.h"

#include <algorithm>
#include <cmath>

#include "track/repeated_frames.h"

namespace softsight {
namespace {

// The gate: a squared Mahalanobis distance of 16 is 4 sigma (2 degrees of freedom: a report
// inside it by chance 1 time in 3000).
constexpr double kGate2 = 16.0;
// Candidates within this of each other are one blob seen by several trackers, or within this
// fraction of the marker's size (two blobs of that size cannot lie closer than twice it; a
// template's second peak is placed only to about a pixel, its centre not yet measured).
constexpr double kSamePlacePx = 1.0;
constexpr double kSamePlaceSizes = 0.5;
// Costs (unitless): an allowed pair costs its distance2 / kGate2 (at most 1) plus a little of
// the tracker's misfit; a first acquisition (no track yet) costs more than any allowed pair, so
// a candidate a started track explains goes to that track; leaving a marker unassigned costs
// more than both, so a marker takes a candidate whenever one is allowed.
constexpr double kMisfitWeight = 0.05;
// The misfit of a candidate in a marker's gate that its tracker did not list: worse than any the
// tracker lists, so its own candidates come first.
constexpr double kUnlistedMisfit = 2.0;
constexpr double kFirstAcquisitionCost = 1.2;
constexpr double kUnassignedCost = 1.5;
// Rejected reports in a row, on one smooth motion, that restart a track: 0.1 s at 30 fps.
constexpr int kReacquireFrames = 3;
// How long a marker's last believed place still says where it is for the swap rule ("a moment
// ago"): a second at 30 fps. A damaged stretch of a recording lasts several frames; a marker that
// really moves onto the place of one lost that long ago is missed for the frame or two it spends
// there.
constexpr int kRecentPlaceFrames = 30;
// How far a rejected report may lie from where the run's constant velocity puts it: the
// marker's size plus this fraction of the run's step (it may be slowing down or speeding up).
constexpr double kRunStepTolerance = 0.5;
// A run must start where it could have left the marker's last believed place at the run's own
// speed: within twice the marker's size plus this many of its steps per frame since (counted up
// to kReacquireFrames). A look-alike that stands still, or moves, far from there starts no run.
constexpr double kRunStartSteps = 1.5;
// Another object may go unseen this many frames and still be followed (a tracker that switched
// from its window to the whole frame lists it again a frame later); longer, it is forgotten.
constexpr int kOtherUnseenFrames = 1;
// Its first step may be this many marker sizes plus the fastest marker's speed; later steps lie
// within a size plus kRunStepTolerance of its step from where its constant velocity puts it.
constexpr double kOtherFirstStepSizes = 3.0;
// A report that does not continue its marker's track must lie within this many sigma of where
// the body puts it (4 sigma in 2 degrees of freedom: 1 time in 3000 by chance) ...
constexpr double kBodyGateSigmas = 4.0;
// ... and no closer than this is ever asked of it (px): sub-pixel noise is not a contradiction.
constexpr double kBodyGateMinPx = 1.5;

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
    : size_px_(std::move(size_px)), body_(size_px_.size()) {
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
  anchor_px_.resize(size_px_.size());
  believed_px_.resize(size_px_.size());
  body_prediction_.resize(size_px_.size());
  learn_from_.resize(size_px_.size());
}

void MarkerTracks::forget(size_t i) {
  for (size_t o = 0; o < active_others_; ++o) others_[o].not_marker[i] = 0;
  Track& t = tracks_.at(i);
  t.motion.clear();
  t.pending_px.reset();
  t.restart = false;
  t.last_px.reset();
  t.repeats = 0;
  t.misses = 0;
  t.since_believed = 0;
  body_.forget(i);
  body_prediction_[i].reset();
}

void MarkerTracks::predict_all() {
  for (Track& t : tracks_) {
    if (!t.predicted) t.motion.predict();
    t.predicted = true;
  }
}

void MarkerTracks::predict_from_body(const std::vector<MarkerObservation>& markers) {
  for (size_t j = 0; j < markers.size(); ++j) {
    const Track& t = tracks_[j];
    const Observation& o = markers[j].observation;
    anchor_px_[j].reset();
    if (t.motion.started() && o.found() && Continues(j, *o.position_px)) {
      anchor_px_[j] = *o.position_px;
    }
  }
  for (size_t i = 0; i < markers.size(); ++i) {
    const Track& t = tracks_[i];
    body_prediction_[i] = t.motion.started() ? body_.predict(i, anchor_px_, t.misses + 1)
                                             : std::nullopt;
  }
}

namespace {

double BodyGatePx(const BodyConstellation::Prediction& p) {
  return std::max(kBodyGateMinPx, kBodyGateSigmas * p.sigma_px);
}

}  // namespace

bool MarkerTracks::BodyAllows(size_t i, const cv::Point2d& p) const {
  const std::optional<BodyConstellation::Prediction>& b = body_prediction_[i];
  return !b || cv::norm(p - b->position_px) <= BodyGatePx(*b);
}

bool MarkerTracks::BodyVouches(size_t i, const cv::Point2d& p) const {
  const std::optional<BodyConstellation::Prediction>& b = body_prediction_[i];
  // Only a tolerance tighter than the marker's size tells it from a look-alike beside it.
  return b && BodyGatePx(*b) <= size_px_[i] && cv::norm(p - b->position_px) <= BodyGatePx(*b);
}

void MarkerTracks::skip() {
  skipped_ = true;
  predict_all();
  for (Track& t : tracks_) {
    t.predicted = false;
    ++t.since_believed;
  }
}

void MarkerTracks::forget_places() {
  for (Track& t : tracks_) t.since_believed = kRecentPlaceFrames + 1;
}

bool MarkerTracks::OnAMissingMarkersPlace(size_t i, const cv::Point2d& p,
                                          const std::vector<MarkerObservation>& markers) const {
  const auto recently_at = [&](size_t j) {
    const Track& t = tracks_[j];
    return t.last_px && t.since_believed <= kRecentPlaceFrames &&
           cv::norm(p - *t.last_px) < kCoincidentMarkerPx;
  };
  if (recently_at(i)) return false;  // Still at its own place, whatever another's record says.
  for (size_t j = 0; j < tracks_.size(); ++j) {
    if (j == i || !recently_at(j)) continue;
    // Marker j is missing unless it has a report its motion can have made (a report out of its
    // reach is not believed).
    const Observation& o = markers[j].observation;
    const bool reported = o.found() && (!tracks_[j].motion.started() || InReach(j, *o.position_px));
    if (!reported) return true;
  }
  return false;
}

size_t MarkerTracks::pool(const cv::Point2d& p, double size_px) {
  // Two markers cannot be at one place: what lies closer than kCoincidentMarkerPx is one.
  const double same_px = std::max({kSamePlacePx, kCoincidentMarkerPx, kSamePlaceSizes * size_px});
  for (size_t k = 0; k < pooled_.size(); ++k) {
    if (cv::norm(pooled_[k].position_px - p) <= same_px) return k;
  }
  pooled_.push_back({p});
  return pooled_.size() - 1;
}

const std::vector<MarkerTracks::Decision>& MarkerTracks::associate(
    std::vector<MarkerObservation>& markers,
    const std::vector<const std::vector<MarkerCandidate>*>& candidates,
    const GarbageTest& garbage_near) {
  CV_Assert(markers.size() == tracks_.size() && candidates.size() == tracks_.size());
  predict_all();
  pooled_.clear();
  gather_entries(markers, candidates, garbage_near);
  add_unlisted_in_gates();
  MatchOthers();
  predict_from_body(markers);
  // The cost matrix.
  for (size_t i = 0; i < markers.size(); ++i) {
    cost_[i].assign(pooled_.size(), kForbidden);
    unassigned_[i] = kUnassignedCost;
    for (const Entry& e : entries_[i]) {
      if (const std::optional<double> cost = cost_of(i, e.pooled, e.misfit, markers)) {
        cost_[i][e.pooled] = *cost;
      }
    }
  }
  const std::vector<int>& assigned = solver_.solve(cost_, unassigned_);
  apply_assignment(assigned, markers);
  FollowOthers(assigned);
  return decisions_;
}

void MarkerTracks::gather_entries(const std::vector<MarkerObservation>& markers,
                                  const std::vector<const std::vector<MarkerCandidate>*>& candidates,
                                  const GarbageTest& garbage_near) {
  // A position next to decoded garbage is whatever the garbage made of the marker: no candidate.
  const auto damaged = [&](const cv::Point2d& p) { return garbage_near && garbage_near(p); };
  for (size_t i = 0; i < markers.size(); ++i) {
    decisions_[i] = Decision{};
    entries_[i].clear();
    report_pooled_[i].reset();
    tracks_[i].repeated = false;
    const Observation& o = markers[i].observation;
    if (o.found() && !damaged(*o.position_px)) {
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
      report_pooled_[i] = pool(*o.position_px, size_px_[i]);
      entries_[i].push_back({*report_pooled_[i], index, misfit});
    }
    // The other candidates that fit the marker: the one the tracker did not choose (a twin it
    // could not tell apart, or one farther from its own prediction) may be the marker.
    if (!tracks_[i].motion.started() || !candidates[i]) continue;
    const std::vector<MarkerCandidate>& list = *candidates[i];
    for (size_t c = 0; c < list.size(); ++c) {
      if (!Fits(list[c].verdict) || damaged(list[c].position_px)) continue;
      const size_t k = pool(list[c].position_px, size_px_[i]);
      if (report_pooled_[i] && k == *report_pooled_[i]) continue;
      entries_[i].push_back({k, c, list[c].misfit});
    }
  }
}

void MarkerTracks::add_unlisted_in_gates() {
  // A candidate inside a started marker's gate proper (its prediction, not a coasting reach) that
  // its tracker did not list (lost, or covered, this frame) is still that marker's to explain:
  // it may take it (and stays not found: its tracker did not verify it), so a marker coasting
  // with a wide reach does not take the place another marker was just predicted at. Only a
  // marker believed in the last frame has such a gate: one coasting for a while has a gate grown
  // wide with it (a finger over it for ten frames: 47 px), and its tracker's silence there is no
  // claim on the place another marker's own tracker recognises.
  for (size_t j = 0; j < tracks_.size(); ++j) {
    const Track& t = tracks_[j];
    if (!t.motion.started() || t.misses > 0) continue;
    for (size_t k = 0; k < pooled_.size(); ++k) {
      const cv::Point2d p = pooled_[k].position_px;
      bool listed = false;
      for (const Entry& e : entries_[j]) listed = listed || e.pooled == k;
      if (listed || !InGate(j, p)) continue;
      entries_[j].push_back({k, std::nullopt, kUnlistedMisfit});
    }
  }
}

std::optional<double> MarkerTracks::cost_of(size_t i, size_t k, double misfit,
                                            const std::vector<MarkerObservation>& markers) const {
  const Track& t = tracks_[i];
  const cv::Point2d p = pooled_[k].position_px;
  if (OnAMissingMarkersPlace(i, p, markers)) return std::nullopt;
  if (!t.motion.started()) {
    // No track yet: the tracker's own first acquisition (its report only), unless another
    // marker's first acquisition is the same place: nothing tells which marker it is.
    bool claimed = false;
    for (size_t j = 0; j < markers.size(); ++j) {
      claimed = claimed || (j != i && !tracks_[j].motion.started() && report_pooled_[j] &&
                            *report_pooled_[j] == k);
    }
    if (report_pooled_[i] && k == *report_pooled_[i] && !claimed) return kFirstAcquisitionCost;
    return std::nullopt;
  }
  const bool continues = Continues(i, p);
  const double motion_fit =
      IsRepeat(t, p) ? 0.0 : std::min(t.motion.distance2(p), kGate2) / kGate2;
  double fit = 0.0;
  if (BodyVouches(i, p)) {
    // Where the others put it (re-acquired, or jumped with its body: a shaken plate). That
    // outweighs having been followed as another object meanwhile.
    const BodyConstellation::Prediction& b = *body_prediction_[i];
    const double d = cv::norm(p - b.position_px) / BodyGatePx(b);
    fit = continues ? std::min(motion_fit, d * d) : d * d;
  } else if (IsOtherObject(i, k)) {
    return std::nullopt;
  } else if (continues) {
    // The track goes on: its motion judges the report.
    fit = motion_fit;
  } else if (InReach(i, p) && BodyAllows(i, p)) {
    // Re-acquired within its motion's reach, and not where the body says it cannot be.
    fit = motion_fit;
  } else {
    return std::nullopt;
  }
  return fit + kMisfitWeight * std::min(misfit, 2.0);
}

void MarkerTracks::apply_assignment(const std::vector<int>& assigned,
                                    std::vector<MarkerObservation>& markers) {
  for (size_t i = 0; i < markers.size(); ++i) {
    Observation& o = markers[i].observation;
    tracks_[i].restart = false;
    if (assigned[i] < 0) {
      if (o.found()) {
        // (A run may restart the track on an object followed as another one: the run's own
        // start, near where the marker was last believed, is the evidence it is the marker.)
        // (Not on a candidate another marker took: two markers cannot be at one place.)
        const bool taken = report_pooled_[i] &&
                           std::find(assigned.begin(), assigned.end(),
                                     static_cast<int>(*report_pooled_[i])) != assigned.end();
        if (tracks_[i].motion.started() && report_pooled_[i] && !taken &&
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
    {
      const cv::Point2d p = pooled_[k].position_px;
      decisions_[i].vouched_by_body =
          tracks_[i].motion.started() && !Continues(i, p) && BodyVouches(i, p);
    }
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
}

bool MarkerTracks::AnyJustLost(const std::vector<MarkerObservation>& markers) {
  CV_Assert(markers.size() == tracks_.size());
  predict_all();
  for (size_t i = 0; i < tracks_.size(); ++i) {
    const Track& t = tracks_[i];
    if (!t.motion.started() || t.misses > 0) continue;
    const Observation& o = markers[i].observation;
    if (!o.found() || !InGate(i, *o.position_px)) return true;
  }
  return false;
}

std::optional<cv::Point2d> MarkerTracks::CommonShift(
    const std::vector<MarkerObservation>& markers) {
  CV_Assert(markers.size() == tracks_.size());
  predict_all();
  cv::Point2d sum(0, 0);
  int count = 0;
  for (size_t i = 0; i < tracks_.size(); ++i) {
    const Track& t = tracks_[i];
    if (!t.motion.started() || t.misses > 0) continue;
    const Observation& o = markers[i].observation;
    if (!o.found()) continue;
    if (InGate(i, *o.position_px)) return std::nullopt;  // This one did not move with the rest.
    sum += *o.position_px - t.motion.position();
    ++count;
  }
  if (count < 2) return std::nullopt;
  const cv::Point2d mean = sum * (1.0 / count);
  for (size_t i = 0; i < tracks_.size(); ++i) {
    const Track& t = tracks_[i];
    const Observation& o = markers[i].observation;
    if (!t.motion.started() || t.misses > 0 || !o.found()) continue;
    if (cv::norm(*o.position_px - t.motion.position() - mean) > size_px_[i]) return std::nullopt;
  }
  return mean;
}

bool MarkerTracks::FollowCamera(const std::vector<MarkerObservation>& markers,
                                const cv::Point2d& shift_px) {
  CV_Assert(markers.size() == tracks_.size());
  predict_all();
  int gained = 0, lost = 0;
  for (size_t i = 0; i < tracks_.size(); ++i) {
    const Track& t = tracks_[i];
    const Observation& o = markers[i].observation;
    if (!t.motion.started() || !o.found()) continue;
    const bool before = InGate(i, *o.position_px);
    const bool after = InGate(i, *o.position_px - shift_px);  // The track moved by the shift.
    gained += !before && after;
    lost += before && !after;
  }
  if (gained <= lost) return false;
  for (Track& t : tracks_) {
    if (!t.motion.started()) continue;
    t.motion.shift(shift_px);
    if (t.last_px) *t.last_px += shift_px;
    if (t.pending_px) *t.pending_px += shift_px;
  }
  for (size_t o = 0; o < active_others_; ++o) others_[o].position_px += shift_px;
  return true;
}

bool MarkerTracks::InGate(size_t i, const cv::Point2d& p) const {
  const Track& t = tracks_[i];
  // Inside the gate, or within what the marker covers in a frame at its speed plus its own size
  // (it may stop or turn sharply within one frame: a bounce, a start).
  return t.motion.distance2(p) <= kGate2 ||
         cv::norm(p - t.motion.position()) <= size_px_[i] + cv::norm(t.motion.velocity()) ||
         IsRepeat(t, p);
}

bool MarkerTracks::ContinuesAnyTrack(const cv::Point2d& p) const {
  for (size_t i = 0; i < tracks_.size(); ++i) {
    if (tracks_[i].motion.started() && Continues(i, p)) return true;
  }
  return false;
}

std::optional<double> MarkerTracks::MotionSupport(size_t i, const cv::Point2d& p) const {
  const Track& t = tracks_.at(i);
  if (!t.motion.started() || t.restart || skipped_ || !Continues(i, p)) return std::nullopt;
  return IsRepeat(t, p) ? 0.0 : std::sqrt(t.motion.distance2(p) / kGate2);
}

bool MarkerTracks::InReach(size_t i, const cv::Point2d& p) const {
  const Track& t = tracks_[i];
  if (InGate(i, p)) return true;
  // Coasting: the marker may have stopped, slowed or kept going since it was last seen. Its
  // reach is anywhere between where it was and where it would be now, plus the gate's radius.
  return t.misses > 0 && t.last_px &&
         DistanceToSegment(p, *t.last_px, t.motion.position()) <=
             size_px_[i] + std::sqrt(kGate2) * t.motion.sigma_px();
}

// Which pooled candidate continues which followed object: nearest first, each at most once, an
// object's next sighting within a size (plus half its step) of where its step puts it, its first
// step within kOtherFirstStepSizes sizes plus the fastest marker's speed.
void MarkerTracks::MatchOthers() {
  pooled_other_.assign(pooled_.size(), std::nullopt);
  if (active_others_ == 0) return;
  double size = 0, speed = 0;
  for (size_t i = 0; i < tracks_.size(); ++i) {
    size = std::max(size, size_px_[i]);
    if (tracks_[i].motion.started()) speed = std::max(speed, cv::norm(tracks_[i].motion.velocity()));
  }
  other_pairs_.clear();
  for (size_t o = 0; o < active_others_; ++o) {
    const Other& other = others_[o];
    const cv::Point2d step = other.step_px.value_or(cv::Point2d(0, 0)) * (1 + other.unseen);
    const double radius = other.step_px
                              ? size + kRunStepTolerance * cv::norm(step)
                              : kOtherFirstStepSizes * size + speed * (1 + other.unseen);
    for (size_t k = 0; k < pooled_.size(); ++k) {
      const double d = cv::norm(pooled_[k].position_px - (other.position_px + step));
      if (d > radius) continue;
      // An object seen once has no motion yet, only a wide reach for its first step; a candidate
      // that continues a marker's own track (believed in the last frame, inside its gate) is
      // explained by that track far better. Seen: a ball tossed past a lamp seen once took the
      // lamp's first step and was refused at the top of its arc.
      if (!other.step_px && ContinuesAnyTrack(pooled_[k].position_px)) continue;
      other_pairs_.push_back({d, k, o});
    }
  }
  std::sort(other_pairs_.begin(), other_pairs_.end(),
            [](const OtherPair& a, const OtherPair& b) { return a.distance_px < b.distance_px; });
  other_seen_.assign(active_others_, 0);
  for (const OtherPair& pair : other_pairs_) {
    if (pooled_other_[pair.pooled] || other_seen_[pair.other]) continue;
    pooled_other_[pair.pooled] = pair.other;
    other_seen_[pair.other] = 1;
  }
}

void MarkerTracks::FollowOthers(const std::vector<int>& assigned) {
  pooled_taken_.assign(pooled_.size(), 0);
  for (size_t i = 0; i < tracks_.size(); ++i) {
    if (assigned[i] >= 0) pooled_taken_[static_cast<size_t>(assigned[i])] = 1;
    if (tracks_[i].restart && report_pooled_[i]) pooled_taken_[*report_pooled_[i]] = 1;
  }
  // Every followed object goes unseen this frame unless a candidate no marker took continues it;
  // one a marker took is that marker, not another object.
  for (size_t o = 0; o < active_others_; ++o) ++others_[o].unseen;
  for (size_t k = 0; k < pooled_.size(); ++k) {
    const cv::Point2d p = pooled_[k].position_px;
    if (pooled_other_[k]) {
      Other& other = others_[*pooled_other_[k]];
      if (pooled_taken_[k]) {
        other.unseen = kOtherUnseenFrames + 1;  // Forgotten below.
      } else {
        other.step_px = (p - other.position_px) * (1.0 / other.unseen);
        other.position_px = p;
        other.unseen = 0;
      }
      continue;
    }
    if (pooled_taken_[k]) continue;
    // A new object. Where marker i could not be in this frame (believed elsewhere, or just lost
    // and this place beyond its reach), it is not marker i.
    if (active_others_ == others_.size()) others_.emplace_back();
    Other& other = others_[active_others_++];
    other.position_px = p;
    other.step_px.reset();
    other.unseen = 0;
    other.not_marker.assign(tracks_.size(), 0);
    for (size_t i = 0; i < tracks_.size(); ++i) {
      const Track& t = tracks_[i];
      if (!t.motion.started()) continue;
      const bool believed_elsewhere = assigned[i] >= 0;
      const bool just_lost = assigned[i] < 0 && t.misses <= 1 && !InReach(i, p);
      other.not_marker[i] = believed_elsewhere || just_lost;
    }
  }
  // Forget the objects not seen for too long (their vectors stay for reuse).
  for (size_t o = 0; o < active_others_;) {
    if (others_[o].unseen > kOtherUnseenFrames) {
      std::swap(others_[o], others_[--active_others_]);
    } else {
      ++o;
    }
  }
}

size_t MarkerTracks::others_excluded_for(size_t i) const {
  size_t n = 0;
  for (size_t o = 0; o < active_others_; ++o) n += others_[o].not_marker.at(i);
  return n;
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
  // A look-alike another marker's track could take is that marker's business, not a run; nor is
  // one where an arrangement checked by more anchors than it needs says the marker cannot be (one
  // its anchors fit exactly may have bent: an actuator's tip beyond its two neighbours).
  const std::optional<BodyConstellation::Prediction>& body = body_prediction_[i];
  if (ExplainedByAnother(i, p) || (body && !body->exact && !BodyAllows(i, p))) {
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

TrackState MarkerTracks::state(size_t i) const {
  const Track& t = tracks_.at(i);
  if (!t.motion.started()) return TrackState::kLost;
  if (t.misses == 0 && !skipped_) {
    return t.motion.updates() == 0 ? TrackState::kTentative : TrackState::kConfirmed;
  }
  // A skipped frame (nothing believed in it) counts as a miss.
  return t.misses + (skipped_ ? 1 : 0) <= kCoastFrames ? TrackState::kCoasting : TrackState::kLost;
}

void MarkerTracks::commit(const std::vector<MarkerObservation>& markers) {
  CV_Assert(markers.size() == tracks_.size());
  skipped_ = false;
  // The body remembers this frame's arrangement; a marker that continued its track teaches how
  // far it moves against its body in a frame.
  for (size_t i = 0; i < markers.size(); ++i) {
    const Observation& o = markers[i].observation;
    believed_px_[i] = o.found() ? o.position_px : std::nullopt;
    learn_from_[i] = o.found() && tracks_[i].motion.started() && tracks_[i].misses == 0
                         ? body_prediction_[i]
                         : std::nullopt;
    body_prediction_[i].reset();
  }
  body_.remember(believed_px_, learn_from_);
  for (size_t i = 0; i < markers.size(); ++i) {
    Track& t = tracks_[i];
    if (!t.predicted) t.motion.predict();
    t.predicted = false;
    const Observation& o = markers[i].observation;
    if (!o.found()) {
      t.repeats = 0;
      ++t.misses;
      ++t.since_believed;
      continue;
    }
    t.misses = 0;
    t.since_believed = 0;
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
