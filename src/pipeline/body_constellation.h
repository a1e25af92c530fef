// Where a marker must be, given where the others are: the markers of one scene keep their
// arrangement from frame to frame (a plate of dots, a cube's face, a bending actuator's markers
// move together), so the markers believed in this frame say where a marker they moved with must
// be, whatever it looks like. This is the identity of a marker among look-alikes (identical white
// dots, a second cart's identical dot): its tracker cannot tell them apart, its own motion since
// it was lost reaches several of them, but only one lies where the body puts it.
//
// For each marker, the constellation remembers the positions of every marker believed in the
// last frame in which it was believed itself (its snapshot). The prediction of marker i in a new
// frame is the snapshot's position of i carried by the transform that best takes the snapshot's
// positions of the anchors (markers believed in this frame, inside their own motion gates) to
// where they are now, each anchor weighted by how still it keeps on the body: affine from three
// anchors or more (the body's motion, its distance to the camera and its tilt in perspective), a
// similarity from two or from anchors along one line, a translation from one (wide: the body may
// have turned about it). Its uncertainty is the fit's residual carried out to the marker (a body
// that deformed fits less well), the anchors' own noise, and how far the marker itself moves
// against its body per frame (learned while it is tracked: a bending actuator's tip moves against
// its base; a plate's dots never do) times the frames since its snapshot.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

class BodyConstellation {
 public:
  struct Prediction {
    cv::Point2d position_px;
    double sigma_px = 0.0;  // 1 sigma of the position (fit residual, relative motion, noise).
    int anchors = 0;        // How many markers it was predicted from.
    // The anchors fit the arrangement exactly (one; two for a similarity; three for an affine):
    // nothing checked that the body kept its shape (it may have bent beyond them).
    bool exact = false;
  };

  explicit BodyConstellation(size_t markers);

  // Marker i's position predicted from `anchors_px` (this frame's anchor positions; absent for a
  // marker that is no anchor; i's own entry is ignored), `frames_since` frames after i's
  // snapshot. Absent when no anchor was believed with i in its snapshot, or when the anchors no
  // longer have any extent (all at one place). From one anchor the prediction is its translation,
  // wide (the body may have turned or scaled about it): it can refuse a look-alike far off, never
  // vouch for a place.
  std::optional<Prediction> predict(size_t i, const std::vector<std::optional<cv::Point2d>>& anchors_px,
                                    int frames_since) const;

  // This frame's believed positions (absent: not believed). Each believed marker's snapshot
  // becomes this frame; `predicted[i]`, when given, was its prediction for this frame from the
  // other markers (with i continuing from the frame before): its miss teaches how far i moves
  // against its body per frame.
  void remember(const std::vector<std::optional<cv::Point2d>>& believed_px,
                const std::vector<std::optional<Prediction>>& predicted);

  // Marker i starts afresh (re-selected, or the video jumped): no snapshot.
  void forget(size_t i);

  // For tests: how far marker i was learned to move against its body per frame (px, 1 sigma).
  double relative_motion_px(size_t i) const { return relative_px_.at(i); }

 private:
  // Per marker: the positions of all markers in its snapshot frame (row i), whether it has one.
  std::vector<std::vector<std::optional<cv::Point2d>>> snapshot_;
  std::vector<uint8_t> has_snapshot_;
  // Per marker: running RMS of its prediction's miss in consecutive frames (px).
  std::vector<double> relative_px_;
  std::vector<int> relative_samples_;
  // How far marker i moves against its body per frame (px, 1 sigma), as far as it is known.
  double relative_of(size_t i) const;
  // Scratch for the fit (reused).
  mutable std::vector<cv::Point2d> from_, to_;
  mutable std::vector<double> weight_;
};

}  // namespace softsight
