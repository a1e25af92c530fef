#include "track/match_kernels.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstdlib>
#include <limits>
#include <type_traits>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

// The AVX2 cross-correlation: functions compiled for AVX2 by their target attribute, called only
// where the processor reports it (GCC and Clang on x86-64; elsewhere the 128-bit kernel only).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && CV_SIMD128
#define SOFTSIGHT_AVX2_CROSS 1
#include <immintrin.h>
#else
#define SOFTSIGHT_AVX2_CROSS 0
#endif

namespace softsight {

namespace {

// The longest template row the 16-bit SAD accumulators take between two flushes (128 chunks of
// 16 bytes, each adding two values <= 255 to a lane: 256 * 255 < 65536).
constexpr int kMaxRowBytes = 2048;

void CheckInputs(const cv::Mat& image, const cv::Mat& templ, const cv::Mat& mask) {
  CV_Assert(image.depth() == CV_8U && templ.depth() == CV_8U);
  CV_Assert(image.channels() == templ.channels());
  CV_Assert(templ.channels() == 1 || templ.channels() == 3);
  CV_Assert(!templ.empty() && image.cols >= templ.cols && image.rows >= templ.rows);
  CV_Assert(templ.total() * templ.channels() <= static_cast<size_t>(kMaxTemplateValues));
  CV_Assert(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == templ.size()));
}

cv::Size ResultSize(const cv::Mat& image, const cv::Size& templ) {
  return {image.cols - templ.width + 1, image.rows - templ.height + 1};
}

bool Counts(const cv::Mat& mask, int r, int c) { return mask.empty() || mask.at<uint8_t>(r, c); }

// Plain scalar loops, shared by the references and by the fast kernels' scalar fallback (rows
// shorter than 8 bytes, or a build without 128-bit SIMD).
template <typename Op>
void ScalarMap(const cv::Mat& image, const cv::Mat& templ, const cv::Mat& mask, cv::Mat& result,
               Op op) {
  CheckInputs(image, templ, mask);
  result.create(ResultSize(image, templ.size()), CV_32S);
  const int cn = templ.channels();
  for (int y = 0; y < result.rows; ++y) {
    int* out = result.ptr<int>(y);
    for (int x = 0; x < result.cols; ++x) {
      int total = 0;
      for (int r = 0; r < templ.rows; ++r) {
        const uint8_t* a = image.ptr<uint8_t>(y + r) + x * cn;
        const uint8_t* b = templ.ptr<uint8_t>(r);
        for (int i = 0; i < templ.cols * cn; ++i) {
          if (Counts(mask, r, i / cn)) total += op(int{a[i]}, int{b[i]});
        }
      }
      out[x] = total;
    }
  }
}

int AbsDiff(int a, int b) { return std::abs(a - b); }
int SqDiff(int a, int b) { return (a - b) * (a - b); }
int Product(int a, int b) { return a * b; }

// ZNCC from exact integer sums over the N counted pixels of one placement: cross = sum I*T,
// sum[c] = sum I_c, sum_sq = sum I^2 over all channels. NaN when the window is flat.
float ZnccFromSums(int64_t n, int64_t cross, const int64_t* sum, int64_t sum_sq, int cn,
                   const PreparedTemplate& t) {
  int64_t num = n * cross;
  int64_t variance = n * sum_sq;
  for (int c = 0; c < cn; ++c) {
    num -= sum[c] * t.sum()[c];
    variance -= sum[c] * sum[c];
  }
  if (variance <= 0) return std::numeric_limits<float>::quiet_NaN();
  const double z = static_cast<double>(num) / std::sqrt(static_cast<double>(variance) *
                                                        static_cast<double>(t.scaled_variance()));
  return static_cast<float>(std::clamp(z, -1.0, 1.0));
}

}  // namespace

// Gives the kernels access to the layout without making it public API.
struct KernelAccess {
  static bool Vectorised(const PreparedTemplate& t) { return t.chunks_per_row_ > 0; }
  // What the vector kernels walk: per template row, `full` 16-byte chunks, then (when `tail`)
  // one chunk of two 8-byte halves at byte offsets `lo` and `hi` of the row.
  struct Chunks {
    int rows, full;
    bool tail;
    int lo, hi;
  };
  static Chunks Layout(const PreparedTemplate& t) {
    return {t.image_.rows, t.full_chunks_, t.has_tail_, t.tail_lo_, t.tail_hi_};
  }
  static const uint8_t* Bytes(const PreparedTemplate& t) { return t.bytes_.data(); }
  static const uint8_t* Mask(const PreparedTemplate& t) { return t.mask_.data(); }
  static const int16_t* Words(const PreparedTemplate& t) { return t.words_.data(); }
  static const std::vector<int>& RunRows(const PreparedTemplate& t) { return t.run_rows_; }
  static const PreparedTemplate::Run* Runs(const PreparedTemplate& t) { return t.runs_.data(); }
};

