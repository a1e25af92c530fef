#include "track/colour_kernels.h"

#include <algorithm>
#include <cstring>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

namespace softsight {
namespace {

// OpenCV's RGB2HSV_b tables (imgproc/src/color_hsv.simd.hpp): hsv_shift 12, 8-bit hue 0..179.
constexpr int kHsvShift = 12;
struct HsvTables {
  int sdiv[256];
  int hdiv[256];
  HsvTables() {
    sdiv[0] = hdiv[0] = 0;
    for (int i = 1; i < 256; ++i) {
      sdiv[i] = cv::saturate_cast<int>((255 << kHsvShift) / (1. * i));
      hdiv[i] = cv::saturate_cast<int>((180 << kHsvShift) / (6. * i));
    }
  }
};
const HsvTables& Tables() {
  static const HsvTables tables;
  return tables;
}

// Asks for row y + 2 of `image` (row_bytes long) while row y is read: a region's rows are
// separate streams of a frame usually not in the cache, and a pass that is the first to touch
// them otherwise waits on every row's loads.
void PrefetchTwoRowsAhead(const cv::Mat& image, int y, size_t row_bytes) {
  if (y + 2 >= image.rows) return;
  const uchar* ahead = image.ptr<uchar>(y + 2);
  for (size_t i = 0; i < row_bytes; i += 64) __builtin_prefetch(ahead + i);
  __builtin_prefetch(ahead + row_bytes - 1);
}

}  // namespace

bool HsvBox::ContainsHue(int hue) const {
  return h.contains_hue(hue);
}

cv::Vec3b BgrToHsvExact(uchar b, uchar g, uchar r) {
  const HsvTables& t = Tables();
  const int v = std::max({b, g, r});
  const int vmin = std::min({b, g, r});
  const int diff = v - vmin;
  const int vr = v == r ? -1 : 0;
  const int vg = v == g ? -1 : 0;
  const int s = (diff * t.sdiv[v] + (1 << (kHsvShift - 1))) >> kHsvShift;
  int h = (vr & (g - b)) + (~vr & ((vg & (b - r + 2 * diff)) + ((~vg) & (r - g + 4 * diff))));
  h = (h * t.hdiv[diff] + (1 << (kHsvShift - 1))) >> kHsvShift;
  h += h < 0 ? 180 : 0;
  return cv::Vec3b(cv::saturate_cast<uchar>(h), static_cast<uchar>(s), static_cast<uchar>(v));
}

HsvClassifier::HsvClassifier(const HsvBox& box) : box_(box) {
  full_hue_ = box.h.covers_all_hues();
  gray_in_ = box.ContainsHue(0) && box.s.lo == 0;
  if (full_hue_) return;
  // Rounded hue u in 0..179 comes from the unrounded t in [-30, 150): u = round(t), plus 180 when
  // negative. So u in [a, b] is t in [a, min(b, 149)] and t in [max(a, 150) - 180, b - 180].
  std::array<std::pair<int, int>, 4> parts;
  int n = 0;
  auto add = [&](int a, int b) {
    if (a <= 149) parts[n++] = {a, std::min(b, 149)};
    if (b >= 150) parts[n++] = {std::max(a, 150) - 180, b - 180};
  };
  if (!box.h.wraps()) {
    add(box.h.lo, std::min(box.h.hi, 179));
  } else {
    add(box.h.lo, 179);
    add(0, box.h.hi);
  }
  for (int i = 1; i < n; ++i) {  // Insertion sort by start (at most four parts).
    for (int j = i; j > 0 && parts[j].first < parts[j - 1].first; --j) std::swap(parts[j], parts[j - 1]);
  }
  for (int i = 0; i < n; ++i) {
    if (intervals_ > 0 && parts[i].first <= t_hi_[intervals_ - 1] + 1) {
      t_hi_[intervals_ - 1] = std::max(t_hi_[intervals_ - 1], parts[i].second);
    } else {
      t_lo_[intervals_] = parts[i].first;
      t_hi_[intervals_] = parts[i].second;
      ++intervals_;
    }
  }
  // The sectors of the largest channel whose hues can come within a unit of an interval (the
  // vector path's "near" test, below): red's t lies in [-30, 30], green's in [30, 90], blue's in
  // [90, 150].
  hue_sectors_ = 0;
  for (int sector = 0; sector < 3; ++sector) {
    const int lo = -30 + 60 * sector, hi = lo + 60;
    for (int i = 0; i < intervals_; ++i) {
      if (hi > t_lo_[i] - 1 && lo < t_hi_[i] + 1) hue_sectors_ |= 1 << sector;
    }
  }
}

void HsvClassifier::ClassifyScalar(const cv::Mat& bgr, cv::Mat& mask) const {
  CV_Assert(bgr.type() == CV_8UC3 && mask.type() == CV_8UC1 && mask.size() == bgr.size());
  for (int y = 0; y < bgr.rows; ++y) {
    const uchar* p = bgr.ptr<uchar>(y);
    uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < bgr.cols; ++x, p += 3) {
      const cv::Vec3b hsv = BgrToHsvExact(p[0], p[1], p[2]);
      m[x] = box_.Contains(hsv[0], hsv[1], hsv[2]) ? 255 : 0;
    }
  }
}

void HsvClassifier::ClassifyFlatScalar(const cv::Mat& gray, cv::Mat& mask) const {
  CV_Assert(gray.type() == CV_8UC1 && mask.type() == CV_8UC1 && mask.size() == gray.size());
  for (int y = 0; y < gray.rows; ++y) {
    const uchar* p = gray.ptr<uchar>(y);
    uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < gray.cols; ++x) {
      const cv::Vec3b hsv = BgrToHsvExact(p[x], p[x], p[x]);
      m[x] = box_.Contains(hsv[0], hsv[1], hsv[2]) ? 255 : 0;
    }
  }
}

