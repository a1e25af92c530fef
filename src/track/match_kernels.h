// Template-matching kernels: SAD, SSD and ZNCC score maps, each with a vector implementation
// (OpenCV universal intrinsics, 128-bit: SSE2 on any x86-64, NEON on ARM) and a slow, obviously
// correct scalar reference beside it. This file pair and colour_kernels are softsight's SIMD.
//
// Every kernel computes, for each placement (x, y) of the w x h template fully inside the image,
// one score over all w*h pixels and all channels, into a (W - w + 1) x (H - h + 1) map:
//   SAD(x, y)  = sum |I - T|                                  CV_32S, exact
//   SSD(x, y)  = sum (I - T)^2                                CV_32S, exact
//   ZNCC(x, y) = sum (I - mean I)(T - mean T) /
//                sqrt(sum (I - mean I)^2 * sum (T - mean T)^2)  CV_32F, in [-1, 1]
// For colour (CV_8UC3) the means are taken per channel and the sums run over all channels (the
// definition cv::matchTemplate's TM_CCOEFF_NORMED uses). A template may carry a mask: then every
// sum and mean runs over the masked-in pixels only (e.g. a round template for a disc marker, so
// the background around it, which rotates with the body, does not bias the match). ZNCC is
// undefined where the window is flat (zero variance): the map holds NaN there, which callers treat
// as "no match". A flat template is refused by PreparedTemplate::Prepare (it can match nothing).
//
// Why not cv::matchTemplate everywhere: it computes in float (SSD not exact; ZNCC off by ~1e-4
// and unstable on near-flat windows). Measured (template_matching_benchmark, 32x32 template): on
// the tracker's 48x48 window these kernels are faster (SSD 13 vs 31 us, ZNCC 12 vs 30 us); on a
// whole VGA frame OpenCV's DFT-based matchTemplate is faster (SSD 7.3 vs 10.2 ms). The tracker
// only meets large regions at coarse pyramid levels, so it uses these exact kernels throughout,
// which also makes windowed and whole-frame results bit-identical.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/track/template_tracker.h"

namespace softsight {

// Templates hold at most kMaxTemplateValues (softsight/track/template_tracker.h) values, so the
// SSD and cross-correlation sums fit the kernels' 32-bit accumulators.

// A template laid out for the vector kernels once (at init or recalibration), so that tracking
// does no per-frame preparation. Rows of w*C bytes are covered by 16-byte chunks; the last,
// partial chunk is loaded as two 8-byte halves that stay inside the row, with a mask that drops
// bytes already counted, so the kernels never read outside the window and need no padding.
class PreparedTemplate {
 public:
  // `templ` is CV_8UC1 or CV_8UC3, at most kMaxTemplateValues values. `mask` is empty or CV_8UC1
  // of the template's size; its nonzero pixels count. Returns false (and leaves the object empty)
  // when the counted pixels are flat: every channel constant, so ZNCC is undefined.
  bool Prepare(const cv::Mat& templ, const cv::Mat& mask = cv::Mat());

  bool empty() const { return image_.empty(); }
  const cv::Mat& image() const { return image_; }  // A continuous copy of the template.
  cv::Size size() const { return image_.size(); }
  int channels() const { return image_.channels(); }
  bool masked() const { return !mask_image_.empty(); }
  const cv::Mat& mask() const { return mask_image_; }  // Empty when every pixel counts.
  int count() const { return count_; }                 // Pixels that count.
  int values() const { return count_ * image_.channels(); }

  // Per-channel sums of T and T^2 (ZNCC needs them).
  const int64_t* sum() const { return sum_; }
  const int64_t* sum_sq() const { return sum_sq_; }
  // sum over channels of (N * sum T_c^2 - (sum T_c)^2), N = count(): N^2 times T's variance.
  int64_t scaled_variance() const { return scaled_variance_; }