namespace {

// sum I * T for every placement (CV_32S, exact): the cross-correlation ZNCC and SSD are built on.
// The image widened to 16 bits is kept in the scratch, or read from its shared image's (defined
// below).
void CrossCorrelation(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result,
                      ZnccScratch& scratch);

// Window sums over the template's counted pixels, one map row at a time: calls
// `row_done(y, sums)` for each row y of the map, sums[x * (kChannels + 1) + c] = sum of channel c
// and sums[x * (kChannels + 1) + kChannels] = sum of I^2 over the channels, at placement (x, y).
// They come from per-row prefix sums P of the image: for a run [b, e) of a template row, the sum
// over it at placement x is P[x + e] - P[x + b]. A pixel's prefix sums are kept together, so one
// loop over a map row adds a run's sums for every placement of the row (it vectorises). The
// arithmetic is unsigned 32-bit: the prefix sums of a wide image may wrap around, their
// differences do not (a window's sums fit, see kMaxTemplateValues), so the sums are exact, as
// summed pixel by pixel.
// One image row's prefix sums for WindowSums: s[(x + 1) * (kChannels + 1) + c] = the sum of
// channel c over pixels 0..x, and [.. + kChannels] the sum of their squares over the channels;
// the first pixel's slots (x = -1) are 0. Unsigned 32-bit, wrapping (see WindowSums).
template <int kChannels>
void PrefixRowReference(const uint8_t* __restrict p, int cols, uint32_t* __restrict s) {
  constexpr int kPerPixel = kChannels + 1;
  uint32_t acc[kPerPixel] = {};
  for (int k = 0; k < kPerPixel; ++k) s[k] = 0;
  for (int x = 0; x < cols; ++x) {
    s += kPerPixel;
    for (int c = 0; c < kChannels; ++c) {
      const uint32_t v = p[x * kChannels + c];
      acc[c] += v;
      acc[kChannels] += v * v;
      s[c] = acc[c];
    }
    s[kChannels] = acc[kChannels];
  }
}

template <int kChannels>
void PrefixRow(const uint8_t* __restrict p, int cols, uint32_t* __restrict s) {
  PrefixRowReference<kChannels>(p, cols, s);
}

#if CV_SIMD128
// Gray: 8 pixels at a time, ~3.6 instructions a pixel instead of 10 (the window sums' prefix
// rows were a tenth of the ZNCC template trackers' instructions). Each pixel's (v, v^2) pair is
// two 32-bit lanes, so a vector holds two pixels' pairs: adding it shifted up by one pair and the
// running total (the last pair so far, in both halves) gives the prefix. v^2 <= 65025 fits 16
// bits. The same wrapping 32-bit sums as the reference, so the same bits.
template <>
void PrefixRow<1>(const uint8_t* __restrict p, int cols, uint32_t* __restrict s) {
  s[0] = 0;
  s[1] = 0;
  int x = 0;
  cv::v_uint32x4 carry = cv::v_setzero_u32();
  for (; x + 8 <= cols; x += 8) {
    const cv::v_uint16x8 v = cv::v_load_expand(p + x);
    const cv::v_uint16x8 sq = cv::v_mul_wrap(v, v);
    cv::v_uint16x8 pairs[2];  // v0, v0^2, v1, v1^2, ...
    cv::v_zip(v, sq, pairs[0], pairs[1]);
    cv::v_uint32x4 w[4];
    cv::v_expand(pairs[0], w[0], w[1]);
    cv::v_expand(pairs[1], w[2], w[3]);
    for (int k = 0; k < 4; ++k) {
      const cv::v_uint32x4 prefix = w[k] + cv::v_rotate_left<2>(w[k]) + carry;
      cv::v_store(s + 2 * (x + 1) + 4 * k, prefix);
      carry = cv::v_combine_high(prefix, prefix);
    }
  }
  // The last pixels a pixel at a time, from the prefix so far (pixel x - 1's, at 2 * x).
  uint32_t sum = s[2 * x], sum_sq = s[2 * x + 1];
  for (; x < cols; ++x) {
    const uint32_t v = p[x];
    sum += v;
    sum_sq += v * v;
    s[2 * (x + 1)] = sum;
    s[2 * (x + 1) + 1] = sum_sq;
  }
}
#endif

// Whether `image` (gray) is a window of the image whose prefix sums `scratch` shares
// (ShareWindowSums), and where in it (`at`). A window of it has its pixels at the same step
// from its first pixel; a buffer of its own cannot lie inside the shared image's (both live).
bool InSharedImage(const cv::Mat& image, const ZnccScratch& scratch, cv::Point* at) {
  if (scratch.shared_image == nullptr || image.type() != CV_8UC1 ||
      image.step[0] != scratch.shared_step || image.data < scratch.shared_image) {
    return false;
  }
  const size_t offset = static_cast<size_t>(image.data - scratch.shared_image);
  const size_t y = offset / scratch.shared_step, x = offset % scratch.shared_step;
  if (x + static_cast<size_t>(image.cols) > static_cast<size_t>(scratch.shared_size.width) ||
      y + static_cast<size_t>(image.rows) > static_cast<size_t>(scratch.shared_size.height)) {
    return false;
  }
  *at = cv::Point(static_cast<int>(x), static_cast<int>(y));
  return true;
}

template <int kChannels, typename RowDone>
void WindowSums(const cv::Mat& image, const PreparedTemplate& t, ZnccScratch& scratch,
                RowDone row_done) {
  constexpr int kPerPixel = kChannels + 1;
  const cv::Size size = ResultSize(image, t.size());
  const int image_cols = image.cols;
  size_t prefix_step = static_cast<size_t>(image_cols + 1) * kPerPixel;
  const uint32_t* prefix = nullptr;  // The image's first pixel's slots (x = -1) in row 0.
  cv::Point in_shared;
  if (kChannels == 1 && InSharedImage(image, scratch, &in_shared)) {
    // The rows' prefix sums from the image this window lies in: a window's sums are differences
    // of one row's prefix sums, the same (mod 2^32, and exact) from whichever pixel they start.
    prefix_step = static_cast<size_t>(scratch.shared_size.width + 1) * kPerPixel;
    prefix = scratch.shared_prefix.data() + prefix_step * in_shared.y + in_shared.x * kPerPixel;
  } else {
    scratch.prefix_sum.resize(prefix_step * image.rows);
    for (int y = 0; y < image.rows; ++y) {
      PrefixRow<kChannels>(image.ptr<uint8_t>(y), image_cols,
                           scratch.prefix_sum.data() + prefix_step * y);
    }
    prefix = scratch.prefix_sum.data();
  }
  const int map_values = size.width * kPerPixel;
  scratch.row_sum.resize(map_values);
  uint32_t* __restrict row_sum = scratch.row_sum.data();
  const std::vector<int>& run_rows = KernelAccess::RunRows(t);
  const auto* runs = KernelAccess::Runs(t);
  const int rows = t.size().height;
  // kValues: the map row's values when known at compile time (0: map_values). The tracker's
  // searches are 3 placements wide (the climbs, the pose rungs: 6 gray values) or 7 (the
  // measurement's window): with the count a constant the loops below are a few vector operations
  // each; with a variable one the compiler's vector loop and its remainder cost more than the
  // additions (issue 45: these loops were 0.13M of the 2.37M instructions a frame of ZNCC on
  // mire-2). The same additions, in the same order.
  const auto sums = [&](auto values) {
    constexpr int kValues = decltype(values)::value;
    const int row_values = kValues > 0 ? kValues : map_values;
    for (int y = 0; y < size.height; ++y) {
      std::fill(row_sum, row_sum + row_values, 0u);
      for (int r = 0; r < rows;) {
        const uint32_t* s = prefix + prefix_step * (y + r);
        const int k = run_rows[r];
        if (r + 1 < rows && run_rows[r + 1] == k + 1 && run_rows[r + 2] == k + 2) {
          // Two rows of one run each (a round mask's rows): added together, so the map row's
          // sums are loaded and stored once for both; the same sums mod 2^32.
          const uint32_t* __restrict end0 = s + runs[k].end * kPerPixel;
          const uint32_t* __restrict begin0 = s + runs[k].begin * kPerPixel;
          const uint32_t* __restrict end1 = s + prefix_step + runs[k + 1].end * kPerPixel;
          const uint32_t* __restrict begin1 = s + prefix_step + runs[k + 1].begin * kPerPixel;
          for (int i = 0; i < row_values; ++i) {
            row_sum[i] += (end0[i] - begin0[i]) + (end1[i] - begin1[i]);
          }
          r += 2;
          continue;
        }
        for (int j = k; j < run_rows[r + 1]; ++j) {
          const uint32_t* __restrict end = s + runs[j].end * kPerPixel;
          const uint32_t* __restrict begin = s + runs[j].begin * kPerPixel;
          for (int i = 0; i < row_values; ++i) row_sum[i] += end[i] - begin[i];
        }
        ++r;
      }
      row_done(y, static_cast<const uint32_t*>(row_sum));
    }
  };
  if (map_values == 3 * kPerPixel) {
    sums(std::integral_constant<int, 3 * kPerPixel>{});
  } else if (map_values == 7 * kPerPixel) {
    sums(std::integral_constant<int, 7 * kPerPixel>{});
  } else {
    sums(std::integral_constant<int, 0>{});
  }
}

// The cross-correlation map in the scratch's buffer (create() keeps it there).
cv::Mat CrossMap(const cv::Mat& image, const PreparedTemplate& t, ZnccScratch& scratch) {
  const cv::Size size = ResultSize(image, t.size());
  scratch.cross_values.resize(size.area());
  cv::Mat cross(size, CV_32S, scratch.cross_values.data());
  CrossCorrelation(image, t, cross, scratch);
  return cross;
}

// Masked ZNCC from the cross-correlation map and the window sums over the mask (1.4x faster on
// the tracker's 48x48 window than summing I and I^2 over the mask at every placement beside
// sum I*T; the window search is the template tracker's largest cost).
template <int kChannels>
void MaskedZncc(const cv::Mat& image, const PreparedTemplate& t, cv::Mat& result,
                ZnccScratch& scratch) {
  const cv::Mat cross = CrossMap(image, t, scratch);
  result.create(cross.size(), CV_32F);
  const int64_t n = t.count();
  WindowSums<kChannels>(image, t, scratch, [&](int y, const uint32_t* row_sums) {
    const int* cross_row = cross.ptr<int>(y);
    float* out = result.ptr<float>(y);
    for (int x = 0; x < result.cols; ++x) {
      const uint32_t* here = row_sums + x * (kChannels + 1);
      int64_t sums[3] = {0, 0, 0};
      for (int c = 0; c < kChannels; ++c) sums[c] = here[c];
      out[x] = ZnccFromSums(n, cross_row[x], sums, here[kChannels], kChannels, t);
    }
  });
}

// SSD = sum I^2 - 2 sum I*T + sum T^2 over the counted pixels, exactly (64-bit; the result fits
// 32 bits, see kMaxTemplateValues): from the same cross-correlation and window sums as ZNCC,
// 1.5-1.9x faster than subtracting, squaring and summing at every placement.
template <int kChannels>
void SsdFromSums(const cv::Mat& image, const PreparedTemplate& t, cv::Mat& result,
                 ZnccScratch& scratch) {
  const cv::Mat cross = CrossMap(image, t, scratch);
  result.create(cross.size(), CV_32S);
  int64_t templ_sq = 0;
  for (int c = 0; c < kChannels; ++c) templ_sq += t.sum_sq()[c];
  WindowSums<kChannels>(image, t, scratch, [&](int y, const uint32_t* row_sums) {
    const int* cross_row = cross.ptr<int>(y);
    int* out = result.ptr<int>(y);
    for (int x = 0; x < result.cols; ++x) {
      const int64_t image_sq = row_sums[x * (kChannels + 1) + kChannels];
      out[x] = static_cast<int>(image_sq - 2 * int64_t{cross_row[x]} + templ_sq);
    }
  });
}

// How many pixels of a template count (all, or the mask's nonzero ones), and the per-channel sums
// of T and T^2 over them.
struct CountedSums {
  int64_t n = 0;
  int64_t sum[3] = {0, 0, 0};
  int64_t sum_sq[3] = {0, 0, 0};
};

// Whether two CV_8UC1 masks of one size hold the same bytes.
bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size()) return false;
  for (int y = 0; y < a.rows; ++y) {
    if (std::memcmp(a.ptr<uint8_t>(y), b.ptr<uint8_t>(y), static_cast<size_t>(a.cols)) != 0) {
      return false;
    }
  }
  return true;
}