void HsvClassifier::ClassifyFlat(const cv::Mat& gray, cv::Mat& mask) const {
  CV_Assert(gray.type() == CV_8UC1 && mask.type() == CV_8UC1 && mask.size() == gray.size());
  // BgrToHsvExact(v, v, v) is (0, 0, v) exactly: in when the box holds hue 0 and saturation 0
  // (gray_in_), and v in its value range.
  const uchar lo = static_cast<uchar>(box_.v.lo), hi = static_cast<uchar>(box_.v.hi);
  for (int y = 0; y < gray.rows; ++y) {
    const uchar* p = gray.ptr<uchar>(y);
    uchar* m = mask.ptr<uchar>(y);
    if (!gray_in_) {
      std::memset(m, 0, static_cast<size_t>(gray.cols));
      continue;
    }
    int x = 0;
#if CV_SIMD128
    const cv::v_uint8x16 v_lo = cv::v_setall_u8(lo), v_hi = cv::v_setall_u8(hi);
    for (; x + 16 <= gray.cols; x += 16) {
      const cv::v_uint8x16 v = cv::v_load(p + x);
      cv::v_store(m + x, (v >= v_lo) & (v <= v_hi));
    }
#endif
    for (; x < gray.cols; ++x) m[x] = p[x] >= lo && p[x] <= hi ? 255 : 0;
  }
}

bool ExtractFlatPlaneReference(const cv::Mat& bgr, cv::Mat& plane) {
  CV_Assert(bgr.type() == CV_8UC3 && plane.type() == CV_8UC1 && plane.size() == bgr.size());
  for (int y = 0; y < bgr.rows; ++y) {
    const cv::Vec3b* p = bgr.ptr<cv::Vec3b>(y);
    uchar* out = plane.ptr<uchar>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      if (p[x][0] != p[x][1] || p[x][1] != p[x][2]) return false;
      out[x] = p[x][0];
    }
  }
  return true;
}

bool ExtractFlatPlane(const cv::Mat& bgr, cv::Mat& plane) {
  CV_Assert(bgr.type() == CV_8UC3 && plane.type() == CV_8UC1 && plane.size() == bgr.size());
  const int n = bgr.cols;
  const size_t row_bytes = static_cast<size_t>(n) * 3;
  for (int y = 0; y < bgr.rows; ++y) {
    // As Classify does (without it this pass, the first to touch the region, waited on every
    // row's loads: 0.235 -> 0.215 ms a frame on mire-2).
    PrefetchTwoRowsAhead(bgr, y, row_bytes);
    const uchar* p = bgr.ptr<uchar>(y);
    uchar* out = plane.ptr<uchar>(y);
    int x = 0;
#if CV_SIMD128
    // The row's last pixels as its last 16 again (the same values where they overlap).
    for (; x < n && n >= 16; x += 16) {
      if (x + 16 > n) x = n - 16;
      cv::v_uint8x16 b, g, r;
      cv::v_load_deinterleave(p + 3 * x, b, g, r);
      if (!cv::v_check_all((b == g) & (g == r))) return false;
      cv::v_store(out + x, b);
    }
#endif
    for (; x < n; ++x) {
      const uchar* c = p + 3 * x;
      if (c[0] != c[1] || c[1] != c[2]) return false;
      out[x] = c[0];
    }
  }
  return true;
}

void HsvClassifier::Classify(const cv::Mat& bgr, cv::Mat& mask) const {
  CV_Assert(bgr.type() == CV_8UC3 && mask.type() == CV_8UC1 && mask.size() == bgr.size());
  // A window's rows are short, separate streams of the frame, which is usually not in the cache
  // yet: the hardware prefetcher does not follow them, and waiting for the loads was a good part
  // of the classifier's time. The rows two ahead are asked for while this one is classified
  // (ClassifyRows).
  ClassifyRows(bgr, mask);
}

