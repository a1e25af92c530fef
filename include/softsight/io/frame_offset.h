// The frame offset between two videos of one scene taken by two cameras started at different
// moments: which frame of the second video shows the moment of the first one's frame i.
//
// From a flash (a frame-wide brightness step both cameras see) when there is one, else by
// cross-correlating each video's motion over a bounded range of offsets. An estimate that is not
// clearly better than the alternatives is refused (no offset, and why), never guessed: a motion
// that repeats (a sinusoidal bend) fits several offsets, a still scene none.
//
// Each video is summarised frame by frame into a `SyncSignal` (one pass, buffers reused); the
// estimate is plain arithmetic on two signals.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

class FrameSource;

// One video's per-frame summary: its mean brightness and how much it moved since the previous
// frame.
class SyncSignal {
 public:
  // Adds the next frame (8-bit BGR or gray; every frame of one video the same size).
  void add(const cv::Mat& frame);

  size_t size() const { return brightness_.size(); }
  // Mean grey level of each frame (0..255).
  const std::vector<double>& brightness() const { return brightness_; }
  // Mean absolute difference from the previous frame (grey levels) of the frame reduced 4x
  // on each side, after taking each frame's mean away: a uniform change of light (a flash,
  // the exposure) is not motion. Frame 0: 0 (no previous frame).
  const std::vector<double>& motion() const { return motion_; }

 private:
  std::vector<double> brightness_, motion_;
  cv::Mat gray_, small_, previous_, difference_, absolute_;  // Reused from frame to frame.
};

// Reads `source` to its end (or `max_frames` frames) into a signal. Throws what read() throws.
SyncSignal MeasureSyncSignal(FrameSource& source, std::optional<int64_t> max_frames = {});

struct FrameOffsetOptions {
  // Offsets searched: -max_offset_frames .. max_offset_frames. Larger finds cameras started
  // further apart, at more risk of a chance match (and the videos must still overlap).
  int64_t max_offset_frames = 60;
  // A flash: the mean grey level rising by at least this much from one frame to the next
  // (grey levels). Lower catches a weaker flash, and mistakes a change of exposure for one.
  double flash_min_step = 20.0;
  // The motion's correlation at the offset chosen must reach min_correlation (0..1) and beat
  // the best other peak by min_margin. Lower accepts less distinct motion, at risk of a wrong
  // offset.
  double min_correlation = 0.6;
  double min_margin = 0.15;
  // An offset is tried only where the videos overlap by at least this many frames and at least
  // half of the shorter video: a short overlap correlates well by chance.
  int64_t min_overlap_frames = 20;

  // False with a one-line message naming the bad field.
  bool Check(std::string* error) const;
};

struct FrameOffsetEstimate {
  enum class Method { kFlash, kMotion };
  Method method = Method::kMotion;
  // Frame i of the first video shows the moment of frame i + offset_frames of the second.
  // Absent: refused, `refusal` says why.
  std::optional<int64_t> offset_frames{};
  std::string refusal{};
  // A flash: the frame where each video's brightness stepped up, and the steps (grey levels).
  std::optional<int64_t> left_flash_frame{}, right_flash_frame{};
  double left_flash_step = 0.0, right_flash_step = 0.0;
  // The motion: the correlation's best peak and the best other one (absent when there is none).
  std::optional<double> peak_correlation{};
  std::optional<int64_t> peak_offset{};
  std::optional<double> second_correlation{};
  std::optional<int64_t> second_offset{};
  // The correlation (Pearson's r of the motion signals) at each offset searched, from
  // -max_offset_frames; absent where the overlap is too short or a signal does not vary.
  std::vector<std::optional<double>> correlation{};
};

// The flash first (the first step up of at least flash_min_step in each video, the two within
// max_offset_frames of each other), else the motion's correlation. Options must pass Check().
FrameOffsetEstimate EstimateFrameOffset(const SyncSignal& left, const SyncSignal& right,
                                        const FrameOffsetOptions& options = {});

// "flash", "motion".
const char* FrameOffsetMethodName(FrameOffsetEstimate::Method method);

// What a refusal calls the two inputs and the setting that gives the offset by hand: the
// program's options by default, a library call's own argument names otherwise.
struct FrameOffsetNames {
  std::string inputs = "--left and --right";
  std::string option = "--frame-offset N";
};

// Reads both sources (to their end, or `max_frames` frames each) and estimates the offset.
// Returns an estimate with an offset, or throws InputError in one line: "cannot find the frame
// offset between <inputs> within +-<max_offset_frames> frames: <refusal>; pass <option>" (also
// for options that fail Check()). Throws what the sources' read() throws.
FrameOffsetEstimate FindFrameOffset(FrameSource& left, FrameSource& right,
                                    const FrameOffsetOptions& options,
                                    std::optional<int64_t> max_frames,
                                    const FrameOffsetNames& names = {});

// One line (no newline) for an estimate with an offset: "frame offset 5 (right frame = left
// frame + 5), found from the motion: correlation 1.000, next best peak 0.635 at offset -15
// (searched +-60)", or "... found from a flash: left frame 20, right frame 13 (brightness steps
// 60.0 and 60.0 grey levels)".
std::string DescribeFrameOffset(const FrameOffsetEstimate& estimate,
                                const FrameOffsetOptions& options);

}  // namespace softsight
