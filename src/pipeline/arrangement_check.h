// Whether the positions trackers report make sense together: markers on one body (the chain,
// else the triple) keep their order along it and their spacing changes smoothly. A tracker
// judges one candidate against its own marker's model, and the association judges each marker
// against its own motion (pipeline/marker_tracks.h, the one motion model); neither can tell that a
// report would stretch the body to twice its length. Reports that would are not believed:
//  - The segment lengths between neighbours along the body are learned from the first frames in
//    which all of them are found and agree, and then follow slowly; a segment more than 1.5x
//    longer or shorter than 0.6x its learned length in one frame is a broken arrangement (1.25x
//    either way when a marker of it is not supported by its motion), and so is a gap (markers not
//    found in between) longer than 1.5x the segments it spans.
//  - Of the two markers of a broken segment, the one its motion supports less is the culprit. A
//    report is supported when it continues its marker's track (believed in the last frame, and
//    inside its gate); its support is its distance from the track's prediction in gate units
//    (`MarkerTracks::MotionSupport`). A report without support (re-acquired, restarted, after
//    frames not believed) is all there is of its marker: when neither has support, both go.
// A marker found to break the arrangement stays suspect until the arrangement vouches for it: its
// next reports are believed only beside a neighbour along the body found in the same frame, the
// segment between them within 1.25x of its learned length either way (the camera was bumped: the
// markers come back together, in their arrangement). A suspect report with no neighbour to check
// it against (the body was taken away and a look-alike of the background is all there is) is not
// believed. Markers off the body, or on a body whose arrangement is not learned yet, cannot be
// vouched for and are believed as before.
// Known limit: segment lengths say nothing of direction, so a look-alike at about the right
// distance from a believed neighbour passes on re-acquisition (the angle at the neighbour would
// tell, but it may change a lot during a long occlusion).
#pragma once

#include <optional>
#include <vector>

#include "softsight/core/types.h"

namespace softsight {

class ArrangementCheck {
 public:
  // `body`: indices of the markers along one body in order, base to tip (fewer than 3: no
  // arrangement is learned). `markers`: how many markers the session has.
  ArrangementCheck(size_t markers, std::vector<size_t> body);

  // Checks this frame's reports. `motion_support[i]`: how well marker i's report continues its
  // track (0 at the prediction, 1 at the gate's edge), absent when its motion does not support
  // it. Reports that break the arrangement become NotFound(kImplausible); their indices
  // (ascending) are returned so the caller can reset those trackers. The result is reused.
  const std::vector<size_t>& check(std::vector<MarkerObservation>& markers,
                                   const std::vector<std::optional<double>>& motion_support);

  // Marker `i` starts afresh (a person placed it, its tracker was rebuilt, or the body vouched
  // for it): it is no longer suspect.
  void forget(size_t i);

  // The learned segment lengths along the body (empty until learned), for tests.
  const std::vector<double>& segment_px() const { return segment_px_; }

 private:
  void reject(size_t i, std::vector<MarkerObservation>& markers);
  void check_segments(std::vector<MarkerObservation>& markers,
                      const std::vector<std::optional<double>>& motion_support);
  void check_suspects(std::vector<MarkerObservation>& markers);
  void learn(const std::vector<MarkerObservation>& markers);

  std::vector<size_t> body_;
  std::vector<bool> suspect_;                  // Broke the arrangement, not vouched for since.
  std::vector<double> segment_px_;             // Learned, one per neighbour pair along the body.
  std::vector<std::vector<double>> learning_;  // Candidate lengths from the first frames.
  std::vector<size_t> rejected_;               // This frame's result (reused).
};

}  // namespace softsight