// The vector path decides each pixel from exact integer inequalities where they are conclusive,
// and leaves the rest (within one hue unit or one saturation unit of a boundary, where OpenCV's
// rounding through its division tables decides) to the exact scalar formula:
//  - saturation: OpenCV's S is floor(255 diff / v + e + 1/2) with |e| <= 0.031, so
//    255 diff >= lo v gives S >= lo, 255 diff <= (lo - 1) v gives S < lo (likewise for hi);
//  - hue: OpenCV's H is floor(t + e + 1/2), t = 30 N / diff, |e| <= 0.16, so t in [A, B] (an
//    interval of integers) is in, and t <= A - 1 or t >= B + 1 for every interval is out. The
//    tests use the numerator N' = N + diff of OpenCV's hue = N * 30 / diff (N = g - b when the
//    maximum is red, b - r + 2 diff when green, r - g + 4 diff when blue), shifted to be >= 0.
// All products stay below 2^16: 30 N' <= 30 * 6 * 255, 255 diff, (B + 31) diff <= 180 * 255.
// The box's constants are set up once for all the rows: per row, they were a tenth of the
// classifier's instructions on the tracker's windows (issue 45).
void HsvClassifier::ClassifyRows(const cv::Mat& image, cv::Mat& mask_image) const {
  const int n = image.cols;
  const size_t row_bytes = static_cast<size_t>(n) * 3;
#if CV_SIMD128
  using namespace cv;
  const v_uint8x16 v_lo = v_setall_u8(static_cast<uchar>(box_.v.lo));
  const v_uint8x16 v_hi = v_setall_u8(static_cast<uchar>(box_.v.hi));
  const v_uint16x8 s_lo = v_setall_u16(static_cast<ushort>(box_.s.lo));
  const v_uint16x8 s_lo1 = v_setall_u16(static_cast<ushort>(std::max(0, box_.s.lo - 1)));
  const v_uint16x8 s_hi = v_setall_u16(static_cast<ushort>(box_.s.hi));
  const v_uint16x8 s_hi1 = v_setall_u16(static_cast<ushort>(box_.s.hi + 1));
  const v_uint16x8 k255 = v_setall_u16(255), k30 = v_setall_u16(30), k3 = v_setall_u16(3),
                   k5 = v_setall_u16(5);
  const v_uint16x8 all16 = v_setall_u16(0xffff), none16 = v_setzero_u16();
  const bool s_lo_can_fail = box_.s.lo > 0, s_hi_can_fail = box_.s.hi < 255;
  // A hue test A d <= 30 N' <= B d is one comparison: 30 N' - A d <= (B - A) d, unsigned, where
  // a value below A d wraps around to more than any width (all products are below 45900).
  std::array<v_uint16x8, 3> in_a, in_width, near_a, near_width, near_b;
  std::array<bool, 3> near_a_any{};
  for (int i = 0; i < intervals_; ++i) {
    in_a[i] = v_setall_u16(static_cast<ushort>(t_lo_[i] + 30));
    in_width[i] = v_setall_u16(static_cast<ushort>(t_hi_[i] - t_lo_[i]));
    near_a_any[i] = t_lo_[i] + 29 < 0;  // No t lies below: the lower side never excludes.
    near_a[i] = v_setall_u16(static_cast<ushort>(std::max(0, t_lo_[i] + 29)));
    near_width[i] = v_setall_u16(static_cast<ushort>(t_hi_[i] - t_lo_[i] + 2));
    near_b[i] = v_setall_u16(static_cast<ushort>(t_hi_[i] + 31));
  }
  const v_uint16x8 one16 = v_setall_u16(1), two16 = v_setall_u16(2);
  // a <= b, unsigned: the saturating difference is 0.
  auto at_most = [&](const v_uint16x8& a, const v_uint16x8& b) { return (a - b) == none16; };
  const v_uint8x16 gray_in = gray_in_ ? v_setall_u8(0xff) : v_setzero_u8();
  const v_uint8x16 sector_r = v_setall_u8(hue_sectors_ & 1 ? 0xff : 0);
  const v_uint8x16 sector_g = v_setall_u8(hue_sectors_ & 2 ? 0xff : 0);
  const v_uint8x16 sector_b = v_setall_u8(hue_sectors_ & 4 ? 0xff : 0);
  const bool sectors_can_fail = !full_hue_ && hue_sectors_ != 7;

  // In / out decisions for 8 pixels (16-bit lanes). `s255` is 255 diff, `above_lo1` whether it
  // exceeds (lo - 1) v (computed once for the early exit below).
  auto decide = [&](const v_uint16x8& b, const v_uint16x8& g, const v_uint16x8& r,
                    const v_uint16x8& v, const v_uint16x8& d, const v_uint16x8& s255,
                    const v_uint16x8& above_lo1, v_uint16x8& in, v_uint16x8& out) {
    in = all16;
    out = none16;
    if (s_lo_can_fail) {
      in &= at_most(v_mul_wrap(s_lo, v), s255);
      out |= ~above_lo1;
    }
    if (s_hi_can_fail) {
      in &= s255 <= v_mul_wrap(s_hi, v);
      out |= s255 >= v_mul_wrap(s_hi1, v);
    }
    if (full_hue_) return;
    const v_uint16x8 is_r = v == r, is_g = (v == g) & ~is_r;
    const v_uint16x8 n_r = v_sub_wrap(v_add_wrap(g, d), b);
    const v_uint16x8 n_g = v_sub_wrap(v_add_wrap(b, v_mul_wrap(d, k3)), r);
    const v_uint16x8 n_b = v_sub_wrap(v_add_wrap(r, v_mul_wrap(d, k5)), g);
    const v_uint16x8 t30 = v_mul_wrap(v_select(is_r, n_r, v_select(is_g, n_g, n_b)), k30);
    v_uint16x8 hue_in = none16, hue_near = none16;
    for (int i = 0; i < intervals_; ++i) {
      hue_in |= at_most(v_sub_wrap(t30, v_mul_wrap(in_a[i], d)), v_mul_wrap(in_width[i], d));
      if (near_a_any[i]) {
        hue_near |= at_most(v_add_wrap(t30, one16), v_mul_wrap(near_b[i], d));
      } else {
        // near_a d < 30 N' < near_b d (d >= 1 here; flat pixels are decided apart).
        hue_near |= at_most(v_sub_wrap(t30, v_add_wrap(v_mul_wrap(near_a[i], d), one16)),
                            v_sub_wrap(v_mul_wrap(near_width[i], d), two16));
      }
    }
    in &= hue_in;
    out |= ~hue_near;
  };

#endif
  for (int y = 0; y < image.rows; ++y) {
    PrefetchTwoRowsAhead(image, y, row_bytes);
    const uchar* bgr = image.ptr<uchar>(y);
    uchar* mask = mask_image.ptr<uchar>(y);
    int x = 0;
#if CV_SIMD128
    for (; x < n && n >= 16; x += 16) {
      // The row's last pixels: the last 16 again, overlapping the previous chunk (each pixel's
      // result depends on it alone), so no pixel of a row of 16 or more takes the scalar formula
      // for being in the tail (on the tracker's windows, a tenth of the pixels did).
      if (x + 16 > n) x = n - 16;
      v_uint8x16 b8, g8, r8;
      v_load_deinterleave(bgr + 3 * x, b8, g8, r8);
      const v_uint8x16 v8 = v_max(b8, v_max(g8, r8));
      const v_uint8x16 d8 = v_sub_wrap(v8, v_min(b8, v_min(g8, r8)));
      const v_uint8x16 v_ok = (v8 >= v_lo) & (v8 <= v_hi);
      // 16 flat pixels (a gray recording handed over as BGR: b == g == r): hue 0 and saturation 0
      // exactly, so each is in by its value alone, as the flat case below decides it.
      if (v_check_all(d8 == v_setzero_u8())) {
        v_store(mask + x, gray_in & v_ok);
        continue;
      }
      // Most pixels of a scene are far from the marker's hue, value or saturation: when all 16
      // are out on those alone (exact, as above), the full test is not needed. First (8-bit, the
      // cheapest) when none of the 16 has its largest channel in a sector whose hues reach the box
      // (decide() would find none of them near a hue interval; a flat pixel has no hue).
      if (sectors_can_fail) {
        const v_uint8x16 is_r = v8 == r8, is_g = (v8 == g8) & ~is_r, is_b = ~(is_r | is_g);
        const v_uint8x16 may_be_in = (is_r & sector_r) | (is_g & sector_g) | (is_b & sector_b) |
                                     ((d8 == v_setzero_u8()) & gray_in);
        if (!v_check_any(v_ok & may_be_in)) {
          v_store(mask + x, v_setzero_u8());
          continue;
        }
      }
      v_uint16x8 vv0, vv1, d0, d1;
      v_expand(v8, vv0, vv1);
      v_expand(d8, d0, d1);
      const v_uint16x8 s255_0 = v_mul_wrap(d0, k255), s255_1 = v_mul_wrap(d1, k255);
      v_uint16x8 above_lo1_0 = all16, above_lo1_1 = all16;
      if (s_lo_can_fail) {
        above_lo1_0 = ~at_most(s255_0, v_mul_wrap(s_lo1, vv0));
        above_lo1_1 = ~at_most(s255_1, v_mul_wrap(s_lo1, vv1));
        if (!v_check_any(v_ok & v_pack(above_lo1_0, above_lo1_1))) {
          v_store(mask + x, v_setzero_u8());
          continue;
        }
      }
      v_uint16x8 b0, b1, g0, g1, r0, r1;
      v_expand(b8, b0, b1);
      v_expand(g8, g0, g1);
      v_expand(r8, r0, r1);
      v_uint16x8 in0, in1, out0, out1;
      decide(b0, g0, r0, vv0, d0, s255_0, above_lo1_0, in0, out0);
      decide(b1, g1, r1, vv1, d1, s255_1, above_lo1_1, in1, out1);
      v_uint8x16 in = v_pack(in0, in1) & v_ok;
      v_uint8x16 out = v_pack(out0, out1) | ~v_ok;
      // max == min: hue 0 and saturation 0 exactly.
      const v_uint8x16 flat = d8 == v_setzero_u8();
      in = v_select(flat, gray_in & v_ok, in);
      out = v_select(flat, ~in, out);
      v_store(mask + x, in);
      const v_uint8x16 open = ~(in | out);
      // The undecided pixels, one bit each: visited by their bits rather than by 16 tests.
      for (int bits = v_signmask(open); bits != 0; bits &= bits - 1) {
        const int k = __builtin_ctz(static_cast<unsigned>(bits));
        const uchar* p = bgr + 3 * (x + k);
        const cv::Vec3b hsv = BgrToHsvExact(p[0], p[1], p[2]);
        mask[x + k] = box_.Contains(hsv[0], hsv[1], hsv[2]) ? 255 : 0;
      }
    }
#endif
    for (; x < n; ++x) {
      const uchar* p = bgr + 3 * x;
      const cv::Vec3b hsv = BgrToHsvExact(p[0], p[1], p[2]);
      mask[x] = box_.Contains(hsv[0], hsv[1], hsv[2]) ? 255 : 0;
    }
  }
}

