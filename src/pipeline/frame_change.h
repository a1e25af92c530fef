// Frames that no motion explains: a frame from another video, a block of decoded garbage, a
// flash. Trackers answer such frames with confident positions (a blob of the right colour is
// somewhere in any picture), so the session must know before it believes them.
//
// The frame is summarised on a coarse grid of cells (a sample every few pixels,
// pipeline/frame_summary.h, so it costs a fraction of one BGR->gray pass): per cell the mean
// colour and the texture (mean absolute difference of neighbouring samples). Each frame is
// compared with the last frame judged normal:
//  - most cells changed at once (far more than the footage's usual frame-to-frame change): the
//    whole frame changed. A change that persists (the light was switched on, the camera was
//    bumped) becomes the new normal after a few frames. A change of the light alone is not a
//    change of the picture: such a frame is compared again, each row of cells after the gain
//    (per channel) that best maps the normal frame's row onto it (the median of the cells'
//    ratios, 1/3x to 3x), and where the light changes nothing else either (the pattern inside a
//    textured cell still correlates), and at most a few cells changed (where the actuator
//    moved), it is believed: a flickering lamp, the camera's exposure, a rolling shutter's bands
//    under mains light. A frame from another video of the same rig, lit otherwise, still differs
//    where its actuator is. In a video that predicts frames from earlier ones (MPEG-4, H.264),
//    a change is accepted only once a key frame after the one it began in shows it: the
//    decoder's silent damage (a flipped bit in a key frame) lasts exactly up to the next key
//    frame and looks like a lasting change until then.
//  - a cell whose texture exploded (random bytes are ~85 grey levels between neighbours, camera
//    images a few): decoded garbage there; markers in or next to it are not trusted. Garbage in
//    a tenth of the frame or more: the decoder lost its place, and the rest of the frame may be
//    a stale copy of an earlier one; the whole frame is not believed for as long as it lasts.
//
// It also tells how far the camera moved: the translation between the summaries' gray samples
// (phase correlation), of the last frame against this one, or across a change just accepted as
// the new normal (a bumped camera), so the markers' tracks can follow the picture.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/frame_summary.h"

namespace softsight {

class FrameChangeDetector {
 public:
  // Frames in a row that must look alike (each compared with the one before) before a sudden
  // change is accepted as the new normal.
  static constexpr int kFramesToAcceptAChange = 3;

  // Compares `bgr` (CV_8UC3) with the last normal frame; call once per frame, before the
  // queries below. A frame of another size starts afresh (it is taken as normal). `key_frame`:
  // Frame::key_frame (a video that predicts frames repeats a damaged picture up to its next key
  // frame, so a lasting change is accepted only once a later key frame shows it).
  void observe(const cv::Mat& bgr, bool key_frame = true);

  // The frame changed all at once, or is largely decoded garbage: nothing found in it can be
  // trusted.
  bool whole_frame_changed() const { return whole_frame_changed_; }
  // The neighbourhood of `image_px` holds garbage (texture far beyond what it had).
  bool garbage_near(const cv::Point2d& image_px) const;

  // How far the picture moved as a whole (the camera) since the frame before, in px: on the
  // frame where a lasting change was just accepted as the new normal, since the last normal
  // frame before that change. Absent when the picture did not change as a whole (half its cells
  // or more: else what moved may be the largest moving thing in view, not the camera), when it
  // cannot tell (too little texture, no clear single translation), or when the picture did not
  // move by a sample or more. Computed on demand (a phase
  // correlation of the summaries' samples: about 60 x 80 at any resolution).
  std::optional<cv::Point2d> camera_shift_px();

 private:
  using Cell = FrameCell;
  static bool Changed(const Cell& now, const Cell& before, const cv::Vec3f& gain, bool relit);
  static bool Garbage(const Cell& now, const Cell& before);
  // The per-channel gain that maps row `row` of `before` onto `now` (1 where it cannot tell).
  cv::Vec3f row_gain(const std::vector<Cell>& now, const std::vector<Cell>& before, int row);
  // Share of cells changed from `b` to `a`; `relit`: after each row's change of light.
  double changed_between(const std::vector<Cell>& a, const std::vector<Cell>& b, bool relit);

  cv::Size size_;             // Of the frames summarised so far.
  CellGrid grid_;             // Their samples and cells.
  FrameSummariser summariser_;
  std::vector<Cell> now_, normal_, previous_;  // Reused: no allocation per frame.
  // The normal frame before a change that was accepted on this frame (for camera_shift_px).
  std::vector<Cell> before_change_;
  bool change_accepted_ = false;
  cv::Mat samples_a_, samples_b_, window_;  // camera_shift_px's scratch.
  std::vector<float> ratios_;                  // row_gain's scratch.
  std::vector<unsigned char> garbage_;         // Per cell: frames in a row it held garbage.
  bool has_normal_ = false;
  bool whole_frame_changed_ = false;
  double changed_fraction_ = 0.0;
  double garbage_fraction_ = 0.0;
  double usual_fraction_ = 0.0;  // Running mean of changed_fraction_ over normal frames.
  int changed_run_ = 0;          // Consecutive frames that changed against the normal one.
  int alike_run_ = 0;            // ... of which the last ones looked like each other.
  bool key_frame_in_run_ = false;  // ... of which one after the first was a key frame.
};

}  // namespace softsight
