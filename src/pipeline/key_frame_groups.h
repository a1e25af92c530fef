// A video that predicts frames from earlier ones (MPEG-4, H.264) repeats damage in every frame
// up to its next key frame, which is decoded afresh. The video source leaves out the frames the
// decoder complained about or concealed damage in and the ones after them (io/decode_probe.h);
// this is for damage the decoder neither reported nor concealed (a flipped bit that still
// decodes: a key frame whose macroblocks slid 16 px, a patch copied to the wrong place). No check
// of one frame can tell such a picture from a real one (a slid picture looks like a bumped
// camera), but the next key frame can: the damage ends exactly there. A marker that the damage
// moved by D comes back by -D at the key frame, after moving by +D where the damage began; real
// motion does not jump to and fro exactly at a key frame.
//
// So a run over such a video holds each group of frames (a key frame and the predicted frames
// after it) until the next key frame has been tracked, checks every marker across that key
// frame, and only then hands the group on. A marker whose position at the key frame jumps
// back by what it jumped at an earlier frame of the group (both far beyond the group's own
// motion noise) is not believed from that earlier frame to the end of the group: its
// observation becomes `implausible` and the frame's measurements, which used it, absent.
// Frames of a camera, an image sequence or an intra-only video are all key frames: they pass
// straight through.
//
// A damaged key frame can also change how the marker moves through its group (the predicted
// frames carry the damage on with their own motion), so the jump back at the next key frame
// does not undo the jump in: a marker that jumps away from its past exactly at the group's key
// frame and jumps again at the next one is not believed anywhere in the group. The two jumps
// are judged against the group's own frames (their motion and scatter without the jumps, which
// would swamp them in a damaged group's short, erratic track). A single change of motion at a
// key frame (a bounce) is believed.
//
// The marker's past is its last believed position in the last few frames handed on (it may be
// hidden in the frame just before the group). When the key frame cannot vouch for a marker (its
// tracker refused what it saw there, or the marker is not there), a jump in the group is not
// believed either, from the jump on; and a marker with no such past and not found at the key
// frame after the group is not believed anywhere in the group (nothing ties those positions to
// the marker: a key frame the damage moved it in). A marker found in too few of the group's
// frames to know its motion there (after damage a tracker often finds it only here and there)
// is not believed in them either: there is nothing to check them against. The last group of a
// run that ended with damage (the decoder reported it, the file was cut) is checked the same
// way, as no key frame follows it.
//
// What it cannot see: damage that grows over several frames (no single jump where it began), a
// damaged group whose own frames scatter as much as its jumps, and damage in the last group of a
// video the decoder did not complain about or conceal damage in.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"
#include "softsight/pipeline/stereo_session.h"

namespace softsight {

class KeyFrameGroups {
 public:
  // A held frame handed on, in source order.
  using Release = std::function<void(const Frame& frame, const FrameResult& result)>;

  // Groups that would hold more than `max_held_bytes` of images, or more than `max_held_frames`
  // frames, are handed on unchecked as the limit is reached (counted in unchecked_frames()).
  // `hold_images` false: the frames are held without their pixels (what receives them reads only
  // the results, e.g. a CSV): a group then costs its rows, not its pictures, and frames handed on
  // have an empty image.
  explicit KeyFrameGroups(size_t max_held_bytes = size_t{512} << 20, bool hold_images = true,
                          size_t max_held_frames = kMaxHeldFrames)
      : max_held_bytes_(max_held_bytes), max_held_frames_(max_held_frames),
        hold_images_(hold_images) {}
  // Twenty seconds at 30 fps (libx264's default key-frame interval is 250 frames; a VGA group
  // with images reaches the byte limit at 582): a longer group is not checked beyond it, and its
  // rows wait no longer than this for their check.
  static constexpr size_t kMaxHeldFrames = 600;

  // From the next frame on, hold images too (a sink that reads them joined the run).
  void hold_images() { hold_images_ = true; }

  // The next frame and its result: held, or handed on (with any group this frame ends) through
  // `release` before add() returns.
  void add(const Frame& frame, const FrameResult& result, const Release& release);
  // The end of the run: the held group, unchecked (no key frame follows it). A run that ended
  // with damage (`damaged`: the decoder reported it, or the file was cut) does not believe a
  // marker's jump in that group, nor a marker the frame before the group did not have.
  void flush(const Release& release, bool damaged = false);