CountedSums SumCountedPixels(const cv::Mat& templ, const cv::Mat& mask) {
  const int cn = templ.channels();
  CountedSums s;
  for (int r = 0; r < templ.rows; ++r) {
    const uint8_t* p = templ.ptr<uint8_t>(r);
    const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(r);
    if (cn == 1) {
      // Gray (the working template, re-prepared every frame): a row's sums fit 32 bits (at most
      // kMaxRowBytes levels), summed branch-free so the compiler vectorises the loop; the same
      // integers as pixel by pixel.
      uint32_t row_n = 0, row_sum = 0, row_sq = 0;
      for (int j = 0; j < templ.cols; ++j) {
        const uint32_t keep = m ? (m[j] != 0) : 1u;
        const uint32_t v = p[j] * keep;
        row_n += keep;
        row_sum += v;
        row_sq += v * v;
      }
      s.n += row_n;
      s.sum[0] += row_sum;
      s.sum_sq[0] += row_sq;
      continue;
    }
    for (int j = 0; j < templ.cols; ++j) {
      if (m && !m[j]) continue;
      ++s.n;
      for (int c = 0; c < cn; ++c) {
        const int64_t v = p[j * cn + c];
        s.sum[c] += v;
        s.sum_sq[c] += v * v;
      }
    }
  }
  return s;
}

}  // namespace

bool PreparedTemplate::Prepare(const cv::Mat& templ, const cv::Mat& mask) {
  CV_Assert(templ.depth() == CV_8U && (templ.channels() == 1 || templ.channels() == 3));
  CV_Assert(!templ.empty());
  CV_Assert(templ.total() * templ.channels() <= static_cast<size_t>(kMaxTemplateValues));
  CV_Assert(templ.cols * templ.channels() <= kMaxRowBytes);
  CV_Assert(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == templ.size()));
  // Buffers keep their capacity, so re-preparing a same-size template (the template update,
  // every frame) allocates nothing. Rows are read through pointers: this runs once per frame
  // per marker, and Mat::at per pixel was a tenth of the tracker's time.
  bytes_.clear();
  mask_.clear();
  words_.clear();

  const int cn = templ.channels();
  const CountedSums sums = SumCountedPixels(templ, mask);
  const int64_t n = sums.n;
  int64_t variance = 0;
  for (int c = 0; c < cn; ++c) variance += n * sums.sum_sq[c] - sums.sum[c] * sums.sum[c];
  if (n == 0 || variance <= 0) {
    image_.release();
    mask_image_.release();
    run_rows_.clear();
    runs_.clear();
    return false;
  }

  // The runs depend on the mask alone: a template re-prepared with the same mask at the same size
  // (the template update, every frame) keeps them (finding them was a tenth of the update).
  const bool masked = !mask.empty() && n < static_cast<int64_t>(mask.total());
  const bool same_runs = !run_rows_.empty() && image_.size() == templ.size() &&
                         image_.channels() == cn && masked == !mask_image_.empty() &&
                         (!masked || SameBytes(mask, mask_image_));
  templ.copyTo(image_);  // Continuous.
  if (masked) {
    if (!same_runs) mask.copyTo(mask_image_);
  } else {
    mask_image_.release();
  }
  count_ = static_cast<int>(n);
  for (int c = 0; c < 3; ++c) {
    sum_[c] = sums.sum[c];
    sum_sq_[c] = sums.sum_sq[c];
  }
  scaled_variance_ = variance;
  if (!same_runs) {
    run_rows_.clear();
    runs_.clear();
    find_runs();
    lay_out_chunks();
  } else {
    lay_out_bytes();
  }
  return true;
}

