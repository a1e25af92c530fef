// Track management and global association: which of this frame's candidates is which marker.
//
// Each marker has a track: a motion model (pipeline/motion_model.h) that predicts where it is
// and how far from there it can be. Per frame, every marker's candidates (its tracker's report
// and every other candidate its tracker found to fit the marker's model) are pooled; one
// candidate seen by several trackers (identical markers) is one candidate. The assignment of
// markers to candidates is solved globally at minimum cost (pipeline/assignment.h): the cost of
// a pair is its squared Mahalanobis distance from the marker's prediction, and a pair outside
// the marker's gate is not allowed. So two markers never take one candidate, a look-alike that
// another marker's track explains goes to that marker (or to nobody), and a report that no
// motion since the marker was last believed explains is not believed.
//
// Track states: none (never believed: the tracker's first acquisition, verified by its own model,
// is taken as it is, unless a started track claims that candidate), tentative (one believed
// report: velocity unknown, the gate is wide), confirmed, and coasting (not believed in the last
// frames: still predicted, its gate growing with the time since, so a re-acquisition must lie
// where a plausible motion could have taken the marker meanwhile). A marker that moved faster
// than its track allowed (a soft actuator at rest, then a sudden step of pressure) is not lost for
// good: when its tracker's own reports, rejected by the gate, follow one smooth motion of their
// own for kReacquireFrames frames in a row and no other marker's track explains any of them, the
// track restarts on them (the first frames stay not believed). The run must also be able to have
// left the marker's last believed place at its own speed: a look-alike elsewhere starts none.
//
// Two markers cannot be at one place: candidates closer than kCoincidentMarkerPx are one pooled
// candidate, which at most one marker takes. Nor can two markers swap places within a second: a
// candidate within kCoincidentMarkerPx of where another marker was believed a moment ago
// (kRecentPlaceFrames), while that marker has no report it can have made now, is not allowed to
// any other marker that was not there itself (a decoding error that shifted the colours of part
// of a frame shows one marker in another's colour; a look-alike at its place). And a candidate
// next to decoded garbage (the caller says where) is no candidate at all.
//
// Candidates no marker takes are things of their own (a look-alike, a second cart's identical
// dot), followed from frame to frame by their own constant velocity while they keep being seen.
// One that was, in its first frame, where marker i could not be (marker i believed elsewhere in
// that same frame, or just lost and the thing outside its reach) is another object for as long
// as it is followed: marker i never takes it, however far its reach grows since. So a lost
// marker is not re-acquired on a look-alike that was in view, elsewhere, when it was lost.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/assignment.h"
#include "pipeline/body_constellation.h"
#include "pipeline/motion_model.h"
#include "softsight/core/types.h"
#include "softsight/track/tracker.h"

namespace softsight {

// Distinct markers on one body are at least a marker diameter apart; a false lock lands on the
// neighbour's centroid to within a pixel or two. 3 px separates the two cases for markers of any
// usable size (radius >= 2 px).
inline constexpr double kCoincidentMarkerPx = 3.0;

class MarkerTracks {
 public:
  // What the session does with a marker's tracker after association.
  struct Decision {
    enum class Action : uint8_t {
      kKeep,    // The report stands (or there was none).
      kReject,  // The report is not believed: NotFound(kImplausible), the tracker searches afresh.
      kAdopt,   // Candidate `candidate` of the tracker's last update is the marker.
    };
    Action action = Action::kKeep;
    size_t candidate = 0;
    // The marker was re-acquired (or jumped) where the other markers' arrangement puts it, within
    // a tolerance tighter than its size: the body vouches for it, whatever its own motion said.
    bool vouched_by_body = false;
  };

  // `size_px[i]`: about marker i's radius. A report within it of the prediction is always inside
  // the gate (a start, a stop, a sharp turn within one frame).
  explicit MarkerTracks(std::vector<double> size_px, MotionModelOptions motion = {});

  // Whether a place is next to what the decoder made of damaged data (frame_change.h): nothing
  // seen there is a candidate.
  using GarbageTest = std::function<bool(const cv::Point2d&)>;