void ClassifyHsvOpenCv(const cv::Mat& bgr, const HsvBox& box, cv::Mat& mask) {
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  if (!box.h.wraps()) {
    cv::inRange(hsv, cv::Scalar(box.h.lo, box.s.lo, box.v.lo),
                cv::Scalar(box.h.hi, box.s.hi, box.v.hi), mask);
    return;
  }
  // Wrapping hue: rotate it so the range starts at 0, then one inRange.
  cv::Mat lut(1, 256, CV_8UC3);
  for (int i = 0; i < 256; ++i) {
    const int hue = i < 180 ? box.h.hue_offset(i) : 255;
    lut.at<cv::Vec3b>(0, i) = cv::Vec3b(static_cast<uchar>(hue), static_cast<uchar>(i),
                                        static_cast<uchar>(i));
  }
  cv::LUT(hsv, lut, hsv);
  cv::inRange(hsv, cv::Scalar(0, box.s.lo, box.v.lo),
              cv::Scalar(box.h.hue_span(), box.s.hi, box.v.hi), mask);
}

namespace {

// One 3x3 erosion (min) or dilation (max) of the padded plane `src` into the inside of the padded
// plane `dst` (both with one row and column of border all round; the border of `src` set).
// The element and the operation are constants of the template: tested per 16 pixels, they were a
// sixth of the pass's instructions (issue 45).
template <bool cross, bool erode>
void Morph3x3PassOf(const cv::Mat& src, cv::Mat& dst) {
  const int w = dst.cols - 2, h = dst.rows - 2;
  for (int y = 0; y < h; ++y) {
    const uchar* up = src.ptr<uchar>(y) + 1;
    const uchar* mid = src.ptr<uchar>(y + 1) + 1;
    const uchar* down = src.ptr<uchar>(y + 2) + 1;
    uchar* out = dst.ptr<uchar>(y + 1) + 1;
    int x = 0;
#if CV_SIMD128
    // 16 outputs from x: each depends on `src` only, so outputs computed twice are the same.
    const auto sixteen = [&](int x) {
      using namespace cv;
      const v_uint8x16 c = v_load(mid + x), l = v_load(mid + x - 1), r = v_load(mid + x + 1);
      const v_uint8x16 u = v_load(up + x), d = v_load(down + x);
      v_uint8x16 m;
      if constexpr (erode) {
        m = v_min(v_min(c, v_min(l, r)), v_min(u, d));
        if constexpr (!cross) {
          m = v_min(m, v_min(v_min(v_load(up + x - 1), v_load(up + x + 1)),
                             v_min(v_load(down + x - 1), v_load(down + x + 1))));
        }
      } else {
        m = v_max(v_max(c, v_max(l, r)), v_max(u, d));
        if constexpr (!cross) {
          m = v_max(m, v_max(v_max(v_load(up + x - 1), v_load(up + x + 1)),
                             v_max(v_load(down + x - 1), v_load(down + x + 1))));
        }
      }
      v_store(out + x, m);
    };
    for (; x + 16 <= w; x += 16) sixteen(x);
    // The row's rest as its last 16 pixels, overlapping the chunk before: a window's width is
    // rarely a multiple of 16, and the rest one pixel at a time was a third of the passes'
    // instructions (issue 45).
    if (x < w && w >= 16) {
      sixteen(w - 16);
      x = w;
    }
#endif
    for (; x < w; ++x) {
      uchar m = mid[x];
      const uchar n[4] = {mid[x - 1], mid[x + 1], up[x], down[x]};
      const uchar diag[4] = {up[x - 1], up[x + 1], down[x - 1], down[x + 1]};
      for (uchar v : n) m = erode ? std::min(m, v) : std::max(m, v);
      if constexpr (!cross) {
        for (uchar v : diag) m = erode ? std::min(m, v) : std::max(m, v);
      }
      out[x] = m;
    }
  }
}

void Morph3x3Pass(const cv::Mat& src, cv::Mat& dst, bool cross, bool erode) {
  if (cross) {
    erode ? Morph3x3PassOf<true, true>(src, dst) : Morph3x3PassOf<true, false>(src, dst);
  } else {
    erode ? Morph3x3PassOf<false, true>(src, dst) : Morph3x3PassOf<false, false>(src, dst);
  }
}

void SetBorder(cv::Mat& padded, int w, int h, uchar value) {
  std::memset(padded.ptr<uchar>(0), value, static_cast<size_t>(w + 2));
  std::memset(padded.ptr<uchar>(h + 1), value, static_cast<size_t>(w + 2));
  for (int y = 1; y <= h; ++y) {
    uchar* row = padded.ptr<uchar>(y);
    row[0] = value;
    row[w + 1] = value;
  }
}

}  // namespace