// The same size, channels and mask as the last layout (the template update, every frame): the
// lanes' bytes (lane_bytes_) and mask (mask_) are as they were; only the values change, so each
// lane's value is its byte masked by its lane's mask, what lay_out_chunks writes (it cleared and
// rewrote all three every frame: half of the template update's preparation, issue 45).
void PreparedTemplate::lay_out_bytes() {
  if (chunks_per_row_ == 0) return;  // Scalar kernels: no layout.
  const int cn = image_.channels();
  const int per_row = chunks_per_row_ * 16;
  const int covered = full_chunks_ * 16;
  for (int r = 0; r < image_.rows; ++r) {
    const uint8_t* p = image_.ptr<uint8_t>(r);
    const size_t row = static_cast<size_t>(r) * per_row;
    uint8_t* __restrict bytes = bytes_.data() + row;
    const uint8_t* __restrict lanes = mask_.data() + row;
    int16_t* __restrict words = words_.data() + row;
    int i = 0;
    if (cn == 1) {
      for (; i < covered; ++i) {  // Lane i reads byte i: vectorised.
        const uint8_t v = static_cast<uint8_t>(p[i] & lanes[i]);
        bytes[i] = v;
        words[i] = v;
      }
    }
    for (; i < per_row; ++i) {
      const int b = lane_bytes_[i];
      const uint8_t v = b < 0 ? uint8_t{0} : static_cast<uint8_t>(p[b] & lanes[i]);
      bytes[i] = v;
      words[i] = v;
    }
  }
}

void PreparedTemplate::find_runs() {
  const bool masked = !mask_image_.empty();
  run_rows_.reserve(image_.rows + 1);
  for (int r = 0; r < image_.rows; ++r) {
    run_rows_.push_back(static_cast<int>(runs_.size()));
    if (!masked) {
      runs_.push_back({0, image_.cols});
      continue;
    }
    const uint8_t* m = mask_image_.ptr<uint8_t>(r);
    for (int j = 0; j < image_.cols;) {
      if (!m[j]) {
        ++j;
        continue;
      }
      const int begin = j;
      while (j < image_.cols && m[j]) ++j;
      runs_.push_back({begin, j});
    }
  }
  run_rows_.push_back(static_cast<int>(runs_.size()));
}

void PreparedTemplate::lay_out_chunks() {
  const int cn = image_.channels();
  const bool masked = !mask_image_.empty();
  row_bytes_ = image_.cols * cn;
  full_chunks_ = 0;
  has_tail_ = false;
  chunks_per_row_ = 0;
  if (row_bytes_ < 8) return;  // Too narrow for 8-byte loads: scalar kernels.
  full_chunks_ = row_bytes_ / 16;
  const int covered = full_chunks_ * 16;
  const int rem = row_bytes_ - covered;
  has_tail_ = rem > 0;
  if (rem >= 8) {
    tail_lo_ = covered;
    tail_hi_ = row_bytes_ - 8;
  } else if (rem > 0) {
    tail_lo_ = row_bytes_ - 8;
    tail_hi_ = row_bytes_ - 8;
  }
  chunks_per_row_ = full_chunks_ + (has_tail_ ? 1 : 0);
  // The row byte each lane of a row's chunks reads (the same in every row); -1 when it reads
  // nothing new.
  const int per_row = chunks_per_row_ * 16;
  lane_bytes_.resize(per_row);
  for (int i = 0; i < per_row; ++i) {
    const int lane = i - covered;
    if (i < covered) {
      lane_bytes_[i] = i;
    } else if (lane < 8) {
      // Low half: the bytes not yet covered by the full chunks.
      lane_bytes_[i] = tail_lo_ + lane >= covered ? tail_lo_ + lane : -1;
    } else {
      // High half: only when the tail is 8 bytes or more, beyond what the low half took.
      const int b = tail_hi_ + lane - 8;
      lane_bytes_[i] = rem >= 8 && b >= covered + 8 ? b : -1;
    }
  }
  const size_t total = static_cast<size_t>(per_row) * image_.rows;
  bytes_.assign(total, 0);
  mask_.assign(total, 0);
  words_.assign(total, 0);
  for (int r = 0; r < image_.rows; ++r) {
    const uint8_t* p = image_.ptr<uint8_t>(r);
    const uint8_t* m = masked ? mask_image_.ptr<uint8_t>(r) : nullptr;
    const size_t row = static_cast<size_t>(r) * per_row;
    int i = 0;
    if (cn == 1) {
      // The full chunks' lanes read the row's bytes in order (lane_bytes_[i] == i): a loop the
      // compiler vectorises, setting what the loop below sets.
      uint8_t* __restrict bytes = bytes_.data() + row;
      uint8_t* __restrict lanes = mask_.data() + row;
      int16_t* __restrict words = words_.data() + row;
      for (; i < covered; ++i) {
        const uint8_t keep = m ? static_cast<uint8_t>(m[i] != 0 ? 0xFF : 0) : uint8_t{0xFF};
        const uint8_t v = static_cast<uint8_t>(p[i] & keep);
        bytes[i] = v;
        lanes[i] = keep;
        words[i] = v;
      }
    }
    for (; i < per_row; ++i) {
      const int b = lane_bytes_[i];
      if (b < 0 || (m && !m[cn == 1 ? b : b / 3])) continue;
      bytes_[row + i] = p[b];
      mask_[row + i] = 0xFF;
      words_[row + i] = p[b];
    }
  }
}

void MatchSadReference(const cv::Mat& image, const cv::Mat& templ, cv::Mat& result,
                       const cv::Mat& mask) {
  ScalarMap(image, templ, mask, result, AbsDiff);
}