 private:
  friend struct KernelAccess;
  // The counted pixels' runs of each row (run_rows_, runs_), from mask_image_.
  void find_runs();
  // The vector layout (row_bytes_ .. words_) of image_ and mask_image_.
  void lay_out_chunks();
  // The same for new pixels of the laid-out size, channels and mask: bytes_ and words_ only.
  void lay_out_bytes();
  cv::Mat image_;
  cv::Mat mask_image_;
  int count_ = 0;
  int64_t sum_[3] = {0, 0, 0};
  int64_t sum_sq_[3] = {0, 0, 0};
  int64_t scaled_variance_ = 0;
  // Vector layout, per template row: `full_chunks_` 16-byte chunks, then an optional tail chunk
  // made of two 8-byte halves at byte offsets tail_lo_ and tail_hi_ of the row.
  int row_bytes_ = 0;
  int full_chunks_ = 0;
  bool has_tail_ = false;
  int tail_lo_ = 0;
  int tail_hi_ = 0;
  int chunks_per_row_ = 0;
  std::vector<uint8_t> bytes_;  // [row][chunk] 16 bytes: template values, masked bytes zero.
  std::vector<uint8_t> mask_;   // [row][chunk] 16 bytes: 0xFF where the byte counts.
  std::vector<int16_t> words_;  // [row][chunk] 16 values: the bytes widened to 16 bits.
  std::vector<int> lane_bytes_;  // Preparation's scratch: the row byte each lane of a row reads.
  // The counted pixels of row r are the runs [run_rows_[r], run_rows_[r + 1]) of runs_, each the
  // pixel columns [begin, end) (unmasked: the whole row). Masked ZNCC and SSD take the window
  // sums over them from row prefix sums, two look-ups per run (a round mask has one run a row).
  struct Run {
    int begin, end;
  };
  std::vector<int> run_rows_;
  std::vector<Run> runs_;
};

// Fast kernels. `image` has the template's type and is at least as large. `result` is
// (re)allocated only when its size or type changes, so a tracker reusing it allocates nothing.
void MatchSad(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result);
// Scratch buffers for ZNCC and SSD: the window sums (integral images for unmasked ZNCC; else row
// prefix sums and one map row of sums over the counted pixels) and the cross-correlation map,
// which both are built on. Vectors keep their capacity when a tracker matches windows of
// changing sizes, so its matching allocates nothing from frame to frame.
struct ZnccScratch {
  cv::Mat sum, sum_sq, cross;
  std::vector<uint32_t> prefix_sum, row_sum;
  std::vector<int> cross_values;
  std::vector<int16_t> widened;  // The image widened to 16 bits for the cross-correlation.
  // The row prefix sums of one gray image shared by the windows of it matched next
  // (ShareWindowSums): its first pixel (nullptr: none shared), its step and size.
  const uint8_t* shared_image = nullptr;
  size_t shared_step = 0;
  cv::Size shared_size;
  std::vector<uint32_t> shared_prefix;
  // The shared image widened to 16 bits for the cross-correlation of its windows (widened on the
  // first window matched, then read by each: every window was widened on its own, issue 45),
  // with one value of padding after it; valid when shared_widened_ready.
  std::vector<int16_t> shared_widened;
  bool shared_widened_ready = false;
};
// Computes the row prefix sums of `image` (CV_8UC1; anything else shares nothing) once, for
// every window of it that MatchZncc or MatchSsd matches a masked template in with this scratch
// next: a tracker matches several overlapping windows of the part of a frame it converted (the
// search, the measurement, the pose rungs), and each computed the prefix sums of its own rows
// (issue 45). The same sums, the same bits. The caller keeps `image`'s pixels as they are until
// StopSharingWindowSums (or another ShareWindowSums).
void ShareWindowSums(const cv::Mat& image, ZnccScratch& scratch);
inline void StopSharingWindowSums(ZnccScratch& scratch) {
  scratch.shared_image = nullptr;
  scratch.shared_widened_ready = false;
}
// SSD = sum I^2 - 2 sum I*T + sum T^2, from the window sums and the cross-correlation (exact).
// Without `scratch`, its buffers are allocated for the call.
void MatchSsd(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result,
              ZnccScratch& scratch);
void MatchSsd(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result);
void MatchZncc(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result,
               ZnccScratch& scratch);
// ZNCC of one placement (`top_left`) of a gray template, the value MatchZncc's map holds there,
// bit for bit (the same exact integer sums), without building a map: no window sums, no
// widened copy (one placement through MatchZncc cost ten times as much: the template update's
// drift guard, every frame, issue 45). False (nothing computed) for colour, or a template too
// narrow for the vector layout, or without vector code: use MatchZncc.
bool MatchZnccAt(const cv::Mat& image, cv::Point top_left, const PreparedTemplate& templ,
                 float* zncc);

// The cross-correlation (MatchZncc's and MatchSsd's sum I * T) runs in 256-bit AVX2 lanes where
// the processor has them (asked at run time: the build itself targets the baseline), else in
// 128-bit lanes; the same exact integer sums. Tests only: whether the AVX2 kernel can run here,
// and a switch to the 128-bit one (on: the default where it can run).
bool WideCrossKernelAvailable();
void UseWideCrossKernel(bool on);

// Slow scalar references, straight from the definitions (ZNCC in double with explicit means).
// `mask` as in PreparedTemplate::Prepare.
void MatchSadReference(const cv::Mat& image, const cv::Mat& templ, cv::Mat& result,
                       const cv::Mat& mask = cv::Mat());
void MatchSsdReference(const cv::Mat& image, const cv::Mat& templ, cv::Mat& result,
                       const cv::Mat& mask = cv::Mat());
void MatchZnccReference(const cv::Mat& image, const cv::Mat& templ, cv::Mat& result,
                        const cv::Mat& mask = cv::Mat());

}  // namespace softsight
