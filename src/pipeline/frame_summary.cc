#include "pipeline/frame_summary.h"

#include <algorithm>
#include <cstdlib>

namespace softsight {
namespace {

// About this many samples across the image's shorter side, whatever its resolution.
constexpr int kSamplesAcross = 120;

}  // namespace

CellGrid CellGrid::For(cv::Size size) {
  CellGrid grid;
  grid.step = std::max(1, std::min(size.width, size.height) / kSamplesAcross);
  grid.cell_px = grid.step * kSamplesPerCell;
  grid.cols = std::max(1, size.width / grid.cell_px);
  grid.rows = std::max(1, size.height / grid.cell_px);
  return grid;
}

void SummariseFrameReference(const cv::Mat& bgr, const CellGrid& grid,
                             std::vector<FrameCell>& cells) {
  CV_Assert(bgr.type() == CV_8UC3);
  const int step = grid.step, cell_px = grid.cell_px, cols = grid.cols, rows = grid.rows;
  cells.assign(static_cast<size_t>(cols) * rows, FrameCell());
  std::vector<int> counts(cells.size(), 0);
  const int half = step / 2;
  for (int y = half; y < bgr.rows; y += step) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    const cv::Vec3b* above = y - step >= 0 ? bgr.ptr<cv::Vec3b>(y - step) : nullptr;
    const int cy = std::min(y / cell_px, rows - 1);
    for (int x = half; x < bgr.cols; x += step) {
      const int cx = std::min(x / cell_px, cols - 1);
      FrameCell& cell = cells[static_cast<size_t>(cy) * cols + cx];
      const cv::Vec3b p = row[x];
      cell.b += p[0];
      cell.g += p[1];
      cell.r += p[2];
      float texture = 0.0f;
      int pairs = 0;
      if (x - step >= 0) {
        const cv::Vec3b q = row[x - step];
        texture += static_cast<float>(std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) +
                                      std::abs(p[2] - q[2]));
        ++pairs;
      }
      if (above != nullptr) {
        const cv::Vec3b q = above[x];
        texture += static_cast<float>(std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) +
                                      std::abs(p[2] - q[2]));
        ++pairs;
      }
      if (pairs > 0) cell.texture += texture / (3.0f * static_cast<float>(pairs));
      ++counts[static_cast<size_t>(cy) * cols + cx];
      // The sample's place in the cell's 8 x 8 grid (a border cell's extra samples are left out).
      const int sx = (x - cx * cell_px) / step, sy = (y - cy * cell_px) / step;
      if (sx < kSamplesPerCell && sy < kSamplesPerCell) {
        cell.gray[static_cast<size_t>(sy * kSamplesPerCell + sx)] =
            static_cast<uint8_t>((p[0] + p[1] + p[2]) / 3);
      }
    }
  }
  for (size_t i = 0; i < cells.size(); ++i) {
    if (counts[i] == 0) continue;
    const float n = static_cast<float>(counts[i]);
    cells[i].b /= n;
    cells[i].g /= n;
    cells[i].r /= n;
    cells[i].texture /= n;
  }
}