void MatchSsdReference(const cv::Mat& image, const cv::Mat& templ, cv::Mat& result,
                       const cv::Mat& mask) {
  ScalarMap(image, templ, mask, result, SqDiff);
}

void MatchZnccReference(const cv::Mat& image, const cv::Mat& templ, cv::Mat& result,
                        const cv::Mat& mask) {
  CheckInputs(image, templ, mask);
  result.create(ResultSize(image, templ.size()), CV_32F);
  const int cn = templ.channels();
  double n = 0;
  double mean_t[3] = {0, 0, 0};
  for (int r = 0; r < templ.rows; ++r) {
    for (int i = 0; i < templ.cols * cn; ++i) {
      if (Counts(mask, r, i / cn)) mean_t[i % cn] += templ.ptr<uint8_t>(r)[i];
    }
    for (int j = 0; j < templ.cols; ++j) n += Counts(mask, r, j) ? 1 : 0;
  }
  for (int c = 0; c < cn; ++c) mean_t[c] /= n;
  for (int y = 0; y < result.rows; ++y) {
    for (int x = 0; x < result.cols; ++x) {
      double mean_i[3] = {0, 0, 0};
      for (int r = 0; r < templ.rows; ++r) {
        const uint8_t* a = image.ptr<uint8_t>(y + r) + x * cn;
        for (int i = 0; i < templ.cols * cn; ++i) {
          if (Counts(mask, r, i / cn)) mean_i[i % cn] += a[i];
        }
      }
      for (int c = 0; c < cn; ++c) mean_i[c] /= n;
      double num = 0, var_i = 0, var_t = 0;
      for (int r = 0; r < templ.rows; ++r) {
        const uint8_t* a = image.ptr<uint8_t>(y + r) + x * cn;
        const uint8_t* b = templ.ptr<uint8_t>(r);
        for (int i = 0; i < templ.cols * cn; ++i) {
          if (!Counts(mask, r, i / cn)) continue;
          const double di = a[i] - mean_i[i % cn];
          const double dt = b[i] - mean_t[i % cn];
          num += di * dt;
          var_i += di * di;
          var_t += dt * dt;
        }
      }
      result.at<float>(y, x) = (var_i > 0 && var_t > 0)
                                   ? static_cast<float>(num / std::sqrt(var_i * var_t))
                                   : std::numeric_limits<float>::quiet_NaN();
    }
  }
}

#if CV_SIMD128

