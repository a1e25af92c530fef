#include "pipeline/frame_change.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <cstdint>
#include <cstdlib>

#include <opencv2/imgproc.hpp>

namespace softsight {
namespace {

// A garbage cell stays "garbage" for at most this many frames before it is taken as the scene
// (a finely textured object may really have come into view).
constexpr int kGarbageMemory = 10;
// After this many changed frames in a row the footage itself changes that much (a moving
// camera): the change becomes normal even when the frames do not look alike.
constexpr int kLongestChangeRun = 10;
// A frame with garbage in this share of its cells is one the decoder lost its place in: what is
// not garbage may be a stale copy of an earlier frame (FFV1 with a corrupt context keeps decoding
// garbage down to some row and leaves the rest of its buffer as it was), so nothing in it is
// believed, however long it lasts. A camera does not turn a tenth of its picture into
// random-byte texture at once (a garbage cell is 3x the texture it had, and > 45 grey levels).
constexpr double kGarbageFrameFraction = 0.1;
// A frame that changed as a whole but, once the change of light is taken out, in no more than
// this share of its cells is the same picture in another light (what moved: the actuator).
// Another video of the same rig, lit otherwise, still differs where its actuator is (a quarter
// of the cells in the tests).
constexpr double kRelitChangedFraction = 0.08;

// Correlation of two cells' samples, or 1 when either is too flat to tell (noise alone, whose
// pattern changes from frame to frame, correlates with nothing).
using CellSamples = decltype(FrameCell::gray);
float PatternCorrelation(const CellSamples& a, const CellSamples& b) {
  // Standard deviation of the samples below which a cell is flat: well above a camera's noise.
  constexpr float kTexturedSpread = 10.0f;
  float sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const float x = a[i], y = b[i];
    sa += x;
    sb += y;
    saa += x * x;
    sbb += y * y;
    sab += x * y;
  }
  const float n = static_cast<float>(a.size());
  const float va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  const float flat = kTexturedSpread * kTexturedSpread * n;
  if (va < flat || vb < flat) return 1.0f;
  return (sab - sa * sb / n) / std::sqrt(va * vb);
}

}  // namespace

bool FrameChangeDetector::Changed(const Cell& now, const Cell& before, const cv::Vec3f& gain,
                                  bool relit) {
  // 30 grey levels of mean colour over a whole cell: a marker moving a few pixels inside it
  // changes the mean by less; the picture being replaced, by more. Compared after the row's
  // change of light, which scales the texture too, and which leaves the pattern of a textured
  // cell as it was.
  const float colour =
      std::max({std::abs(now.b - gain[0] * before.b), std::abs(now.g - gain[1] * before.g),
                std::abs(now.r - gain[2] * before.r)});
  const float texture = before.texture * (gain[0] + gain[1] + gain[2]) / 3.0f;
  return colour > 30.0f || now.texture > 2.0f * texture + 10.0f ||
         now.texture < 0.5f * texture - 10.0f ||
         (relit && PatternCorrelation(now.gray, before.gray) < 0.3f);
}

cv::Vec3f FrameChangeDetector::row_gain(const std::vector<Cell>& now,
                                        const std::vector<Cell>& before, int row) {
  // Cells darker than this say little about a gain (noise and black level dominate).
  constexpr float kDarkest = 24.0f;
  constexpr float kLeast = 1.0f / 3.0f, kMost = 3.0f;
  cv::Vec3f gain(1.0f, 1.0f, 1.0f);
  const size_t first = static_cast<size_t>(row) * grid_.cols;
  for (int c = 0; c < 3; ++c) {
    ratios_.clear();
    for (size_t i = first; i < first + static_cast<size_t>(grid_.cols); ++i) {
      const float b = c == 0 ? before[i].b : c == 1 ? before[i].g : before[i].r;
      const float n = c == 0 ? now[i].b : c == 1 ? now[i].g : now[i].r;
      if (b >= kDarkest) ratios_.push_back(n / b);
    }
    // Half the row's cells at least must say: a change confined to a few cells is not the light.
    if (ratios_.size() * 2 < static_cast<size_t>(grid_.cols)) continue;  // cols >= 1: never empty.
    auto middle = ratios_.begin() + static_cast<std::ptrdiff_t>(ratios_.size() / 2);
    std::nth_element(ratios_.begin(), middle, ratios_.end());
    if (*middle >= kLeast && *middle <= kMost) gain[c] = *middle;
  }
  return gain;
}

