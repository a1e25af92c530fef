// Whether the positions trackers report make sense together and over time. A tracker judges
// one candidate against its own marker's model; it cannot know that its marker was at the other
// end of the image a frame ago, or that the position it found would stretch the body to twice
// its length. Reports that break either are not believed:
//  - Motion: a marker tracked in the last frames has a predicted position (constant velocity);
//    a report farther from it than the marker's size, plus the speed it had, plus the prediction
//    error usual for it, is a jump (a look-alike, a corrupted frame). After a frame in which
//    nothing was believed the prediction reaches over the gap, and so it does after a repeated
//    frame (a moving marker standing exactly still for a frame or two: the footage repeats
//    frames to fill its rate).
//  - Arrangement: markers on one body (the chain, else the triple) keep their order along it and
//    their spacing changes smoothly. The segment lengths between neighbours along the body are
//    learned from the first frames in which all of them are found and agree, and then follow
//    slowly; a segment more than 1.5x longer or shorter than 0.6x its learned length in one frame
//    is a broken arrangement (1.25x either way for a marker just re-acquired, or back after frames
//    in which it was not believed), and so is a gap (markers not found in between) longer than 1.5x the
//    segments it spans. Of the two markers of a broken segment, the one the motion supports
//    less is the culprit (a marker just re-acquired has no support; when neither has, both).
// A marker re-acquired after being lost, or after it was found implausible, is checked against
// the arrangement only, never against its stale position: it may have moved anywhere meanwhile.
// A marker found implausible stays suspect until the arrangement vouches for it: its next reports
// are believed only beside a neighbour along the body found in the same frame, the segment
// between them within 1.25x of its learned length either way (the camera was bumped: the markers
// come back together, in their arrangement). A suspect report with no neighbour to check it
// against (the body was taken away and a look-alike of the background is all there is) is not
// believed. Markers off the body, or on a body whose arrangement is not learned yet, cannot be
// vouched for and are believed as before.
// Known limit: segment lengths say nothing of direction, so a look-alike at about the right
// distance from a believed neighbour passes on re-acquisition (the angle at the neighbour would
// tell, but it may change a lot during a long occlusion).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"

namespace softsight {

class MarkerPlausibility {
 public:
  // `size_px[i]`: a length of marker i's size (about its radius), the unit of its motion bounds.
  // `body`: indices of the markers along one body in order, base to tip (fewer than 3: no
  // arrangement is learned).
  MarkerPlausibility(std::vector<double> size_px, std::vector<size_t> body);

  // Checks this frame's reports. Implausible ones become NotFound(kImplausible); their indices
  // (ascending) are returned so the caller can reset those trackers. The result is reused.
  const std::vector<size_t>& check(int64_t frame_index, std::vector<MarkerObservation>& markers);

  // Marker `i` starts afresh (its tracker was rebuilt or re-selected): no motion history.
  void forget(size_t i);

  // The learned segment lengths along the body (empty until learned), for tests.
  const std::vector<double>& segment_px() const { return segment_px_; }

 private:
  struct Track {
    std::optional<cv::Point2d> last;  // Last believed position ...
    int64_t last_frame = 0;           // ... and its frame.
    cv::Point2d velocity{0, 0};       // px per frame, from consecutive believed positions.
    bool has_velocity = false;
    double residual_px = 0.0;         // Running mean of |position - prediction|.
    bool reacquiring = true;          // No motion history to check against.
    int still_frames = 0;             // Reports in a row exactly where it was (see .cc).
    bool suspect = false;             // Found implausible, not vouched for since (see above).
  };
  // Motion residual over its bound (> 1: a jump); absent when there is no history to check.
  std::optional<double> motion_ratio(size_t i, int64_t frame, const cv::Point2d& p) const;
  void reject(size_t i, std::vector<MarkerObservation>& markers);
  void check_arrangement(std::vector<MarkerObservation>& markers);
  void check_suspects(std::vector<MarkerObservation>& markers);
  void learn(const std::vector<MarkerObservation>& markers);

  std::vector<double> size_px_;
  std::vector<size_t> body_;
  std::vector<Track> tracks_;
  std::vector<double> segment_px_;           // Learned, one per neighbour pair along the body.
  std::vector<std::vector<double>> learning_;  // Candidate lengths from the first frames.
  std::vector<std::optional<double>> ratio_;   // This frame's motion ratios (reused).
  // This frame: the motion vouches for the report (believed in the frame before, and no jump).
  std::vector<bool> supported_;
  std::vector<size_t> rejected_;               // This frame's result (reused).
};

}  // namespace softsight
