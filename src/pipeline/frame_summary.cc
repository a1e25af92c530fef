#include "pipeline/frame_summary.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>

// GatherSamples' byte shuffle: a function compiled for SSSE3 by its target attribute, taken when
// the processor has it (the build targets SSE2 only: no -march).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define SOFTSIGHT_SSSE3_GATHER 1
#include <immintrin.h>
#else
#define SOFTSIGHT_SSSE3_GATHER 0
#endif

namespace softsight {
namespace {

// About this many samples across the image's shorter side, whatever its resolution: a sample
// every 8 px at VGA, 12 px at 720p, 18 px at 1080p (cells of 32, 48 and 72 px).
constexpr int kSamplesAcross = 60;

// A cell's texture from the sum of its samples' textures in sixths of a level (a sample with
// both neighbours adds the sum of its six |differences| / 6, one with one neighbour the sum of
// three / 3 = twice that sum in sixths): one expression for both versions, so they agree to the
// last bit.
float MeanTexture(int sixths, int samples) {
  return static_cast<float>(static_cast<double>(sixths) / (6.0 * static_cast<double>(samples)));
}

// |a - b| of two levels, in a form the compiler vectorises in 8-bit lanes (max - min).
inline int AbsDifference(uint8_t a, uint8_t b) {
  return static_cast<uint8_t>(std::max(a, b) - std::min(a, b));
}

// The sum over the channels of |p - q|.
int ChannelDifferences(const cv::Vec3b& p, const cv::Vec3b& q) {
  return std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]);
}

// The planes' length, a whole number of vectors (the samples past the row's are never read
// into a cell): the loops below then run in whole vectors, with no scalar remainder.
constexpr size_t kLanes = 16;