void OpenClose3x3(cv::Mat& mask, bool cross, cv::Mat& scratch) {
  CV_Assert(mask.type() == CV_8UC1);
  const int w = mask.cols, h = mask.rows;
  if (w == 0 || h == 0) return;
  // Two padded planes in one buffer: rows of w + 2 border bytes + 16 bytes of slack, so the vector
  // loop's loads stay inside the buffer.
  const int stride = w + 2 + 16;
  const int rows = h + 2;
  const size_t bytes = static_cast<size_t>(stride) * rows * 2;
  if (scratch.empty() || scratch.total() * scratch.elemSize() < bytes) {
    scratch.create(1, static_cast<int>(bytes), CV_8U);
  }
  cv::Mat a(rows, w + 2, CV_8U, scratch.data, static_cast<size_t>(stride));
  cv::Mat b(rows, w + 2, CV_8U, scratch.data + static_cast<size_t>(stride) * rows,
            static_cast<size_t>(stride));
  const cv::Rect inner(1, 1, w, h);
  mask.copyTo(a(inner));
  // Opening: erode (outside counts as 255), dilate (outside 0); closing: dilate, erode.
  SetBorder(a, w, h, 255);
  Morph3x3Pass(a, b, cross, true);
  SetBorder(b, w, h, 0);
  Morph3x3Pass(b, a, cross, false);
  SetBorder(a, w, h, 0);
  Morph3x3Pass(a, b, cross, false);
  SetBorder(b, w, h, 255);
  Morph3x3Pass(b, a, cross, true);
  a(inner).copyTo(mask);
}

void OpenClose3x3Reference(cv::Mat& mask, bool cross) {
  const cv::Mat kernel =
      cv::getStructuringElement(cross ? cv::MORPH_CROSS : cv::MORPH_RECT, cv::Size(3, 3));
  cv::Mat isolated = mask.clone(), opened, closed;
  cv::morphologyEx(isolated, opened, cv::MORPH_OPEN, kernel);
  cv::morphologyEx(opened, closed, cv::MORPH_CLOSE, kernel);
  closed.copyTo(mask);
}