  // Marker-frames found to be the decoder's damage and reported implausible instead.
  int64_t demoted() const { return demoted_; }
  // Frames handed on without a check: groups over the memory limit, and the last group.
  int64_t unchecked_frames() const { return unchecked_frames_; }

 private:
  struct Held {
    Frame frame;
    FrameResult result;
  };
  // Demotes, in the held group, what the key frame `next` shows to be damage.
  void check(const FrameResult& next);
  // A marker the key frame after the group does not show: a jump in the group is not believed.
  void check_unverified(size_t marker);
  bool jumps_at_both_ends(double threshold);
  std::optional<double> track(size_t marker, const Observation* key, int64_t key_index);
  void demote_from(size_t marker, int64_t first_damaged);
  void remember(const FrameResult& released);
  void hold(const Frame& frame, const FrameResult& result);
  void release_held(const Release& release, bool checked);

  size_t max_held_bytes_;
  size_t max_held_frames_;
  bool hold_images_;
  bool predicted_seen_ = false;  // Until a predicted frame comes, every frame passes through.
  std::vector<Held> held_;       // Slots reused across groups: their images keep their buffers.
  size_t count_ = 0;             // held_[0, count_) is the open group.
  size_t held_bytes_ = 0;
  // Per marker, its position in the last frame handed on that found and believed it, while that
  // is one of the last few frames handed on (a group's track starts there).
  struct Anchor {
    int64_t index;
    cv::Point2d px;
    int frames_since;  // Frames handed on since and including it.
  };
  std::vector<std::optional<Anchor>> tail_;
  const Anchor* anchor(size_t marker) const;
  // check()'s scratch, per marker.
  std::vector<int64_t> indices_;
  std::vector<cv::Point2d> points_, residuals_;
  std::vector<double> scratch_;
  int64_t demoted_ = 0;
  int64_t unchecked_frames_ = 0;
};

// A pair's frames (two views, pipeline/stereo_session.h) through the same check: each view's
// groups are checked by a KeyFrameGroups of their own, as one view's are (the two views' key
// frames need not come together: two cameras, two encoders), and a pair goes on once both its
// frames have been checked, in source order. A marker either view's check did not believe is
// not found in 3D in that pair (its status "left_implausible" or "right_implausible", as for a
// view that did not find it), and the pair's 3D shape and segments, measured with it, are
// absent; the view's own angle (angle_left_deg / angle_right_deg) is as that view's check left
// it. Only key frames so far: pairs pass straight through.
class PairKeyFrameGroups {
 public:
  using Release = std::function<void(const FramePair& pair, const StereoFrameResult& result)>;

  // `max_held_bytes` bounds the held pairs' pictures (both views); beyond it the held pairs go
  // on unchecked. `hold_images` false: the pairs are held without their pixels.
  explicit PairKeyFrameGroups(size_t max_held_bytes = size_t{512} << 20, bool hold_images = true);
  ~PairKeyFrameGroups();
  PairKeyFrameGroups(const PairKeyFrameGroups&) = delete;
  PairKeyFrameGroups& operator=(const PairKeyFrameGroups&) = delete;

  void hold_images() { hold_images_ = true; }
  // The next pair and its result (its left_view and right_view set, as StereoSession gives
  // them): held, or handed on with every pair now checked in both views through `release`. A
  // pair handed on has its left_view / right_view pointing at its views' checked results, valid
  // during release().
  void add(const FramePair& pair, const StereoFrameResult& result, const Release& release);
  // The end of the run: every held pair, each view's last group unchecked (KeyFrameGroups::flush).
  void flush(const Release& release, bool damaged = false);
  // Pair marker-frames no longer found because a view's check did not believe the marker.
  int64_t demoted() const { return demoted_; }

 private:
  struct Held {
    FramePair pair;
    StereoFrameResult result;
    FrameResult left, right;  // Each view's result as its check handed it back.
  };
  void release_ready(const Release& release);
  void believe_views(Held& held);

  size_t max_held_bytes_;
  bool hold_images_;
  bool predicted_seen_ = false;
  KeyFrameGroups left_, right_;
  // held_[0, count_) are held in source order; each view's check has handed back
  // held_[0, left_done_) and held_[0, right_done_); held_[0, head_) have gone on (moved out at
  // the end of release_ready). Slots are reused: their buffers stay.
  std::vector<Held> held_;
  size_t count_ = 0, left_done_ = 0, right_done_ = 0, head_ = 0;
  size_t held_bytes_ = 0;
  KeyFrameGroups::Release left_checked_, right_checked_, pass_;
  int64_t demoted_ = 0;
};

}  // namespace softsight