// One sampled row (planes b, g, r of `padded` samples, each with the sample to its left at
// index -1, the first's a copy of it; the row above in above_*, unless `first_row`) added to
// the columns' sums: each sample's texture in sixths (see MeanTexture; the first row has no
// upper neighbours and the first column no left ones: one pair, counted twice) and its
// channels; and the row's gray levels. 8- and 16-bit lanes in loops of whole vectors, which the
// compiler vectorises with SSE2, on planes that do not overlap (__restrict: else it checks
// before each loop, or gives up on it). The summary of a VGA frame took 307k instructions in int
// lanes (SSE2 has no abs nor 32-bit multiply), 194k in narrow lanes with a scalar remainder
// after each loop and the columns' sums added one by one, 141k now.
void AddRowToColumns(const uint8_t* __restrict b, const uint8_t* __restrict g,
                     const uint8_t* __restrict r, const uint8_t* __restrict above_b,
                     const uint8_t* __restrict above_g, const uint8_t* __restrict above_r,
                     bool first_row, size_t padded, uint16_t* __restrict texture_sixths,
                     uint16_t* __restrict sum_b, uint16_t* __restrict sum_g,
                     uint16_t* __restrict sum_r, uint8_t* __restrict gray) {
  // Each sample's left neighbour: the planes shifted by one (index -1 is the padding sample).
  // Indexing b[j - 1] with an unsigned j = 0 would wrap the offset (undefined; UBSan says so).
  const uint8_t* __restrict left_b = b - 1;
  const uint8_t* __restrict left_g = g - 1;
  const uint8_t* __restrict left_r = r - 1;
  if (first_row) {
    for (size_t j0 = 0; j0 < padded; j0 += kLanes) {
      for (size_t j = j0; j < j0 + kLanes; ++j) {
        const int left = AbsDifference(b[j], left_b[j]) + AbsDifference(g[j], left_g[j]) +
                         AbsDifference(r[j], left_r[j]);
        texture_sixths[j] = static_cast<uint16_t>(texture_sixths[j] + 2 * left);
      }
    }
  } else {
    for (size_t j0 = 0; j0 < padded; j0 += kLanes) {
      for (size_t j = j0; j < j0 + kLanes; ++j) {
        const int both = AbsDifference(b[j], left_b[j]) + AbsDifference(g[j], left_g[j]) +
                         AbsDifference(r[j], left_r[j]) + AbsDifference(b[j], above_b[j]) +
                         AbsDifference(g[j], above_g[j]) + AbsDifference(r[j], above_r[j]);
        texture_sixths[j] = static_cast<uint16_t>(texture_sixths[j] + both);
      }
    }
    // The first column's left difference was 0 (its left is itself): its upper one counts twice.
    texture_sixths[0] = static_cast<uint16_t>(
        texture_sixths[0] + AbsDifference(b[0], above_b[0]) + AbsDifference(g[0], above_g[0]) +
        AbsDifference(r[0], above_r[0]));
  }
  for (size_t j0 = 0; j0 < padded; j0 += kLanes) {
    for (size_t j = j0; j < j0 + kLanes; ++j) {
      sum_b[j] = static_cast<uint16_t>(sum_b[j] + b[j]);
      sum_g[j] = static_cast<uint16_t>(sum_g[j] + g[j]);
      sum_r[j] = static_cast<uint16_t>(sum_r[j] + r[j]);
      const uint16_t level_sum = static_cast<uint16_t>(b[j] + g[j] + r[j]);
      gray[j] = static_cast<uint8_t>(level_sum / 3);
    }
  }
}

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
  std::vector<int> counts(cells.size(), 0), sum_b(cells.size(), 0), sum_g(cells.size(), 0),
      sum_r(cells.size(), 0), texture_sixths(cells.size(), 0);
  const int half = step / 2;
  for (int y = half; y < bgr.rows; y += step) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    const cv::Vec3b* above = y - step >= 0 ? bgr.ptr<cv::Vec3b>(y - step) : nullptr;
    const int cy = std::min(y / cell_px, rows - 1);
    for (int x = half; x < bgr.cols; x += step) {
      const int cx = std::min(x / cell_px, cols - 1);
      const size_t k = static_cast<size_t>(cy) * cols + cx;
      const cv::Vec3b p = row[x];
      sum_b[k] += p[0];
      sum_g[k] += p[1];
      sum_r[k] += p[2];
      int differences = 0, pairs = 0;
      if (x - step >= 0) {
        differences += ChannelDifferences(p, row[x - step]);
        ++pairs;
      }
      if (above != nullptr) {
        differences += ChannelDifferences(p, above[x]);
        ++pairs;
      }
      // differences / (3 pairs) levels, in sixths.
      if (pairs > 0) texture_sixths[k] += differences * 2 / pairs;
      ++counts[k];
      // The sample's place in the cell's grid (a border cell's extra samples are left out).
      const int sx = (x - cx * cell_px) / step, sy = (y - cy * cell_px) / step;
      if (sx < kSamplesPerCell && sy < kSamplesPerCell) {
        cells[k].gray[static_cast<size_t>(sy * kSamplesPerCell + sx)] =
            static_cast<uint8_t>((p[0] + p[1] + p[2]) / 3);
      }
    }
  }
  for (size_t k = 0; k < cells.size(); ++k) {
    if (counts[k] == 0) continue;
    const float n = static_cast<float>(counts[k]);
    cells[k].b = static_cast<float>(sum_b[k]) / n;
    cells[k].g = static_cast<float>(sum_g[k]) / n;
    cells[k].r = static_cast<float>(sum_r[k]) / n;
    cells[k].texture = MeanTexture(texture_sixths[k], counts[k]);
  }
}