namespace {

using KA = KernelAccess;

// SAD of one placement. v_reduce_sad (psadbw on x86) sums 16 absolute differences in one step;
// masked bytes are zeroed on both sides, so they add |0 - 0| = 0.
template <bool kMasked>
inline int SadAt(const uint8_t* p, size_t step, const PreparedTemplate& t) {
  const auto [rows, full, tail, lo, hi] = KA::Layout(t);
  const uint8_t* tb = KA::Bytes(t);
  const uint8_t* tm = KA::Mask(t);
  unsigned acc0 = 0, acc1 = 0;  // Two chains for instruction-level parallelism.
  for (int r = 0; r < rows; ++r, p += step) {
    int c = 0;
    for (; c + 1 < full; c += 2, tb += 32, tm += 32) {
      cv::v_uint8x16 a0 = cv::v_load(p + 16 * c), a1 = cv::v_load(p + 16 * c + 16);
      if (kMasked) {
        a0 &= cv::v_load(tm);
        a1 &= cv::v_load(tm + 16);
      }
      acc0 += cv::v_reduce_sad(a0, cv::v_load(tb));
      acc1 += cv::v_reduce_sad(a1, cv::v_load(tb + 16));
    }
    for (; c < full; ++c, tb += 16, tm += 16) {
      cv::v_uint8x16 a = cv::v_load(p + 16 * c);
      if (kMasked) a &= cv::v_load(tm);
      acc0 += cv::v_reduce_sad(a, cv::v_load(tb));
    }
    if (tail) {
      acc1 += cv::v_reduce_sad(cv::v_load_halves(p + lo, p + hi) & cv::v_load(tm), cv::v_load(tb));
      tb += 16;
      tm += 16;
    }
  }
  return static_cast<int>(acc0 + acc1);
}

// SAD of two neighbouring placements (x and x + 1) at once: each template chunk is loaded once
// for both, and the two sums are independent chains.
template <bool kMasked>
inline void SadPairAt(const uint8_t* p, int cn, size_t step, const PreparedTemplate& t,
                      int* out) {
  const auto [rows, full, tail, lo, hi] = KA::Layout(t);
  const uint8_t* tb = KA::Bytes(t);
  const uint8_t* tm = KA::Mask(t);
  unsigned acc0 = 0, acc1 = 0;
  for (int r = 0; r < rows; ++r, p += step) {
    const uint8_t* q = p + cn;
    for (int c = 0; c < full; ++c, tb += 16, tm += 16) {
      const cv::v_uint8x16 tv = cv::v_load(tb);
      cv::v_uint8x16 a0 = cv::v_load(p + 16 * c), a1 = cv::v_load(q + 16 * c);
      if (kMasked) {
        const cv::v_uint8x16 m = cv::v_load(tm);
        a0 &= m;
        a1 &= m;
      }
      acc0 += cv::v_reduce_sad(a0, tv);
      acc1 += cv::v_reduce_sad(a1, tv);
    }
    if (tail) {
      const cv::v_uint8x16 tv = cv::v_load(tb), m = cv::v_load(tm);
      acc0 += cv::v_reduce_sad(cv::v_load_halves(p + lo, p + hi) & m, tv);
      acc1 += cv::v_reduce_sad(cv::v_load_halves(q + lo, q + hi) & m, tv);
      tb += 16;
      tm += 16;
    }
  }
  out[0] = static_cast<int>(acc0);
  out[1] = static_cast<int>(acc1);
}

template <bool kMasked>
void VectorSadMap(const cv::Mat& image, const PreparedTemplate& t, cv::Mat& result) {
  const int cn = t.channels();
  const size_t step = image.step[0];
  for (int y = 0; y < result.rows; ++y) {
    int* out = result.ptr<int>(y);
    const uint8_t* p = image.ptr<uint8_t>(y);
    int x = 0;
    for (; x + 1 < result.cols; x += 2) SadPairAt<kMasked>(p + x * cn, cn, step, t, out + x);
    if (x < result.cols) out[x] = SadAt<kMasked>(p + x * cn, step, t);
  }
}

// sum I * T at one placement of an image already widened to 16 bits (`step` values a row): the
// template words are zero where masked, so no mask is needed. Widening the image once instead
// of at every placement (which unpacked each byte again for each of the placements covering
// it) takes the shuffles out of the inner loop, half of its instructions.
inline int CrossAt(const int16_t* p, size_t step, const PreparedTemplate& t) {
  const auto [rows, full, tail, lo, hi] = KA::Layout(t);
  const int16_t* tw = KA::Words(t);
  cv::v_int32x4 acc0 = cv::v_setzero_s32(), acc1 = cv::v_setzero_s32();
  for (int r = 0; r < rows; ++r, p += step) {
    for (int c = 0; c < full; ++c, tw += 16) {
      acc0 = cv::v_dotprod(cv::v_load(p + 16 * c), cv::v_load(tw), acc0);
      acc1 = cv::v_dotprod(cv::v_load(p + 16 * c + 8), cv::v_load(tw + 8), acc1);
    }
    if (tail) {
      acc0 = cv::v_dotprod(cv::v_load(p + lo), cv::v_load(tw), acc0);
      acc1 = cv::v_dotprod(cv::v_load(p + hi), cv::v_load(tw + 8), acc1);
      tw += 16;
    }
  }
  return cv::v_reduce_sum(acc0 + acc1);
}

// CrossAt for the four placements x .. x + 3 (pixel stride `cn`) at once: each template chunk is
// loaded once for the four, and the loop's overhead per row is shared.
inline void CrossAt4(const int16_t* p, int cn, size_t step, const PreparedTemplate& t, int* out) {
  const auto [rows, full, tail, lo, hi] = KA::Layout(t);
  const int16_t* tw = KA::Words(t);
  cv::v_int32x4 acc0 = cv::v_setzero_s32(), acc1 = cv::v_setzero_s32();
  cv::v_int32x4 acc2 = cv::v_setzero_s32(), acc3 = cv::v_setzero_s32();
  const int16_t* p1 = p + cn;
  const int16_t* p2 = p + 2 * cn;
  const int16_t* p3 = p + 3 * cn;
  auto add = [&](int a, int b, const int16_t* w) {
    const cv::v_int16x8 ta = cv::v_load(w), tb = cv::v_load(w + 8);
    acc0 = cv::v_dotprod(cv::v_load(p + a), ta, acc0);
    acc1 = cv::v_dotprod(cv::v_load(p1 + a), ta, acc1);
    acc2 = cv::v_dotprod(cv::v_load(p2 + a), ta, acc2);
    acc3 = cv::v_dotprod(cv::v_load(p3 + a), ta, acc3);
    acc0 = cv::v_dotprod(cv::v_load(p + b), tb, acc0);
    acc1 = cv::v_dotprod(cv::v_load(p1 + b), tb, acc1);
    acc2 = cv::v_dotprod(cv::v_load(p2 + b), tb, acc2);
    acc3 = cv::v_dotprod(cv::v_load(p3 + b), tb, acc3);
  };
  for (int r = 0; r < rows; ++r, p += step, p1 += step, p2 += step, p3 += step) {
    for (int c = 0; c < full; ++c, tw += 16) add(16 * c, 16 * c + 8, tw);
    if (tail) {
      add(lo, hi, tw);
      tw += 16;
    }
  }
  out[0] = cv::v_reduce_sum(acc0);
  out[1] = cv::v_reduce_sum(acc1);
  out[2] = cv::v_reduce_sum(acc2);
  out[3] = cv::v_reduce_sum(acc3);
}

#if SOFTSIGHT_AVX2_CROSS
// The 128-bit kernels above, 16 template words a 256-bit lane pair: the chunk's low 8 words
// against the image at its first offset, its high 8 at its second, as CrossAt pairs them (a
// full chunk: 16 consecutive words; the tail: `lo` and `hi`). Half the multiply-adds and loads
// of the 128-bit kernels, for the same exact integer sums (products of levels <= 255 summed in
// 32-bit lanes below 2^31, in any order): the correlation was a fifth of a ZNCC frame of ViSP's
// mire-2, its large dot's 72x54 template at up to 1.2x (issue 45).
__attribute__((target("avx2"))) inline __m256i Avx2Pair(const int16_t* lo, const int16_t* hi) {
  return _mm256_inserti128_si256(
      _mm256_castsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(lo))),
      _mm_loadu_si128(reinterpret_cast<const __m128i*>(hi)), 1);
}

__attribute__((target("avx2"))) inline __m256i Avx2Load(const int16_t* p) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}

__attribute__((target("avx2"))) inline int Avx2Sum(__m256i v) {
  __m128i s = _mm_add_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, 0x4E));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, 0xB1));
  return _mm_cvtsi128_si32(s);
}

// Avx2CrossAt4 for kN placements side by side (3: the last three of a map row, the whole row of
// the pose rungs' and the measurement's 3-wide maps, which were four placements with the fourth
// dropped: a quarter of their work, issue 45). Each placement's sum is its own, as in CrossAt.
template <int kN>
__attribute__((target("avx2"))) inline void Avx2CrossAtN(const int16_t* p, int cn, size_t step,
                                                         const int16_t* tw,
                                                         const KernelAccess::Chunks& layout,
                                                         int* out) {
  __m256i acc[kN];
  for (int k = 0; k < kN; ++k) acc[k] = _mm256_setzero_si256();
  for (int r = 0; r < layout.rows; ++r, p += step) {
    for (int c = 0; c < layout.full; ++c, tw += 16) {
      const __m256i w = Avx2Load(tw);
      const int a = 16 * c;
      for (int k = 0; k < kN; ++k) {
        acc[k] = _mm256_add_epi32(acc[k], _mm256_madd_epi16(Avx2Load(p + k * cn + a), w));
      }
    }
    if (layout.tail) {
      const __m256i w = Avx2Load(tw);
      const int lo = layout.lo, hi = layout.hi;
      for (int k = 0; k < kN; ++k) {
        acc[k] = _mm256_add_epi32(acc[k],
                                  _mm256_madd_epi16(Avx2Pair(p + k * cn + lo, p + k * cn + hi), w));
      }
      tw += 16;
    }
  }
  for (int k = 0; k < kN; ++k) out[k] = Avx2Sum(acc[k]);
}

// CrossAt4 in 256-bit lanes: the placements x .. x + 3 (pixel stride `cn`).
__attribute__((target("avx2"))) void Avx2CrossAt4(const int16_t* p, int cn, size_t step,
                                                   const int16_t* tw,
                                                   const KernelAccess::Chunks& layout, int* out) {
  Avx2CrossAtN<4>(p, cn, step, tw, layout, out);
}