bool FrameChangeDetector::Garbage(const Cell& now, const Cell& before) {
  // Uniform random bytes differ by ~85 levels between neighbours; camera noise of sigma 10 by
  // ~11, a marker's rim adds ~20 to its cell.
  return now.texture > 45.0f && now.texture > 3.0f * before.texture + 30.0f;
}

double FrameChangeDetector::changed_between(const std::vector<Cell>& a,
                                            const std::vector<Cell>& b, bool relit) {
  int changed = 0;
  for (int row = 0; row < grid_.rows; ++row) {
    const cv::Vec3f gain = relit ? row_gain(a, b, row) : cv::Vec3f(1.0f, 1.0f, 1.0f);
    const size_t first = static_cast<size_t>(row) * grid_.cols;
    for (size_t i = first; i < first + static_cast<size_t>(grid_.cols); ++i) {
      changed += Changed(a[i], b[i], gain, relit) ? 1 : 0;
    }
  }
  return a.empty() ? 0.0 : static_cast<double>(changed) / static_cast<double>(a.size());
}

void FrameChangeDetector::observe(const cv::Mat& bgr, bool key_frame) {
  CV_Assert(bgr.type() == CV_8UC3);
  if (bgr.size() != size_ || !has_normal_) {
    size_ = bgr.size();
    grid_ = CellGrid::For(size_);
    summariser_.summarise(bgr, grid_, now_);
    normal_ = now_;
    previous_ = now_;
    garbage_.assign(now_.size(), 0);
    ratios_.reserve(static_cast<size_t>(grid_.cols));
    has_normal_ = true;
    whole_frame_changed_ = false;
    changed_fraction_ = 0.0;
    garbage_fraction_ = 0.0;
    changed_run_ = 0;
    return;
  }
  summariser_.summarise(bgr, grid_, now_);
  change_accepted_ = false;
  changed_fraction_ = changed_between(now_, normal_, false);
  int garbage_cells = 0;
  for (size_t i = 0; i < now_.size(); ++i) garbage_cells += Garbage(now_[i], normal_[i]) ? 1 : 0;
  garbage_fraction_ = static_cast<double>(garbage_cells) / static_cast<double>(now_.size());
  // Footage that changes a lot from frame to frame (a moving camera) raises the bar.
  const double threshold = std::clamp(3.0 * usual_fraction_ + 0.15, 0.4, 0.95);
  bool normal = true;
  if (garbage_fraction_ >= kGarbageFrameFraction) {
    // Never the new normal, and no step towards it: the normal frame stays the last one before
    // the decoder went wrong, so the garbage stays garbage until a clean frame comes.
    whole_frame_changed_ = true;
    normal = false;
    changed_run_ = 0;
    alike_run_ = 0;
  } else if (changed_fraction_ > threshold &&
             changed_between(now_, normal_, true) <= kRelitChangedFraction) {
    // The light changed (a flicker, the exposure) and little else: the picture is the same.
    whole_frame_changed_ = false;
    changed_run_ = 0;
    alike_run_ = 0;
  } else if (changed_fraction_ > threshold) {
    // Frames that look alike (a change that stays) count towards accepting it.
    const bool alike = changed_run_ > 0 && changed_between(now_, previous_, false) < 0.5 * threshold;
    // A change that begins in a predicted frame, or in a key frame, may be the decoder's damage,
    // which every frame up to the next key frame repeats: it must be seen in a key frame after
    // the one it began in (in a camera's or an intra-only video's frames, the next frame).
    key_frame_in_run_ = changed_run_ > 0 && (key_frame_in_run_ || key_frame);
    ++changed_run_;
    alike_run_ = alike ? alike_run_ + 1 : 1;
    normal = (alike_run_ >= kFramesToAcceptAChange || changed_run_ >= kLongestChangeRun) &&
             key_frame_in_run_;
    if (normal) {
      before_change_ = normal_;
      change_accepted_ = true;
      usual_fraction_ = std::max(usual_fraction_, changed_fraction_ / 3.0);
      changed_run_ = 0;
      alike_run_ = 0;
    }
    whole_frame_changed_ = !normal;
  } else {
    whole_frame_changed_ = false;
    changed_run_ = 0;
    alike_run_ = 0;
    usual_fraction_ = 0.95 * usual_fraction_ + 0.05 * changed_fraction_;
  }
  for (size_t i = 0; i < now_.size(); ++i) {
    const bool garbage = Garbage(now_[i], normal_[i]) && garbage_[i] < kGarbageMemory;
    garbage_[i] = garbage ? static_cast<unsigned char>(garbage_[i] + 1) : 0;
    // The normal picture keeps what the garbage hides, so garbage that stays is still garbage.
    if (normal && !garbage) normal_[i] = now_[i];
  }
  std::swap(previous_, now_);
}