namespace {

#if SOFTSIGHT_SSSE3_GATHER
// 16 samples `stride` bytes apart from `p` into b, g and r: each sample's four bytes in one 32-bit
// read (its B, G, R and the next pixel's first byte, unused), a vector's four samples sorted into
// runs of B, G and R by one byte shuffle, and the four vectors' runs put together (issue 45: the
// byte-at-a-time gather was a fifth of the summary's instructions).
__attribute__((target("ssse3"))) void GatherSamples16(const uint8_t* p, size_t stride, uint8_t* b,
                                                      uint8_t* g, uint8_t* r) {
  const __m128i sort = _mm_setr_epi8(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15);
  __m128i v[4];
  for (size_t k = 0; k < 4; ++k) {
    int32_t w[4];
    for (size_t i = 0; i < 4; ++i) std::memcpy(&w[i], p + (4 * k + i) * stride, 4);
    v[k] = _mm_shuffle_epi8(_mm_setr_epi32(w[0], w[1], w[2], w[3]), sort);  // B4 G4 R4 -
  }
  const __m128i bg_low = _mm_unpacklo_epi32(v[0], v[1]);   // B0-3 B4-7 G0-3 G4-7
  const __m128i bg_high = _mm_unpacklo_epi32(v[2], v[3]);  // B8-11 B12-15 G8-11 G12-15
  const __m128i r_low = _mm_unpackhi_epi32(v[0], v[1]);    // R0-3 R4-7 - -
  const __m128i r_high = _mm_unpackhi_epi32(v[2], v[3]);   // R8-11 R12-15 - -
  _mm_storeu_si128(reinterpret_cast<__m128i*>(b), _mm_unpacklo_epi64(bg_low, bg_high));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(g), _mm_unpackhi_epi64(bg_low, bg_high));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(r), _mm_unpacklo_epi64(r_low, r_high));
}

bool HasSsse3() {
  static const bool has = __builtin_cpu_supports("ssse3");
  return has;
}
#endif

// One sampled row of the frame (`n` samples `stride` bytes apart from `row`) into the planes b, g
// and r, and each plane's padding sample (index -1) a copy of its first.
void GatherSamples(const uint8_t* row, size_t stride, size_t n, uint8_t* b, uint8_t* g,
                   uint8_t* r) {
  size_t j = 0;
#if SOFTSIGHT_SSSE3_GATHER
  // Sixteen at a time while the block's last sample is not the row's last: a sample's 32-bit read
  // takes the byte after it, which the row's last pixel may not have.
  if (HasSsse3()) {
    for (; j + 16 < n; j += 16) GatherSamples16(row + j * stride, stride, b + j, g + j, r + j);
  }
#endif
  const uint8_t* p = row + j * stride;
  for (; j + 4 <= n; j += 4, p += 4 * stride) {  // Four at a time: a quarter of the loop's own work.
    for (size_t k = 0; k < 4; ++k) {
      b[j + k] = p[k * stride];
      g[j + k] = p[k * stride + 1];
      r[j + k] = p[k * stride + 2];
    }
  }
  for (; j < n; ++j, p += stride) {
    b[j] = p[0];
    g[j] = p[1];
    r[j] = p[2];
  }
  b[-1] = b[0];
  g[-1] = g[0];
  r[-1] = r[0];
}

// The gray levels of a sampled row (`nx` samples) into the cells of row `cy` of the grid
// (`cols` cells a row), as their gray samples' row `sy`.
void CopyGraySamples(const uint8_t* gray, int nx, int cy, int sy, int cols,
                     std::vector<FrameCell>& cells) {
  constexpr int K = kSamplesPerCell;
  for (int cx = 0; cx < cols; ++cx) {
    const int begin = cx * K;
    uint8_t* to = cells[static_cast<size_t>(cy) * cols + cx].gray.data() + sy * K;
    if (begin + K <= nx) {
      std::memcpy(to, gray + begin, K);  // A constant size: one move, no call.
    } else {
      std::copy(gray + begin, gray + nx, to);  // A frame narrower than a cell.
    }
  }
}

// Per column of samples, the sums over a row of cells' sampled rows.
struct ColumnSums {
  const uint16_t* b;
  const uint16_t* g;
  const uint16_t* r;
  const uint16_t* texture_sixths;
};