// Sample (i, j) of the grid is pixel (half + i * step, half + j * step), and it belongs to cell
// (min(i / 8, rows - 1), min(j / 8, cols - 1)) at place (i % 8, j % 8): half < step, so
// (half + j * step) / (8 * step) == j / 8. The reference's per-pixel divisions and neighbour
// checks are thereby the first sampled row and column, and a cell's samples are the runs
// [8 cx, 8 cx + 8) of each of its sampled rows (the last column's run goes to the row's end).
void FrameSummariser::summarise(const cv::Mat& bgr, const CellGrid& grid,
                                std::vector<FrameCell>& cells) {
  CV_Assert(bgr.type() == CV_8UC3);
  const int step = grid.step, cols = grid.cols, rows = grid.rows;
  const int half = step / 2;  // < bgr.cols and bgr.rows: step <= their minimum.
  const int nx = (bgr.cols - 1 - half) / step + 1, ny = (bgr.rows - 1 - half) / step + 1;
  const size_t n = static_cast<size_t>(nx);
  cells.assign(static_cast<size_t>(cols) * rows, FrameCell());
  for (std::vector<uint8_t>* plane : {&b_, &g_, &r_, &above_b_, &above_g_, &above_r_, &gray_}) {
    plane->resize(n);
  }
  texture_.resize(n);
  sum_b_.assign(cells.size(), 0);
  sum_g_.assign(cells.size(), 0);
  sum_r_.assign(cells.size(), 0);
  const size_t row_bytes = 3 * static_cast<size_t>(bgr.cols);
  for (int i = 0; i < ny; ++i) {
    // The frame is usually in no cache (just decoded, or larger than it), and the sampled rows
    // are `step` rows apart: the hardware prefetcher, which follows one row, starts cold at each
    // one, and the row's gather below waited for memory most of its time (~70 % of the summary
    // at 720p). Asking for the row after next while this one is summed hides that wait.
    if (i + 2 < ny) {
      const char* ahead = reinterpret_cast<const char*>(bgr.ptr<uint8_t>(half + (i + 2) * step));
      for (size_t offset = 0; offset < row_bytes; offset += 64) __builtin_prefetch(ahead + offset);
    }
    const uint8_t* row = bgr.ptr<uint8_t>(half + i * step) + 3 * half;
    uint8_t* b = b_.data();
    uint8_t* g = g_.data();
    uint8_t* r = r_.data();
    for (size_t j = 0; j < n; ++j) {
      const uint8_t* p = row + 3 * static_cast<size_t>(step) * j;
      b[j] = p[0];
      g[j] = p[1];
      r[j] = p[2];
    }
    // Per sample: the sum of |differences| to its left and upper neighbours over the pairs it
    // has, as the reference computes it (the division too: its rounding is part of the sum).
    float* texture = texture_.data();
    const uint8_t *ab = above_b_.data(), *ag = above_g_.data(), *ar = above_r_.data();
    if (i == 0) {
      texture[0] = 0.0f;  // No neighbour: adds nothing (x + 0.0f == x).
      for (size_t j = 1; j < n; ++j) {
        const int left = std::abs(b[j] - b[j - 1]) + std::abs(g[j] - g[j - 1]) +
                         std::abs(r[j] - r[j - 1]);
        texture[j] = static_cast<float>(left) / 3.0f;
      }
    } else {
      texture[0] = static_cast<float>(std::abs(b[0] - ab[0]) + std::abs(g[0] - ag[0]) +
                                      std::abs(r[0] - ar[0])) / 3.0f;
      for (size_t j = 1; j < n; ++j) {
        const int both = std::abs(b[j] - b[j - 1]) + std::abs(g[j] - g[j - 1]) +
                         std::abs(r[j] - r[j - 1]) + std::abs(b[j] - ab[j]) +
                         std::abs(g[j] - ag[j]) + std::abs(r[j] - ar[j]);
        texture[j] = static_cast<float>(both) / 6.0f;
      }
    }
    uint8_t* gray = gray_.data();
    for (size_t j = 0; j < n; ++j) gray[j] = static_cast<uint8_t>((b[j] + g[j] + r[j]) / 3);
    // Into the cells, each cell's samples in the reference's order (row by row, left to right).
    const int cy = std::min(i / kSamplesPerCell, rows - 1), sy = i - cy * kSamplesPerCell;
    for (int cx = 0; cx < cols; ++cx) {
      const size_t k = static_cast<size_t>(cy) * cols + cx;
      const int begin = cx * kSamplesPerCell;
      const int end = cx == cols - 1 ? nx : begin + kSamplesPerCell;
      int sb = 0, sg = 0, sr = 0;
      float t = cells[k].texture;
      for (int j = begin; j < end; ++j) {
        sb += b[j];
        sg += g[j];
        sr += r[j];
        t += texture[j];
      }
      cells[k].texture = t;
      sum_b_[k] += sb;
      sum_g_[k] += sg;
      sum_r_[k] += sr;
      if (sy < kSamplesPerCell) {
        std::copy(gray + begin, gray + std::min(end, begin + kSamplesPerCell),
                  cells[k].gray.begin() + sy * kSamplesPerCell);
      }
    }
    b_.swap(above_b_);
    g_.swap(above_g_);
    r_.swap(above_r_);
  }
  // Means over the cells' samples; integer sums of at most 16 x 16 x 255 are exact in a float,
  // as the reference's float sums of the same integers are.
  for (int cy = 0; cy < rows; ++cy) {
    const int height = (cy == rows - 1 ? ny : (cy + 1) * kSamplesPerCell) - cy * kSamplesPerCell;
    for (int cx = 0; cx < cols; ++cx) {
      const int width = (cx == cols - 1 ? nx : (cx + 1) * kSamplesPerCell) - cx * kSamplesPerCell;
      const size_t k = static_cast<size_t>(cy) * cols + cx;
      const float count = static_cast<float>(width * height);
      cells[k].b = static_cast<float>(sum_b_[k]) / count;
      cells[k].g = static_cast<float>(sum_g_[k]) / count;
      cells[k].r = static_cast<float>(sum_r_[k]) / count;
      cells[k].texture /= count;
    }
  }
}

}  // namespace softsight