// CrossAt in 256-bit lanes.
__attribute__((target("avx2"))) int Avx2CrossAt(const int16_t* p, size_t step, const int16_t* tw,
                                                const KernelAccess::Chunks& layout) {
  __m256i acc = _mm256_setzero_si256();
  for (int r = 0; r < layout.rows; ++r, p += step) {
    for (int c = 0; c < layout.full; ++c, tw += 16) {
      acc = _mm256_add_epi32(acc, _mm256_madd_epi16(Avx2Load(p + 16 * c), Avx2Load(tw)));
    }
    if (layout.tail) {
      acc = _mm256_add_epi32(
          acc, _mm256_madd_epi16(Avx2Pair(p + layout.lo, p + layout.hi), Avx2Load(tw)));
      tw += 16;
    }
  }
  return Avx2Sum(acc);
}

// CrossRows' placements (rows `step` values apart), in 256-bit lanes: the same placements four
// at a time, the same reads (the 16 words of a chunk are the two 8-word loads of CrossAt).
__attribute__((target("avx2"))) void Avx2CrossRows(const int16_t* widened, int step, int cn, const PreparedTemplate& t,
                                                   cv::Mat& result) {
  const KernelAccess::Chunks layout = KA::Layout(t);
  const int16_t* tw = KA::Words(t);
  for (int y = 0; y < result.rows; ++y) {
    int* out = result.ptr<int>(y);
    const int16_t* p = widened + static_cast<size_t>(step) * y;
    int x = 0;
    for (; x + 3 < result.cols; x += 4) {
      Avx2CrossAt4(p + x * cn, cn, static_cast<size_t>(step), tw, layout, out + x);
    }
    if (result.cols - x == 3) {
      Avx2CrossAtN<3>(p + x * cn, cn, static_cast<size_t>(step), tw, layout, out + x);
      x += 3;
    }
    for (; x < result.cols; ++x) {
      out[x] = Avx2CrossAt(p + x * cn, static_cast<size_t>(step), tw, layout);
    }
  }
}

bool& WideCrossKernel() {
  static bool on = __builtin_cpu_supports("avx2");
  return on;
}
#endif

// The map's placements from widened rows `step` values apart (a placement's row y at
// widened + step * y).
void CrossRows(const int16_t* widened, int step, int cn, const PreparedTemplate& t,
               cv::Mat& result) {
#if SOFTSIGHT_AVX2_CROSS
  if (WideCrossKernel()) {
    Avx2CrossRows(widened, step, cn, t, result);
    return;
  }
#endif
  for (int y = 0; y < result.rows; ++y) {
    int* out = result.ptr<int>(y);
    const int16_t* p = widened + static_cast<size_t>(step) * y;
    int x = 0;
    for (; x + 3 < result.cols; x += 4) CrossAt4(p + x * cn, cn, step, t, out + x);
    if (result.cols - x == 3) {
      int four[4];
      CrossAt4(p + x * cn, cn, step, t, four);
      std::copy(four, four + 3, out + x);
      x += 3;
    }
    for (; x < result.cols; ++x) out[x] = CrossAt(p + x * cn, step, t);
  }
}

void VectorCrossMap(const cv::Mat& image, const PreparedTemplate& t, cv::Mat& result,
                    ZnccScratch& scratch) {
  const int cn = t.channels();
  const int row_values = image.cols * cn;
  cv::Point at;
  if (cn == 1 && InSharedImage(image, scratch, &at)) {
    // A window of the shared image (the tracker's search, measurement and pose rungs match
    // several of the part it converted): that image is widened once, and each window's rows are
    // read from it at its step. The same values, so the same sums; a placement's reads past its
    // window's row (CrossAt4's dropped fourth) land in the shared rows or its padding.
    const size_t step = static_cast<size_t>(scratch.shared_size.width);
    if (!scratch.shared_widened_ready) {
      const size_t values = step * static_cast<size_t>(scratch.shared_size.height);
      scratch.shared_widened.resize(values + 1);  // Mostly the size it had: no new values.
      for (int y = 0; y < scratch.shared_size.height; ++y) {
        const uint8_t* p = scratch.shared_image + scratch.shared_step * static_cast<size_t>(y);
        int16_t* w = scratch.shared_widened.data() + step * static_cast<size_t>(y);
        for (size_t i = 0; i < step; ++i) w[i] = p[i];
      }
      scratch.shared_widened[values] = 0;
      scratch.shared_widened_ready = true;
    }
    CrossRows(scratch.shared_widened.data() + step * static_cast<size_t>(at.y) +
                  static_cast<size_t>(at.x),
              static_cast<int>(step), cn, t, result);
    return;
  }
  std::vector<int16_t>& widened = scratch.widened;
  // The last three placements of a map row are computed four at a time too (CrossAt4 shares
  // each template load between its placements: a third fewer instructions than CrossAt three
  // times, for the pose rungs' 3-wide maps and the measurement's 7-wide one); the placement past
  // the map row's end reads a pixel past the image row, which is the next row, or past the last
  // row, which is this padding. Its sum is dropped. One or two are cheaper one at a time. (The
  // 256-bit kernel computes the three alone: Avx2CrossAtN<3>.)
  const size_t pad = static_cast<size_t>(cn);
  const size_t values = static_cast<size_t>(row_values) * image.rows;
  widened.resize(values + pad);
  for (int y = 0; y < image.rows; ++y) {
    const uint8_t* p = image.ptr<uint8_t>(y);
    int16_t* w = widened.data() + static_cast<size_t>(row_values) * y;
    for (int i = 0; i < row_values; ++i) w[i] = p[i];
  }
  std::fill(widened.begin() + static_cast<std::ptrdiff_t>(values), widened.end(), int16_t{0});
  CrossRows(widened.data(), row_values, cn, t, result);
}

// sum I, sum I^2 and sum I * T over the counted pixels of one placement of a gray template at
// `p` (`step` bytes a row), in the template's chunks: the image bytes masked as the template's
// (a tail's bytes counted by a full chunk too are masked there), widened, and multiplied in
// pairs into 32-bit lanes, which hold every sum (kMaxTemplateValues * 255^2 < 2^31).
void GrayPlacementSums(const uint8_t* p, size_t step, const PreparedTemplate& t, int64_t* sum,
                       int64_t* sum_sq, int64_t* cross) {
  const auto [rows, full, tail, lo, hi] = KA::Layout(t);
  const uint8_t* tm = KA::Mask(t);
  const int16_t* tw = KA::Words(t);
  const cv::v_int16x8 ones = cv::v_setall_s16(1);
  cv::v_int32x4 s = cv::v_setzero_s32(), q = cv::v_setzero_s32(), x = cv::v_setzero_s32();
  const auto add = [&](const cv::v_uint8x16& raw) {
    const cv::v_uint8x16 v = raw & cv::v_load(tm);
    cv::v_uint16x8 a, b;
    cv::v_expand(v, a, b);
    const cv::v_int16x8 ia = cv::v_reinterpret_as_s16(a), ib = cv::v_reinterpret_as_s16(b);
    s = cv::v_dotprod(ia, ones, s);
    s = cv::v_dotprod(ib, ones, s);
    q = cv::v_dotprod(ia, ia, q);
    q = cv::v_dotprod(ib, ib, q);
    x = cv::v_dotprod(ia, cv::v_load(tw), x);
    x = cv::v_dotprod(ib, cv::v_load(tw + 8), x);
    tm += 16;
    tw += 16;
  };
  for (int r = 0; r < rows; ++r, p += step) {
    for (int c = 0; c < full; ++c) add(cv::v_load(p + 16 * c));
    if (tail) add(cv::v_load_halves(p + lo, p + hi));
  }
  *sum = cv::v_reduce_sum(s);
  *sum_sq = cv::v_reduce_sum(q);
  *cross = cv::v_reduce_sum(x);
}

}  // namespace