  // The association of this frame. `markers`: the trackers' reports; `candidates[i]`: what
  // marker i's tracker weighed (may be empty); `garbage_near`: where the frame is damaged (empty:
  // nowhere). Rejected reports are turned into NotFound(kImplausible) here; adopted ones are left
  // to the caller (the tracker makes the candidate its report). Returns one decision per marker
  // (reused).
  const std::vector<Decision>& associate(
      std::vector<MarkerObservation>& markers,
      const std::vector<const std::vector<MarkerCandidate>*>& candidates,
      const GarbageTest& garbage_near = {});
  // The frame's believed reports (after every other check) update the tracks. Call once per
  // frame after associate().
  void commit(const std::vector<MarkerObservation>& markers);
  // Whether a marker believed in the last frame has no report inside its gate in this one
  // (`markers`: the trackers' reports, before associate()): the moment to ask whether the
  // camera moved.
  bool AnyJustLost(const std::vector<MarkerObservation>& markers);
  // The one translation that every marker believed in the last frame made at once (each report
  // this frame outside its gate, all of them within a marker's size of the same step from their
  // predictions; two such markers at least): the camera moved, or the whole body at once, where
  // the picture around it is too plain to tell (pipeline/frame_change.h). Absent otherwise.
  std::optional<cv::Point2d> CommonShift(const std::vector<MarkerObservation>& markers);
  // The camera moved the picture by `shift_px` since the last frame: every track (and every
  // other object) moves with it, when that brings more of the markers' reports into their gates
  // than it takes out (a shift that explains no report is not the markers' camera). Returns
  // whether the tracks moved.
  bool FollowCamera(const std::vector<MarkerObservation>& markers, const cv::Point2d& shift_px);
  // A frame in which nothing was believed (it changed as a whole): the tracks are predicted over
  // it, nothing else.
  void skip();
  // Marker i starts afresh (re-selected, re-specified, or the video jumped): no motion.
  void forget(size_t i);
  // Where the markers were believed a moment ago says nothing any more (a person re-selected a
  // marker, perhaps at the place of another): the swap rule (see the file comment) waits for new
  // believed places.
  void forget_places();

  // Where marker i's track stands after this frame's commit() (or skip()).
  TrackState state(size_t i) const;

  // Whether this frame's report of marker i restarts its track (a run of its tracker's own
  // reports the gate had rejected): its motion before is no evidence against it.
  bool restarting(size_t i) const { return tracks_.at(i).restart; }

  // How well a report of marker i at `p` continues its track, for the checks after association
  // (pipeline/arrangement_check.h): its distance from the track's prediction in gate units (0 at
  // the prediction, 1 at the Mahalanobis gate's edge; 0 for a repeated frame) when the marker was
  // believed in the last frame and `p` lies in its gate proper. Absent when its motion does not
  // support the report: no track, coasting, restarting, or outside the gate. Call between
  // associate() and commit().
  std::optional<double> MotionSupport(size_t i, const cv::Point2d& p) const;

  // For tests: marker i's motion model.
  const MotionModel& motion(size_t i) const { return tracks_.at(i).motion; }
  // For tests: how many other objects are followed, and how many of them marker i may never take.
  size_t others() const { return active_others_; }
  size_t others_excluded_for(size_t i) const;