void MarkOutside(cv::Mat& mask, uchar outside, std::vector<cv::Point>& stack) {
  CV_Assert(mask.type() == CV_8UC1 && outside != 0);
  // A span fill: each seed's run of 0 in its row is marked at once, and the rows above and below
  // it get one seed per run of 0 beside it (a pixel at a time, a stack push per pixel, cost 3x
  // cv::floodFill).
  stack.clear();
  const int width = mask.cols, height = mask.rows;
  const auto seed_runs = [&](int y, int x0, int x1) {  // One seed per run of 0 in [x0, x1].
    const uchar* row = mask.ptr<uchar>(y);
    for (int x = x0; x <= x1;) {
      if (row[x] != 0) {
        ++x;
        continue;
      }
      stack.emplace_back(x, y);
      while (x <= x1 && row[x] == 0) ++x;
    }
  };
  seed_runs(0, 0, width - 1);
  seed_runs(height - 1, 0, width - 1);
  for (int y = 1; y + 1 < height; ++y) {
    seed_runs(y, 0, 0);
    seed_runs(y, width - 1, width - 1);
  }
  while (!stack.empty()) {
    const cv::Point p = stack.back();
    stack.pop_back();
    uchar* row = mask.ptr<uchar>(p.y);
    if (row[p.x] != 0) continue;  // Marked since it was seeded.
    int left = p.x, right = p.x;
    while (left > 0 && row[left - 1] == 0) --left;
    while (right + 1 < width && row[right + 1] == 0) ++right;
    std::memset(row + left, outside, static_cast<size_t>(right - left + 1));
    if (p.y > 0) seed_runs(p.y - 1, left, right);
    if (p.y + 1 < height) seed_runs(p.y + 1, left, right);
  }
}

