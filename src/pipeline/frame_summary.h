// The frame-change detector's summary of a frame (pipeline/frame_change.h): a sample every
// `step` pixels, 4 x 4 samples to a cell; per cell the mean colour, the texture (mean absolute
// difference of horizontally and vertically adjacent samples) and the samples' gray levels.
//
// It runs on every frame the session sees, so it must cost a small fraction of the trackers'
// work. Issue 26: the first version (a loop over the samples with three integer divisions and two
// branches per sample) cost 3x the three colour trackers at VGA. Issue 45: 8 x 8 samples to a
// cell, a sample every 4 px at VGA, still cost as many instructions as a BGR->gray pass of the
// whole frame (36 % of the session's time). The detector's questions are about whole cells (32 px
// at VGA) and the whole frame: most cells changed at once, a cell turned into decoded garbage, the
// picture shifted as a whole; a sample every 8 px answers them as one every 4 px did (the tests
// of the damaged, relit and bumped pictures, the real footage) for a quarter of the samples and
// half the rows read. FrameSummariser copies each sampled row into planes once, computes the
// row's differences and gray levels in loops the compiler vectorises, adds them up per column of
// samples, and per cell once a row of cells is complete. Every sum is an integer, so it is the
// same to the last bit as SummariseFrameReference, the obviously correct version it is tested
// against (frame_summary_test.cc: bit-identical on random, rendered and odd-sized frames).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace softsight {

// Samples per cell side: cells of 4 x 4 samples (32 px at VGA) hold a marker or two.
inline constexpr int kSamplesPerCell = 4;

struct FrameCell {
  float b = 0, g = 0, r = 0;  // Mean colour.
  // Mean over the cell's samples of each sample's mean |difference| to its left and upper
  // neighbours (per channel; over the neighbours it has).
  float texture = 0;
  std::array<uint8_t, kSamplesPerCell * kSamplesPerCell> gray{};  // The samples, (b + g + r) / 3.
};

// Where the samples and cells of a frame of some size are.
struct CellGrid {
  int step = 1;             // Sample spacing in pixels; samples at step / 2 + k * step.
  int cell_px = 1;          // Cell side in pixels (kSamplesPerCell * step).
  int cols = 0, rows = 0;   // Cells per row and column (at least 1 each); the last column and
                            // row of cells also hold the samples beyond cols * cell_px.
  // About 60 samples across the image's shorter side, whatever its resolution.
  static CellGrid For(cv::Size size);
};

// Summarises `bgr` (CV_8UC3, of the size `grid` was made for) into `cells` (row-major,
// grid.cols x grid.rows). Keeps its scratch rows: no allocation per frame once the size is set.
class FrameSummariser {
 public:
  void summarise(const cv::Mat& bgr, const CellGrid& grid, std::vector<FrameCell>& cells);

 private:
  // The sampled row and the one above it, as planes; the row's gray levels.
  std::vector<uint8_t> b_, g_, r_, above_b_, above_g_, above_r_, gray_;
  // Per column of samples, over the sampled rows of the current row of cells (at most 2 x 4 rows:
  // the last row of cells takes the rest): the sums of the channels and of the samples' texture
  // in sixths of a level (each at most 2 x 3 x 255), exact in 16 bits.
  std::vector<uint16_t> column_b_, column_g_, column_r_, column_texture_sixths_;
};

// The reference: one pass over the samples, each added to its cell as the definition says.
void SummariseFrameReference(const cv::Mat& bgr, const CellGrid& grid,
                             std::vector<FrameCell>& cells);

}  // namespace softsight