 private:
  struct Track {
    MotionModel motion;
    bool predicted = false;       // predict() ran for this frame.
    int repeats = 0;              // Reports in a row exactly where the last one was.
    int misses = 0;               // Frames since the last believed report.
    // Frames since last_px was believed, frames nothing was believed in included (the swap rule's
    // "a moment ago").
    int since_believed = 0;
    std::optional<cv::Point2d> last_px;  // The last believed report.
    bool repeated = false;        // This frame's report is a repeated frame (see commit).
    // Reports the gate rejected, while they follow one motion of their own: the last one, the
    // step between the last two, how many in a row.
    std::optional<cv::Point2d> pending_px;
    std::optional<cv::Point2d> pending_step_px;
    int pending_reports = 0;
    int pending_gap = 1;          // Frames from the last believed report to the run's first.
    bool restart = false;         // This frame's report restarts the track (see commit).
  };
  struct Pooled {
    cv::Point2d position_px;
  };
  static bool IsRepeat(const Track& t, const cv::Point2d& p);
  // Whether a started track other than `i`'s could take a report at `p`.
  bool ExplainedByAnother(size_t i, const cv::Point2d& p) const;
  // Whether `p` lies in marker i's gate proper: inside the Mahalanobis gate, within its size plus
  // a frame's motion of its prediction, or a repeated frame.
  bool InGate(size_t i, const cv::Point2d& p) const;
  // Whether a report at `p` continues marker i's track: believed in the last frame, and `p` in
  // its gate proper.
  bool Continues(size_t i, const cv::Point2d& p) const {
    return tracks_[i].misses == 0 && InGate(i, p);
  }
  // Whether marker i's started track can be at `p` this frame: inside its gate, within its size
  // plus a frame's motion, a repeated frame, or, while coasting, within reach of anywhere between
  // where it was last seen and where it would be now.
  bool InReach(size_t i, const cv::Point2d& p) const;
  // Whether a report at `p` would continue some started marker's track.
  bool ContinuesAnyTrack(const cv::Point2d& p) const;
  // Whether pooled candidate k is followed as another object that marker i may never take.
  bool IsOtherObject(size_t i, size_t k) const {
    return pooled_other_[k] && others_[*pooled_other_[k]].not_marker[i];
  }
  // Follows the candidates no marker took (see the file comment); `assigned`: the solver's.
  void FollowOthers(const std::vector<int>& assigned);
  void MatchOthers();
  // Marker i's report at `p` was rejected: true when it extends a run of rejected reports that
  // follows one smooth motion for kReacquireFrames frames (the track then restarts on it).
  bool ExtendsARejectedRun(size_t i, const cv::Point2d& p);
  void predict_all();
  // Where the body puts marker i this frame (see body_constellation.h), from the markers whose
  // reports continue their tracks inside their gates.
  void predict_from_body(const std::vector<MarkerObservation>& markers);
  // Whether a report at `p` that does not continue marker i's track (a re-acquisition, or a jump
  // out of its gate) lies where the body puts it (always true when the body says nothing), and
  // whether the body alone vouches for it.
  bool BodyAllows(size_t i, const cv::Point2d& p) const;
  bool BodyVouches(size_t i, const cv::Point2d& p) const;
  // The pooled candidate at `p` (a marker of about `size_px`), added when there is none.
  size_t pool(const cv::Point2d& p, double size_px);
  // Whether marker i may not take a candidate at `p` because another marker, believed there a
  // moment ago, has no report of its own it can have made now (see the file comment).
  bool OnAMissingMarkersPlace(size_t i, const cv::Point2d& p,
                              const std::vector<MarkerObservation>& markers) const;
  // associate()'s steps. Each marker's entries: its report and the other candidates that fit it
  // (not those next to decoded garbage), pooled.
  void gather_entries(const std::vector<MarkerObservation>& markers,
                      const std::vector<const std::vector<MarkerCandidate>*>& candidates,
                      const GarbageTest& garbage_near);
  // The pooled candidates inside a started marker's gate proper that its tracker did not list.
  void add_unlisted_in_gates();
  // The cost of marker i taking pooled candidate k (its tracker's misfit `misfit`); none when it
  // may not take it.
  std::optional<double> cost_of(size_t i, size_t k, double misfit,
                                const std::vector<MarkerObservation>& markers) const;
  // The decisions from the solver's assignment: keep, adopt or reject each marker's report.
  void apply_assignment(const std::vector<int>& assigned, std::vector<MarkerObservation>& markers);

  std::vector<double> size_px_;
  std::vector<Track> tracks_;
  bool skipped_ = false;  // The last frame was skip()ped, not commit()ted.
  BodyConstellation body_;
  std::vector<std::optional<cv::Point2d>> anchor_px_, believed_px_;
  std::vector<std::optional<BodyConstellation::Prediction>> body_prediction_, learn_from_;
  std::vector<Decision> decisions_;
  // Per frame, reused: the pooled candidates, each marker's (pooled index, tracker index,
  // misfit) entries, the cost matrix and the report's pooled index per marker.
  std::vector<Pooled> pooled_;
  struct Entry {
    size_t pooled;
    std::optional<size_t> tracker_index;  // Absent: the report itself (no candidate list).
    double misfit;
  };
  std::vector<std::vector<Entry>> entries_;
  std::vector<std::vector<double>> cost_;
  std::vector<double> unassigned_;
  std::vector<std::optional<size_t>> report_pooled_;
  MinimumCostAssignment solver_;

  // Other objects (see the file comment): others_[0, active_others_) are followed; the rest are
  // kept for reuse (their vectors keep their capacity).
  struct Other {
    cv::Point2d position_px;
    std::optional<cv::Point2d> step_px;  // Between its last two sightings.
    int unseen = 0;                      // Frames since it was last seen.
    std::vector<uint8_t> not_marker;     // Per marker: 1 when that marker may never take it.
  };
  std::vector<Other> others_;
  size_t active_others_ = 0;
  std::vector<std::optional<size_t>> pooled_other_;  // Per pooled candidate: the other it is.
  struct OtherPair {
    double distance_px;
    size_t pooled, other;
  };
  std::vector<OtherPair> other_pairs_;
  std::vector<uint8_t> other_seen_, pooled_taken_;
};

}  // namespace softsight