void MarkOutsideReference(cv::Mat& mask, uchar outside) {
  CV_Assert(mask.type() == CV_8UC1 && outside != 0);
  cv::Mat padded;
  cv::copyMakeBorder(mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::floodFill(padded, cv::Point(0, 0), cv::Scalar(outside), nullptr, cv::Scalar(), cv::Scalar(),
                4);
  padded(cv::Rect(1, 1, mask.cols, mask.rows)).copyTo(mask);
}

cv::Rect NonZeroBounds(const cv::Mat& mask) {
  CV_Assert(mask.type() == CV_8UC1);
  int top = -1, bottom = -1, left = mask.cols, right = -1;
  for (int y = 0; y < mask.rows; ++y) {
    const uchar* row = mask.ptr<uchar>(y);
    int x = 0;
    // First nonzero column of the row, then the last one (only beyond the extent known so far).
#if CV_SIMD128
    // The first nonzero of the first chunk with one: the lowest bit of its sign mask.
    for (; x + 16 <= mask.cols; x += 16) {
      const int lit = cv::v_signmask(cv::v_load(row + x) != cv::v_setzero_u8());
      if (lit) {
        x += __builtin_ctz(static_cast<unsigned>(lit));
        break;
      }
    }
#endif
    while (x < mask.cols && !row[x]) ++x;
    if (x == mask.cols) continue;
    left = std::min(left, x);
    if (top < 0) top = y;
    bottom = y;
    int last = mask.cols - 1;
#if CV_SIMD128
    while (last - 15 > right && last - 15 >= x &&
           !cv::v_check_any(cv::v_load(row + last - 15) != cv::v_setzero_u8())) {
      last -= 16;
    }
#endif
    while (last > right && !row[last]) --last;
    right = std::max(right, last);
  }
  if (top < 0) return cv::Rect();
  return cv::Rect(left, top, right - left + 1, bottom - top + 1);
}

void NonZeroPoints(const cv::Mat& mask, std::vector<cv::Point>& points) {
  CV_Assert(mask.type() == CV_8UC1);
  points.clear();
  for (int y = 0; y < mask.rows; ++y) {
    const uchar* row = mask.ptr<uchar>(y);
    int x = 0;
#if CV_SIMD128
    for (; x + 16 <= mask.cols; x += 16) {
      const int bits = cv::v_signmask(cv::v_load(row + x) != cv::v_setzero_u8());
      for (int rest = bits; rest != 0; rest &= rest - 1) {
        points.emplace_back(x + __builtin_ctz(static_cast<unsigned>(rest)), y);
      }
    }
#endif
    for (; x < mask.cols; ++x) {
      if (row[x]) points.emplace_back(x, y);
    }
  }
}

int RunLabeller::Find(int i) {
  while (parent_[static_cast<size_t>(i)] != i) {
    parent_[static_cast<size_t>(i)] = parent_[static_cast<size_t>(parent_[static_cast<size_t>(i)])];
    i = parent_[static_cast<size_t>(i)];
  }
  return i;
}

void RunLabeller::Label(const cv::Mat& mask) {
  CV_Assert(mask.type() == CV_8UC1);
  runs_.clear();
  parent_.clear();
  components_.clear();
  const int w = mask.cols;
  size_t prev_begin = 0, prev_end = 0;
  for (int y = 0; y < mask.rows; ++y) {
    const uchar* row = mask.ptr<uchar>(y);
    const size_t begin = runs_.size();
    // Each run's start (the next nonzero pixel) and end (the next 0 after it), found 16 pixels
    // at a time: the first such pixel of a chunk is the lowest bit of its comparison's sign
    // mask. Pixel by pixel inside the runs, the scan was a third of the labelling on the
    // tracker's windows, whose masks are mostly runs (issue 45).
    int x = 0;
    while (x < w) {
#if CV_SIMD128
      for (; x + 16 <= w; x += 16) {
        const int lit = cv::v_signmask(cv::v_load(row + x) != cv::v_setzero_u8());
        if (lit) {
          x += __builtin_ctz(static_cast<unsigned>(lit));
          break;
        }
      }
#endif
      while (x < w && !row[x]) ++x;
      if (x >= w) break;
      const int start = x;
#if CV_SIMD128
      for (; x + 16 <= w; x += 16) {
        const int dark = cv::v_signmask(cv::v_load(row + x) == cv::v_setzero_u8());
        if (dark) {
          x += __builtin_ctz(static_cast<unsigned>(dark));
          break;
        }
      }
#endif
      while (x < w && row[x]) ++x;
      runs_.push_back({y, start, x});
    }
    // Union with the runs of the row above that touch (8-connected: columns overlap or meet
    // diagonally). Both lists are sorted by x0.
    size_t p = prev_begin;
    for (size_t r = begin; r < runs_.size(); ++r) {
      parent_.push_back(static_cast<int>(r));
      const Run& run = runs_[r];
      while (p < prev_end && runs_[p].x1 < run.x0) ++p;  // Ends before the diagonal.
      for (size_t q = p; q < prev_end && runs_[q].x0 <= run.x1; ++q) {
        const int a = Find(static_cast<int>(r)), b = Find(static_cast<int>(q));
        if (a != b) parent_[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
      }
    }
    prev_begin = begin;
    prev_end = runs_.size();
  }
  // Components in order of their first run (= raster order of their first pixel): roots are the
  // smallest run index of their set.
  const size_t n = runs_.size();
  run_component_.assign(n, -1);
  for (size_t r = 0; r < n; ++r) {
    const int root = Find(static_cast<int>(r));
    if (root == static_cast<int>(r)) {
      run_component_[r] = static_cast<int>(components_.size());
      components_.emplace_back();
    } else {
      run_component_[r] = run_component_[static_cast<size_t>(root)];
    }
  }
  // Boxes first (moments are taken relative to them), then runs grouped by component.
  count_.assign(components_.size(), 0);
  for (size_t r = 0; r < n; ++r) {
    const Run& run = runs_[r];
    const size_t c = static_cast<size_t>(run_component_[r]);
    Component& comp = components_[c];
    const cv::Rect rect(run.x0, run.y, run.x1 - run.x0, 1);
    comp.box = count_[c] == 0 ? rect : (comp.box | rect);
    ++count_[c];
  }
  int offset = 0;
  for (size_t c = 0; c < components_.size(); ++c) {
    components_[c].first_run = offset;
    components_[c].run_count = 0;
    offset += count_[c];
  }
  sorted_.resize(n);
  for (size_t r = 0; r < n; ++r) {
    const Run& run = runs_[r];
    Component& comp = components_[static_cast<size_t>(run_component_[r])];
    sorted_[static_cast<size_t>(comp.first_run + comp.run_count++)] = run;
    // Sums over x in [a, b) and their squares, exact in 64 bits.
    const int64_t a = run.x0 - comp.box.x, b = run.x1 - comp.box.x, len = b - a;
    const int64_t yy = run.y - comp.box.y;
    auto sum_sq = [](int64_t k) { return k * (k + 1) * (2 * k + 1) / 6; };  // 0^2 + .. + k^2
    comp.area += static_cast<int>(len);
    comp.m10 += (a + b - 1) * len / 2;
    comp.m20 += sum_sq(b - 1) - (a > 0 ? sum_sq(a - 1) : 0);
    comp.m01 += yy * len;
    comp.m02 += yy * yy * len;
  }
}

void RunLabeller::Draw(int i, cv::Mat& out, cv::Point origin) const {
  const Component& comp = components_[static_cast<size_t>(i)];
  for (int k = 0; k < comp.run_count; ++k) {
    const Run& run = sorted_[static_cast<size_t>(comp.first_run + k)];
    const int y = run.y - origin.y;
    if (y < 0 || y >= out.rows) continue;
    const int x0 = std::max(0, run.x0 - origin.x), x1 = std::min(out.cols, run.x1 - origin.x);
    if (x1 > x0) std::memset(out.ptr<uchar>(y) + x0, 255, static_cast<size_t>(x1 - x0));
  }
}

std::vector<RunLabeller::Component> LabelReference(const cv::Mat& mask) {
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::vector<RunLabeller::Component> out(static_cast<size_t>(std::max(0, count - 1)));
  for (int i = 1; i < count; ++i) {
    RunLabeller::Component& c = out[static_cast<size_t>(i - 1)];
    const int* s = stats.ptr<int>(i);
    c.box = cv::Rect(s[cv::CC_STAT_LEFT], s[cv::CC_STAT_TOP], s[cv::CC_STAT_WIDTH],
                     s[cv::CC_STAT_HEIGHT]);
    c.area = s[cv::CC_STAT_AREA];
    for (int y = 0; y < c.box.height; ++y) {
      const int* l = labels.ptr<int>(c.box.y + y) + c.box.x;
      for (int x = 0; x < c.box.width; ++x) {
        if (l[x] != i) continue;
        c.m10 += x;
        c.m01 += y;
        c.m20 += static_cast<int64_t>(x) * x;
        c.m02 += static_cast<int64_t>(y) * y;
      }
    }
  }
  return out;
}

void EdgeZonesReference(const cv::Mat& own, cv::Mat& zones) {
  CV_Assert(own.type() == CV_8UC1 && zones.type() == CV_8UC1 && zones.size() == own.size());
  const int w = own.cols, h = own.rows;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool blob = own.at<uchar>(y, x) == 255;
      bool near = false, reach = false;
      for (int dy = -4; dy <= 4; ++dy) {
        for (int dx = -4; dx <= 4; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          if ((own.at<uchar>(qy, qx) == 255) == blob) continue;  // Same kind.
          const int big = std::max(std::abs(dx), std::abs(dy));
          const int small = std::min(std::abs(dx), std::abs(dy));
          const int d = 3 * big + small;
          near = near || d <= 6;
          reach = reach || d <= 12;
        }
      }
      zones.at<uchar>(y, x) = near ? kZoneNear : reach && !blob ? kZoneReach : kZoneFar;
    }
  }
}

