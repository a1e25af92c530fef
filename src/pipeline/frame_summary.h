// The frame-change detector's summary of a frame (pipeline/frame_change.h): a sample every
// `step` pixels, 8 x 8 samples to a cell; per cell the mean colour, the texture (mean absolute
// difference of horizontally and vertically adjacent samples) and the samples' gray levels.
//
// It runs on every frame the session sees, so it must cost a small fraction of the trackers'
// work (issue 26: the first version, one loop over the samples with three integer divisions and
// two branches per sample, cost 3x the three colour trackers at VGA). FrameSummariser copies
// each sampled row into planes once, computes the row's differences and gray levels in loops
// the compiler vectorises, and adds them up cell by cell, each cell's samples in the order the
// reference adds them, so the floating-point sums are the same to the last bit.
// SummariseFrameReference is the obviously correct version it is tested against
// (frame_summary_test.cc: bit-identical on random, rendered and odd-sized frames).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

// Samples per cell side: cells of 8 x 8 samples (32 px at VGA) hold a marker or two.
inline constexpr int kSamplesPerCell = 8;

struct FrameCell {
  float b = 0, g = 0, r = 0;  // Mean colour.
  float texture = 0;          // Mean |difference| of horizontally and vertically adjacent samples.
  std::array<uint8_t, 64> gray{};  // The cell's 8 x 8 samples, (b + g + r) / 3.
};

// Where the samples and cells of a frame of some size are.
struct CellGrid {
  int step = 1;             // Sample spacing in pixels; samples at step / 2 + k * step.
  int cell_px = 1;          // Cell side in pixels (kSamplesPerCell * step).
  int cols = 0, rows = 0;   // Cells per row and column (at least 1 each); the last column and
                            // row of cells also hold the samples beyond cols * cell_px.
  // About 120 samples across the image's shorter side, whatever its resolution.
  static CellGrid For(cv::Size size);
};

// Summarises `bgr` (CV_8UC3, of the size `grid` was made for) into `cells` (row-major,
// grid.cols x grid.rows). Keeps its scratch rows: no allocation per frame once the size is set.
class FrameSummariser {
 public:
  void summarise(const cv::Mat& bgr, const CellGrid& grid, std::vector<FrameCell>& cells);

 private:
  // The sampled row and the one above it, as planes; the row's per-sample texture and gray.
  std::vector<uint8_t> b_, g_, r_, above_b_, above_g_, above_r_, gray_;
  std::vector<float> texture_;
  std::vector<int> sum_b_, sum_g_, sum_r_;  // Per cell, exact (at most 16 x 16 samples of 255).
};

// The reference: one pass over the samples, each added to its cell as the definition says.
void SummariseFrameReference(const cv::Mat& bgr, const CellGrid& grid,
                             std::vector<FrameCell>& cells);

}  // namespace softsight