#endif  // CV_SIMD128

void MatchSad(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result) {
  CV_Assert(!templ.empty());
  CheckInputs(image, templ.image(), templ.mask());
#if CV_SIMD128
  if (KernelAccess::Vectorised(templ)) {
    result.create(ResultSize(image, templ.size()), CV_32S);
    if (templ.masked()) {
      VectorSadMap<true>(image, templ, result);
    } else {
      VectorSadMap<false>(image, templ, result);
    }
    return;
  }
#endif
  ScalarMap(image, templ.image(), templ.mask(), result, AbsDiff);
}

void MatchSsd(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result,
              ZnccScratch& scratch) {
  CV_Assert(!templ.empty());
  CheckInputs(image, templ.image(), templ.mask());
#if CV_SIMD128
  if (KernelAccess::Vectorised(templ)) {
    if (templ.channels() == 1) {
      SsdFromSums<1>(image, templ, result, scratch);
    } else {
      SsdFromSums<3>(image, templ, result, scratch);
    }
    return;
  }
#endif
  (void)scratch;
  ScalarMap(image, templ.image(), templ.mask(), result, SqDiff);
}

void MatchSsd(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result) {
  ZnccScratch scratch;
  MatchSsd(image, templ, result, scratch);
}

namespace {

// ZNCC keeps the widened image in its scratch.
void CrossCorrelation(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result,
                      ZnccScratch& scratch) {
  CV_Assert(!templ.empty());
  CheckInputs(image, templ.image(), templ.mask());
#if CV_SIMD128
  if (KernelAccess::Vectorised(templ)) {
    result.create(ResultSize(image, templ.size()), CV_32S);
    VectorCrossMap(image, templ, result, scratch);
    return;
  }
#endif
  (void)scratch;
  ScalarMap(image, templ.image(), templ.mask(), result, Product);
}

}  // namespace

void MatchZncc(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& result,
               ZnccScratch& scratch) {
  CV_Assert(!templ.empty());
  CheckInputs(image, templ.image(), templ.mask());
  const int cn = templ.channels();
  if (templ.masked()) {
    if (cn == 1) {
      MaskedZncc<1>(image, templ, result, scratch);
    } else {
      MaskedZncc<3>(image, templ, result, scratch);
    }
    return;
  }
  CrossCorrelation(image, templ, scratch.cross, scratch);
  // Window sums from integral images: exact (32-bit sums, 64-bit float squares < 2^53).
  cv::integral(image, scratch.sum, scratch.sum_sq, CV_32S, CV_64F);
  result.create(scratch.cross.size(), CV_32F);
  const int w = templ.size().width, h = templ.size().height;
  const int64_t n = templ.count();
  for (int y = 0; y < result.rows; ++y) {
    const int* cross = scratch.cross.ptr<int>(y);
    const int* s0 = scratch.sum.ptr<int>(y);
    const int* s1 = scratch.sum.ptr<int>(y + h);
    const double* q0 = scratch.sum_sq.ptr<double>(y);
    const double* q1 = scratch.sum_sq.ptr<double>(y + h);
    float* out = result.ptr<float>(y);
    for (int x = 0; x < result.cols; ++x) {
      int64_t sums[3] = {0, 0, 0};
      int64_t sum_sq = 0;
      for (int c = 0; c < cn; ++c) {
        const int a = x * cn + c, b = (x + w) * cn + c;
        sums[c] = int64_t{s1[b]} - s1[a] - s0[b] + s0[a];
        sum_sq += static_cast<int64_t>(q1[b] - q1[a] - q0[b] + q0[a]);
      }
      out[x] = ZnccFromSums(n, cross[x], sums, sum_sq, cn, templ);
    }
  }
}

bool MatchZnccAt(const cv::Mat& image, cv::Point top_left, const PreparedTemplate& templ,
                 float* zncc) {
#if CV_SIMD128
  if (templ.empty() || templ.channels() != 1 || image.type() != CV_8UC1 ||
      !KernelAccess::Vectorised(templ)) {
    return false;
  }
  CV_Assert(top_left.x >= 0 && top_left.y >= 0 && top_left.x + templ.size().width <= image.cols &&
            top_left.y + templ.size().height <= image.rows);
  int64_t sum = 0, sum_sq = 0, cross = 0;
  GrayPlacementSums(image.ptr<uint8_t>(top_left.y) + top_left.x, image.step[0], templ, &sum,
                    &sum_sq, &cross);
  *zncc = ZnccFromSums(templ.count(), cross, &sum, sum_sq, 1, templ);
  return true;
#else
  (void)image;
  (void)top_left;
  (void)templ;
  (void)zncc;
  return false;
#endif
}

bool WideCrossKernelAvailable() {
#if SOFTSIGHT_AVX2_CROSS
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

void UseWideCrossKernel(bool on) {
#if SOFTSIGHT_AVX2_CROSS
  WideCrossKernel() = on && __builtin_cpu_supports("avx2");
#else
  (void)on;
#endif
}

void ShareWindowSums(const cv::Mat& image, ZnccScratch& scratch) {
  scratch.shared_image = nullptr;
  scratch.shared_widened_ready = false;  // Widened again on first use.
  if (image.type() != CV_8UC1 || image.empty()) return;
  const size_t prefix_step = static_cast<size_t>(image.cols + 1) * 2;
  scratch.shared_prefix.resize(prefix_step * image.rows);
  for (int y = 0; y < image.rows; ++y) {
    PrefixRow<1>(image.ptr<uint8_t>(y), image.cols, scratch.shared_prefix.data() + prefix_step * y);
  }
  scratch.shared_image = image.data;
  scratch.shared_step = image.step[0];
  scratch.shared_size = image.size();
}

}  // namespace softsight