namespace {

// The cells' gray samples laid out as the image they were sampled from (CV_32F).
void SampleImage(const std::vector<FrameCell>& cells, const CellGrid& grid, cv::Mat& out) {
  out.create(grid.rows * kSamplesPerCell, grid.cols * kSamplesPerCell, CV_32F);
  for (int cy = 0; cy < grid.rows; ++cy) {
    for (int cx = 0; cx < grid.cols; ++cx) {
      const FrameCell& cell = cells[static_cast<size_t>(cy) * grid.cols + cx];
      for (int y = 0; y < kSamplesPerCell; ++y) {
        float* row = out.ptr<float>(cy * kSamplesPerCell + y) + cx * kSamplesPerCell;
        for (int x = 0; x < kSamplesPerCell; ++x) row[x] = cell.gray[y * kSamplesPerCell + x];
      }
    }
  }
}

// A phase correlation peak below this is no single clear translation (little texture, or the
// actuator's own motion as large as the background's).
constexpr double kMinShiftResponse = 0.15;
// The share of cells that must have changed against the normal frame for the camera to have
// moved.
constexpr double kCameraMovedFraction = 0.5;

}  // namespace

std::optional<cv::Point2d> FrameChangeDetector::camera_shift_px() {
  // Only a picture that changed as a whole moved with the camera: where a few cells changed,
  // the largest textured thing that moved (a cart, the actuator) would pass for the camera.
  if (!has_normal_ || !(change_accepted_ || changed_fraction_ >= kCameraMovedFraction)) {
    return std::nullopt;
  }
  // observe() left this frame's summary in previous_ and the frame before's in now_.
  SampleImage(change_accepted_ ? before_change_ : now_, grid_, samples_a_);
  SampleImage(previous_, grid_, samples_b_);
  if (window_.size() != samples_a_.size()) {
    cv::createHanningWindow(window_, samples_a_.size(), CV_32F);
  }
  double response = 0.0;
  const cv::Point2d shift = cv::phaseCorrelate(samples_a_, samples_b_, window_, &response);
  if (!(response >= kMinShiftResponse) || !(cv::norm(shift) >= 1.0) ||
      std::abs(shift.x) > samples_a_.cols / 4 || std::abs(shift.y) > samples_a_.rows / 4) {
    return std::nullopt;
  }
  return shift * static_cast<double>(grid_.step);
}

bool FrameChangeDetector::garbage_near(const cv::Point2d& image_px) const {
  if (!has_normal_ || !std::isfinite(image_px.x) || !std::isfinite(image_px.y)) return false;
  const int cx = std::clamp(static_cast<int>(image_px.x / grid_.cell_px), 0, grid_.cols - 1);
  const int cy = std::clamp(static_cast<int>(image_px.y / grid_.cell_px), 0, grid_.rows - 1);
  for (int y = std::max(0, cy - 1); y <= std::min(grid_.rows - 1, cy + 1); ++y) {
    for (int x = std::max(0, cx - 1); x <= std::min(grid_.cols - 1, cx + 1); ++x) {
      if (garbage_[static_cast<size_t>(y) * grid_.cols + x] != 0) return true;
    }
  }
  return false;
}

}  // namespace softsight