// The cells of row `cy` (`cols` cells; `nx` samples a row, `height` sampled rows) from their
// columns' sums: their mean colour and texture.
void CellsFromColumns(const ColumnSums& sums, int nx, int cy, int height, int cols,
                      std::vector<FrameCell>& cells) {
  constexpr int K = kSamplesPerCell;
  for (int cx = 0; cx < cols; ++cx) {
    const int begin = cx * K, end = cx == cols - 1 ? nx : begin + K;
    int cell_b = 0, cell_g = 0, cell_r = 0, cell_texture = 0;
    const auto add_column = [&](int j) {
      cell_b += sums.b[j];
      cell_g += sums.g[j];
      cell_r += sums.r[j];
      cell_texture += sums.texture_sixths[j];
    };
    if (end - begin == K) {
      for (int k = 0; k < K; ++k) add_column(begin + k);  // A constant count: unrolled.
    } else {
      for (int j = begin; j < end; ++j) add_column(j);
    }
    FrameCell& cell = cells[static_cast<size_t>(cy) * cols + cx];
    const int samples = (end - begin) * height;
    const float count = static_cast<float>(samples);
    cell.b = static_cast<float>(cell_b) / count;
    cell.g = static_cast<float>(cell_g) / count;
    cell.r = static_cast<float>(cell_r) / count;
    cell.texture = MeanTexture(cell_texture, samples);
  }
}

}  // namespace

// Sample (i, j) of the grid is pixel (half + i * step, half + j * step), and it belongs to cell
// (min(i / K, rows - 1), min(j / K, cols - 1)) at place (i % K, j % K), K = kSamplesPerCell:
// half < step, so (half + j * step) / (K * step) == j / K. The reference's per-pixel divisions and
// neighbour checks are thereby the first sampled row and column, and a cell's samples are the
// columns [K cx, K cx + K) of its sampled rows (the last column of cells takes the row's rest,
// the last row of cells the rest of the rows).
void FrameSummariser::summarise(const cv::Mat& bgr, const CellGrid& grid,
                                std::vector<FrameCell>& cells) {
  CV_Assert(bgr.type() == CV_8UC3);
  constexpr int K = kSamplesPerCell;
  const int step = grid.step, cols = grid.cols, rows = grid.rows;
  const int half = step / 2;  // < bgr.cols and bgr.rows: step <= their minimum.
  const int nx = (bgr.cols - 1 - half) / step + 1, ny = (bgr.rows - 1 - half) / step + 1;
  const size_t n = static_cast<size_t>(nx);
  if (nx < K * cols || ny < K * rows) {
    // A frame smaller than a cell: its one cell's gray samples are not all written below.
    cells.assign(static_cast<size_t>(cols) * rows, FrameCell());
  } else {
    cells.resize(static_cast<size_t>(cols) * rows);  // Every field is written below.
  }
  const size_t padded = (n + kLanes - 1) / kLanes * kLanes;
  // Each plane with room for the sample left of the first (index -1).
  for (std::vector<uint8_t>* plane : {&b_, &g_, &r_, &above_b_, &above_g_, &above_r_}) {
    plane->resize(padded + 1);
  }
  gray_.resize(padded);
  for (std::vector<uint16_t>* column :
       {&column_b_, &column_g_, &column_r_, &column_texture_sixths_}) {
    column->assign(padded, 0);
  }
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
    uint8_t* b = b_.data() + 1;
    uint8_t* g = g_.data() + 1;
    uint8_t* r = r_.data() + 1;
    GatherSamples(row, 3 * static_cast<size_t>(step), n, b, g, r);
    AddRowToColumns(b, g, r, above_b_.data() + 1, above_g_.data() + 1, above_r_.data() + 1, i == 0,
                    padded, column_texture_sixths_.data(), column_b_.data(), column_g_.data(),
                    column_r_.data(), gray_.data());
    const int cy = std::min(i / K, rows - 1), sy = i - cy * K;
    if (sy < K) CopyGraySamples(gray_.data(), nx, cy, sy, cols, cells);
    // A row of cells is complete: its cells from the columns' sums, and the columns start again.
    const bool last_of_its_cells = cy < rows - 1 ? (i + 1) % K == 0 : i == ny - 1;
    if (last_of_its_cells) {
      CellsFromColumns({column_b_.data(), column_g_.data(), column_r_.data(),
                        column_texture_sixths_.data()},
                       nx, cy, i + 1 - cy * K, cols, cells);
      for (std::vector<uint16_t>* column :
           {&column_b_, &column_g_, &column_r_, &column_texture_sixths_}) {
        std::fill(column->begin(), column->end(), 0);
      }
    }
    b_.swap(above_b_);
    g_.swap(above_g_);
    r_.swap(above_r_);
  }
}

}  // namespace softsight