void EdgeZones(const cv::Mat& own, cv::Mat& zones, cv::Mat& scratch) {
  CV_Assert(own.type() == CV_8UC1 && zones.type() == CV_8UC1 && zones.size() == own.size());
  const int w = own.cols, h = own.rows;
  if (w == 0 || h == 0) return;
#if CV_SIMD128
  using namespace cv;
  // Planes of the mask padded by kPad zero pixels all round (outside the mask nothing counts):
  // `a` the blob (255), `b` the rest; a1..a4 the maximum of `a` over a row's x +- 1..4, b1, b2 of
  // `b` over x +- 1, 2. Rows of the padded width rounded up to 16 plus 16 bytes of slack, so a
  // chunk of 16 reading 4 columns either side stays inside its row.
  constexpr int kPad = 4;
  const int chunks = (w + 15) / 16;
  const int stride = 16 * chunks + 2 * kPad + 16;
  const int rows = h + 2 * kPad;
  constexpr int kPlanes = 8;
  const size_t plane = static_cast<size_t>(stride) * rows;
  const size_t bytes = plane * kPlanes;
  if (scratch.empty() || scratch.total() * scratch.elemSize() < bytes) {
    scratch.create(1, static_cast<int>(bytes), CV_8U);
  }
  uchar* base = scratch.data;
  uchar* a = base;
  uchar* b = base + plane;
  uchar* a1 = base + 2 * plane;
  uchar* a2 = base + 3 * plane;
  uchar* a3 = base + 4 * plane;
  uchar* a4 = base + 5 * plane;
  uchar* b1 = base + 6 * plane;
  uchar* b2 = base + 7 * plane;
  std::memset(a, 0, 2 * plane);
  const v_uint8x16 k255 = v_setall_u8(255);
  for (int y = 0; y < h; ++y) {
    const uchar* in = own.ptr<uchar>(y);
    uchar* ar = a + static_cast<size_t>(y + kPad) * stride + kPad;
    uchar* br = b + static_cast<size_t>(y + kPad) * stride + kPad;
    int x = 0;
    const auto sixteen = [&](int x) {
      const v_uint8x16 blob = v_load(in + x) == k255;
      v_store(ar + x, blob);
      v_store(br + x, ~blob);
    };
    for (; x + 16 <= w; x += 16) sixteen(x);
    // The row's rest as its last 16 pixels again (the same values where they overlap).
    if (x < w && w >= 16) {
      sixteen(w - 16);
      x = w;
    }
    for (; x < w; ++x) {
      ar[x] = in[x] == 255 ? 255 : 0;
      br[x] = in[x] == 255 ? 0 : 255;
    }
  }
  // Row maxima (every row: the padding rows give 0).
  for (int r = 0; r < rows; ++r) {
    const size_t o = static_cast<size_t>(r) * stride + kPad;
    for (int c = 0; c < chunks; ++c) {
      const size_t i = o + 16 * c;
      const v_uint8x16 m1 = v_load(a + i - 1) | v_load(a + i) | v_load(a + i + 1);
      const v_uint8x16 m2 = m1 | v_load(a + i - 2) | v_load(a + i + 2);
      const v_uint8x16 m3 = m2 | v_load(a + i - 3) | v_load(a + i + 3);
      const v_uint8x16 m4 = m3 | v_load(a + i - 4) | v_load(a + i + 4);
      v_store(a1 + i, m1);
      v_store(a2 + i, m2);
      v_store(a3 + i, m3);
      v_store(a4 + i, m4);
      const v_uint8x16 n1 = v_load(b + i - 1) | v_load(b + i) | v_load(b + i + 1);
      v_store(b1 + i, n1);
      v_store(b2 + i, n1 | v_load(b + i - 2) | v_load(b + i + 2));
    }
  }
  const v_uint8x16 near_v = v_setall_u8(kZoneNear), reach_v = v_setall_u8(kZoneReach),
                   far_v = v_setall_u8(kZoneFar);
  const ptrdiff_t s = stride;
  for (int y = 0; y < h; ++y) {
    uchar* out = zones.ptr<uchar>(y);
    const size_t o = static_cast<size_t>(y + kPad) * stride + kPad;
    for (int c = 0; c < chunks; ++c) {
      const size_t i = o + 16 * c;
      // Within 6 of a pixel of the kind: the 3x3 square, and two along the row or the column.
      const v_uint8x16 a6 = v_load(a1 + i - s) | v_load(a1 + i) | v_load(a1 + i + s) |
                            v_load(a2 + i) | v_load(a + i - 2 * s) | v_load(a + i + 2 * s);
      const v_uint8x16 b6 = v_load(b1 + i - s) | v_load(b1 + i) | v_load(b1 + i + s) |
                            v_load(b2 + i) | v_load(b + i - 2 * s) | v_load(b + i + 2 * s);
      // Within 12 of the blob: the 7x7 square, and four along the row or the column.
      const v_uint8x16 a12 = v_load(a3 + i - 3 * s) | v_load(a3 + i - 2 * s) |
                             v_load(a3 + i - s) | v_load(a3 + i) | v_load(a3 + i + s) |
                             v_load(a3 + i + 2 * s) | v_load(a3 + i + 3 * s) | v_load(a4 + i) |
                             v_load(a + i - 4 * s) | v_load(a + i + 4 * s);
      const v_uint8x16 blob = v_load(a + i);
      const v_uint8x16 near = v_select(blob, b6, a6);
      const v_uint8x16 zone = v_select(near, near_v, v_select(a12 & ~blob, reach_v, far_v));
      if (16 * c + 16 <= w) {
        v_store(out + 16 * c, zone);
      } else {
        uchar last[16];
        v_store(last, zone);
        std::memcpy(out + 16 * c, last, static_cast<size_t>(w - 16 * c));
      }
    }
  }
#else
  (void)scratch;
  EdgeZonesReference(own, zones);
#endif
}

}  // namespace softsight
