#include "track/template_parts.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

// ProjectLevels' byte shuffle for gray runs: a function compiled for SSSE3 by its target
// attribute, called only where the processor reports it (GCC and Clang on x86-64).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && CV_SIMD128
#define SOFTSIGHT_SSSE3_GRAY 1
#include <immintrin.h>
#else
#define SOFTSIGHT_SSSE3_GRAY 0
#endif

namespace softsight::template_internal {

std::string RectText(const cv::Rect& r) {
  return cv::format("[%d, %d, %d, %d]", r.x, r.y, r.width, r.height);
}

cv::Point2d HalfSize(const cv::Size& size) {
  return {(size.width - 1) / 2.0, (size.height - 1) / 2.0};
}

double PeakOffset(double l, double c, double r, bool v_shaped) {
  if (!std::isfinite(l) || !std::isfinite(r)) return 0.0;
  double d = 0.0;
  if (v_shaped) {
    const double slope = c - std::min(l, r);
    if (slope > 0) d = (r - l) / (2.0 * slope);
  } else {
    const double curvature = 2.0 * c - l - r;
    if (curvature > 0) d = (r - l) / (2.0 * curvature);
  }
  return std::clamp(d, -0.5, 0.5);
}

cv::Point2d SubPixel(const cv::Mat& sim, cv::Point best, bool v_shaped) {
  cv::Point2d offset(0, 0);
  const float* row = sim.ptr<float>(best.y);
  if (best.x > 0 && best.x < sim.cols - 1) {
    offset.x = PeakOffset(row[best.x - 1], row[best.x], row[best.x + 1], v_shaped);
  }
  if (best.y > 0 && best.y < sim.rows - 1) {
    offset.y = PeakOffset(sim.at<float>(best.y - 1, best.x), row[best.x],
                          sim.at<float>(best.y + 1, best.x), v_shaped);
  }
  return offset;
}

bool BestIn(const cv::Mat& sim, cv::Point* at) {
  float best = -std::numeric_limits<float>::infinity();
  bool any = false;
  for (int y = 0; y < sim.rows; ++y) {
    const float* s = sim.ptr<float>(y);
    for (int x = 0; x < sim.cols; ++x) {
      if (s[x] > best || (!any && !std::isnan(s[x]))) {
        best = s[x];
        *at = {x, y};
        any = true;
      }
    }
  }
  return any;
}

bool RivalIn(const cv::Mat& sim, cv::Point best, int radius, cv::Point* at) {
  float top = -std::numeric_limits<float>::infinity();
  bool any = false;
  for (int y = 0; y < sim.rows; ++y) {
    const float* s = sim.ptr<float>(y);
    for (int x = 0; x < sim.cols; ++x) {
      if (std::abs(x - best.x) <= radius && std::abs(y - best.y) <= radius) continue;
      const float v = s[x];
      if (std::isnan(v) || (any && v <= top)) continue;
      bool peak = true;
      for (int dy = -1; dy <= 1 && peak; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int yy = y + dy, xx = x + dx;
          if ((dx == 0 && dy == 0) || yy < 0 || xx < 0 || yy >= sim.rows || xx >= sim.cols) continue;
          if (sim.at<float>(yy, xx) > v) {
            peak = false;
            break;
          }
        }
      }
      if (!peak) continue;
      top = v;
      *at = {x, y};
      any = true;
    }
  }
  return any;
}

int RivalRadius(const cv::Size& templ) {
  return std::max(2, std::min(templ.width, templ.height) / 2);
}

bool NoRivalReachable(int margin_px, cv::Point from_prediction, int rival_radius) {
  return margin_px + std::abs(from_prediction.x) <= rival_radius &&
         margin_px + std::abs(from_prediction.y) <= rival_radius;
}

cv::Mat RoundMask(const cv::Size& size) {
  cv::Mat mask(size, CV_8UC1);
  const cv::Point2d centre = HalfSize(size);
  const double rx = size.width / 2.0, ry = size.height / 2.0;
  for (int i = 0; i < size.height; ++i) {
    for (int j = 0; j < size.width; ++j) {
      const double u = (j - centre.x) / rx, v = (i - centre.y) / ry;
      mask.at<uint8_t>(i, j) = u * u + v * v <= 1.0 ? 255 : 0;
    }
  }
  return mask;
}

double ZnccAt(const cv::Mat& image, cv::Point top_left, const PreparedTemplate& templ,
              cv::Mat& result, ZnccScratch& scratch) {
  float one = 0;
  if (MatchZnccAt(image, top_left, templ, &one)) return one;  // Gray: the one placement alone.
  MatchZncc(image(cv::Rect(top_left, templ.size())), templ, result, scratch);
  return result.at<float>(0, 0);  // NaN on a flat window: fails every comparison.
}

cv::Point2d SymmetryCentre(const cv::Mat& templ, double* strength) {
  *strength = 0.0;
  const cv::Point2d geometric = HalfSize(templ.size());
  const int m = std::min({3, (templ.cols - 3) / 2, (templ.rows - 3) / 2});
  if (m < 1) return geometric;
  const cv::Rect inner_rect(m, m, templ.cols - 2 * m, templ.rows - 2 * m);
  cv::Point2d c = geometric;
  cv::Mat turned, zncc;
  ZnccScratch scratch;
  PreparedTemplate inner;
  for (int iteration = 0; iteration < 3; ++iteration) {
    const cv::Matx23d turn(-1, 0, 2 * c.x, 0, -1, 2 * c.y);  // Its own inverse.
    cv::warpAffine(templ, turned, turn, templ.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    if (!inner.Prepare(turned(inner_rect))) return geometric;
    MatchZncc(templ, inner, zncc, scratch);
    cv::Point best;
    if (!BestIn(zncc, &best)) return geometric;
    *strength = zncc.at<float>(best);
    const cv::Point2d shift = cv::Point2d(best.x - m, best.y - m) + SubPixel(zncc, best, false);
    c += 0.5 * shift;
    if (std::abs(c.x - geometric.x) > m || std::abs(c.y - geometric.y) > m) return geometric;
    if (cv::norm(shift) < 1e-3) break;
  }
  return c;
}

cv::Point2d MarkerSymmetryCentre(const cv::Mat& templ, const cv::Point2d& blob_centre,
                                 double blob_area, double* strength) {
  const double reach = std::sqrt(std::max(blob_area, 0.0) / CV_PI) + 2.0;
  const cv::Rect around =
      cv::Rect(cv::Point(cvRound(blob_centre.x - reach), cvRound(blob_centre.y - reach)),
               cv::Point(cvRound(blob_centre.x + reach) + 1, cvRound(blob_centre.y + reach) + 1)) &
      cv::Rect(0, 0, templ.cols, templ.rows);
  if (around.width < 7 || around.height < 7) return SymmetryCentre(templ, strength);
  return SymmetryCentre(templ(around), strength) + cv::Point2d(around.tl());
}

void CappedChebyshevDistance(const cv::Mat& label, const cv::Rect& area, cv::Mat& dist,
                             std::vector<uint8_t>& row_distance) {
  CV_Assert(label.type() == CV_8UC1 && dist.type() == CV_8UC1 && dist.size() == label.size());
  if (area.empty()) return;
  CV_Assert((area & cv::Rect(0, 0, label.cols, label.rows)) == area);
  constexpr int kReach = 4, kNone = kReach + 1;
  // The rows within reach of the area, and per row the distance from each of the area's columns
  // to the row's nearest label pixel within reach (kNone: none).
  const int top = std::max(0, area.y - kReach), bottom = std::min(label.rows, area.br().y + kReach);
  const int width = area.width;
#if CV_SIMD128
  // Each row's distances 16 columns at a time: the nearest label pixel within reach along the
  // row is at k when one of the pixels k to the left or right is one and none nearer is, so the
  // distance is kNone, then k for k = 4 .. 0 wherever that pair holds one (as the two passes
  // below find it, bit for bit). Rows are read from a copy padded with kReach zeros and more
  // (outside the label's row: no label pixel, as the passes do not look there); the distances'
  // rows are `stride` long, a multiple of 16, so the last vector stays in the buffer.
  const int stride = (width + 15) / 16 * 16;
  const size_t distances = static_cast<size_t>((bottom - top) * stride);
  row_distance.resize(distances + static_cast<size_t>(stride + 2 * kReach));
  uint8_t* const padded = row_distance.data() + distances;
  const int from = area.x - kReach;  // The label column of padded[0].
  const int copy_begin = std::max(0, from), copy_end = std::min(label.cols, from + stride + 2 * kReach);
  std::fill(padded, padded + stride + 2 * kReach, uint8_t{0});
  const cv::v_uint8x16 zero = cv::v_setzero_u8();
  for (int y = top; y < bottom; ++y) {
    const uint8_t* row = label.ptr<uint8_t>(y);
    std::copy(row + copy_begin, row + copy_end, padded + (copy_begin - from));
    uint8_t* out = row_distance.data() + static_cast<size_t>((y - top) * stride);
    for (int x = 0; x < width; x += 16) {
      const uint8_t* at = padded + x + kReach;  // Column area.x + x.
      cv::v_uint8x16 d = cv::v_setall_u8(static_cast<uint8_t>(kNone));
      for (int k = kReach; k >= 1; --k) {
        const cv::v_uint8x16 pair = cv::v_load(at - k) | cv::v_load(at + k);
        d = cv::v_select(pair != zero, cv::v_setall_u8(static_cast<uint8_t>(k)), d);
      }
      d = cv::v_select(cv::v_load(at) != zero, zero, d);
      cv::v_store(out + x, d);
    }
  }
#else
  const int stride = width;
  row_distance.resize(static_cast<size_t>((bottom - top) * width));
  for (int y = top; y < bottom; ++y) {
    const uint8_t* row = label.ptr<uint8_t>(y);
    uint8_t* out = row_distance.data() + static_cast<size_t>((y - top) * width);
    // Left to right, from reach before the area: the distance back to the last label pixel.
    int since = kNone;
    for (int x = std::max(0, area.x - kReach); x < area.br().x; ++x) {
      since = row[x] ? 0 : std::min(since + 1, kNone);
      if (x >= area.x) out[x - area.x] = static_cast<uint8_t>(since);
    }
    // Right to left, from reach after the area: the nearer of that and the next label pixel.
    since = kNone;
    for (int x = std::min(label.cols, area.br().x + kReach) - 1; x >= area.x; --x) {
      since = row[x] ? 0 : std::min(since + 1, kNone);
      if (x < area.br().x) {
        uint8_t& d = out[x - area.x];
        d = static_cast<uint8_t>(std::min<int>(d, since));
      }
    }
  }
#endif
  // Down the columns, a row at a time across the area: the least over the rows within reach of
  // max(their distance along the row, |dy|).
#if CV_SIMD128
  // In whole vectors of the rows' stride, into the padded row's buffer (no longer needed), then
  // the area's width of it into `dist`: a loop over the width alone left the last width % 16
  // columns to scalar code, most of this function's work at the blobs' widths (issue 45).
  // The rows k above and below taken together: max(min(a, b), k) is min(max(a, k), max(b, k)),
  // so the least over both of max(distance, k) is one max a pair of rows, with k a constant
  // (issue 45: a row's |dy| was made into a vector for every row and chunk). A row beyond the
  // area's reach has no label pixel within reach: kNone, which changes no minimum.
  const size_t none_row = row_distance.size();
  row_distance.resize(none_row + static_cast<size_t>(stride), static_cast<uint8_t>(kNone));
  std::fill(row_distance.begin() + static_cast<std::ptrdiff_t>(none_row), row_distance.end(),
            static_cast<uint8_t>(kNone));
  uint8_t* const scratch_row = row_distance.data() + distances;  // The padded row, no longer needed.
  const auto row_at = [&](int yy) -> const uint8_t* {
    return row_distance.data() +
           (yy >= top && yy < bottom ? static_cast<size_t>((yy - top) * stride) : none_row);
  };
  const cv::v_uint8x16 reach[kReach + 1] = {
      cv::v_setall_u8(0), cv::v_setall_u8(1), cv::v_setall_u8(2), cv::v_setall_u8(3),
      cv::v_setall_u8(4)};
  for (int y = area.y; y < area.br().y; ++y) {
    const uint8_t* rows_at[2 * kReach + 1];
    for (int k = -kReach; k <= kReach; ++k) rows_at[k + kReach] = row_at(y + k);
    for (int x = 0; x < width; x += 16) {
      cv::v_uint8x16 d = cv::v_load(rows_at[kReach] + x);  // Its own row: k = 0.
      for (int k = 1; k <= kReach; ++k) {
        const cv::v_uint8x16 pair =
            cv::v_min(cv::v_load(rows_at[kReach - k] + x), cv::v_load(rows_at[kReach + k] + x));
        d = cv::v_min(d, cv::v_max(pair, reach[k]));
      }
      cv::v_store(scratch_row + x, d);
    }
    std::memcpy(dist.ptr<uint8_t>(y) + area.x, scratch_row, static_cast<size_t>(width));
  }
#else
  for (int y = area.y; y < area.br().y; ++y) {
    uint8_t* __restrict out = dist.ptr<uint8_t>(y) + area.x;
    std::fill(out, out + width, static_cast<uint8_t>(kNone));
    const int first = std::max(top, y - kReach), last = std::min(bottom - 1, y + kReach);
    for (int yy = first; yy <= last; ++yy) {
      const uint8_t* __restrict along = row_distance.data() + static_cast<size_t>((yy - top) * stride);
      const uint8_t rows_away = static_cast<uint8_t>(std::abs(yy - y));
      for (int x = 0; x < width; ++x) out[x] = std::min(out[x], std::max(along[x], rows_away));
    }
  }
#endif
}

void CappedChebyshevDistanceReference(const cv::Mat& label, const cv::Rect& area, cv::Mat& dist) {
  for (int y = area.y; y < area.br().y; ++y) {
    for (int x = area.x; x < area.br().x; ++x) {
      int best = 5;
      for (int dy = -4; dy <= 4; ++dy) {
        for (int dx = -4; dx <= 4; ++dx) {
          const int yy = y + dy, xx = x + dx;
          if (yy < 0 || xx < 0 || yy >= label.rows || xx >= label.cols) continue;
          if (label.at<uint8_t>(yy, xx)) best = std::min(best, std::max(std::abs(dx), std::abs(dy)));
        }
      }
      dist.at<uint8_t>(y, x) = static_cast<uint8_t>(best);
    }
  }
}

void BlobChannelOf(const cv::Mat& native, const cv::Mat& projection, cv::Mat& out) {
  if (native.channels() == 1) {
    out = native;
  } else if (!projection.empty()) {
    ProjectLevels(native, projection, out);
  } else {
    cv::cvtColor(native, out, cv::COLOR_BGR2GRAY);
  }
}

cv::Mat ContrastProjection(const cv::Mat& bgr) {
  const cv::Mat samples = bgr.clone().reshape(1, static_cast<int>(bgr.total()));
  cv::Mat covariance, mean;
  cv::calcCovarMatrix(samples, covariance, mean,
                      cv::COVAR_NORMAL | cv::COVAR_ROWS | cv::COVAR_SCALE, CV_64F);
  cv::Mat values, vectors;
  cv::eigen(covariance, values, vectors);
  cv::Vec3d axis(vectors.at<double>(0, 0), vectors.at<double>(0, 1), vectors.at<double>(0, 2));
  const double l1 = std::abs(axis[0]) + std::abs(axis[1]) + std::abs(axis[2]);
  if (!(l1 > 0)) return {};
  if (axis[0] + axis[1] + axis[2] < 0) axis = -axis;  // Mostly positive: light stays light.
  axis /= l1;
  double offset = 0;
  for (int c = 0; c < 3; ++c) offset -= 255.0 * std::min(0.0, axis[c]);
  cv::Mat m = (cv::Mat_<float>(1, 4) << axis[0], axis[1], axis[2], offset);
  return m;
}

void LookAlikeZncc(const cv::Mat& image, const PreparedTemplate& templ,
                   const PreparedTemplate* half, double floor, cv::Mat& sim,
                   LookAlikeScratch& scratch, ZnccScratch& zncc) {
  const cv::Size size = templ.size();
  const cv::Size map_size(image.cols - size.width + 1, image.rows - size.height + 1);
  if (half == nullptr) {
    MatchZncc(image, templ, sim, zncc);
    return;
  }
  cv::pyrDown(image, scratch.half_image);
  if (scratch.half_image.cols < half->size().width ||
      scratch.half_image.rows < half->size().height) {
    MatchZncc(image, templ, sim, zncc);
    return;
  }
  MatchZncc(scratch.half_image, *half, scratch.half_sim, zncc);
  // The full-resolution placements to match: blocks around the half-resolution ones that pass.
  scratch.wanted.create(map_size, CV_8UC1);
  scratch.wanted.setTo(0);
  const float pass = static_cast<float>(floor - kLookAlikeSlack);
  int passed = 0;
  for (int y = 0; y < scratch.half_sim.rows; ++y) {
    const float* row = scratch.half_sim.ptr<float>(y);
    for (int x = 0; x < scratch.half_sim.cols; ++x) {
      if (!(row[x] >= pass)) continue;
      ++passed;
      const cv::Rect block(2 * x - kLookAlikeReachPx, 2 * y - kLookAlikeReachPx,
                           2 * kLookAlikeReachPx + 1, 2 * kLookAlikeReachPx + 1);
      scratch.wanted(block & cv::Rect(0, 0, map_size.width, map_size.height)).setTo(1);
    }
  }
  if (passed * 8 > static_cast<int>(scratch.half_sim.total())) {  // Mostly alike: all of it.
    MatchZncc(image, templ, sim, zncc);
    return;
  }
  sim.create(map_size, CV_32F);
  sim.setTo(std::numeric_limits<float>::quiet_NaN());
  // Each band of rows with wanted placements matched as one window over their columns' span
  // (a placement's ZNCC depends on its own pixels only: the values are the whole map's).
  const cv::Mat& wanted = scratch.wanted;
  for (int y = 0; y < map_size.height;) {
    int y_end = y, x_begin = map_size.width, x_end = 0;
    for (; y_end < map_size.height; ++y_end) {
      const uint8_t* r = wanted.ptr<uint8_t>(y_end);
      int first = 0;
      while (first < map_size.width && !r[first]) ++first;
      if (first == map_size.width) break;
      int last = map_size.width - 1;
      while (!r[last]) --last;
      x_begin = std::min(x_begin, first);
      x_end = std::max(x_end, last + 1);
    }
    if (y_end == y) {  // A row without wanted placements.
      ++y;
      continue;
    }
    const cv::Rect placements(x_begin, y, x_end - x_begin, y_end - y);
    const cv::Rect window(placements.x, placements.y, placements.width + size.width - 1,
                          placements.height + size.height - 1);
    MatchZncc(image(window), templ, scratch.part, zncc);
    scratch.part.copyTo(sim(placements));
    y = y_end;
  }
}

BlobRimSums RimLevelSumsReference(const cv::Mat& gray, const cv::Mat& mask, const cv::Mat& dist,
                                  const cv::Mat& label, const cv::Rect& grown) {
  BlobRimSums sums;
  const int cols = label.cols;  // label is continuous.
  for (int y = grown.y; y < grown.br().y; ++y) {
    const uint8_t* levels = gray.ptr<uint8_t>(y);
    const uint8_t* inside = mask.data ? mask.ptr<uint8_t>(y) : nullptr;
    const uint8_t* distance = dist.ptr<uint8_t>(y);
    const uint8_t* in = label.ptr<uint8_t>(y);
    for (int x = grown.x; x < grown.br().x; ++x) {
      const int d = distance[x];
      if (inside && !inside[x]) continue;
      if (d == 0 && in[x - cols] && in[x + cols] && in[x - 1] && in[x + 1]) {
        sums.fg_sum += levels[x];
        ++sums.fg_n;
      } else if (d == 3 || d == 4) {
        sums.bg_sum += levels[x];
        ++sums.bg_n;
      }
    }
  }
  return sums;
}

BlobRimSums RimLevelSums(const cv::Mat& gray, const cv::Mat& mask, const cv::Mat& dist,
                         const cv::Mat& label, const cv::Rect& grown) {
#if CV_SIMD128
  if (!mask.empty() || grown.width < 18) return RimLevelSumsReference(gray, mask, dist, label, grown);
  // The patch's first and last rows and columns a pixel at a time (their neighbours' reads
  // would leave the patch; none of them is a component pixel, see above), the rest 16 pixels
  // at a time: the counts and sums of whole levels in integer lanes, exact.
  const int cols = label.cols;
  const int x0 = std::max(grown.x, 1), x1 = std::min(grown.br().x, gray.cols - 1);
  BlobRimSums sums;
  const auto scalar = [&](int y, int from, int to) {
    const BlobRimSums part =
        RimLevelSumsReference(gray, mask, dist, label, cv::Rect(from, y, to - from, 1));
    sums.fg_sum += part.fg_sum;
    sums.fg_n += part.fg_n;
    sums.bg_sum += part.bg_sum;
    sums.bg_n += part.bg_n;
  };
  const cv::v_uint8x16 zero = cv::v_setzero_u8(), three = cv::v_setall_u8(3),
                       four = cv::v_setall_u8(4), one = cv::v_setall_u8(1);
  unsigned fg_sum = 0, bg_sum = 0, fg_n = 0, bg_n = 0;  // Exact: at most 255 a pixel.
  for (int y = grown.y; y < grown.br().y; ++y) {
    if (y == 0 || y == gray.rows - 1 || x1 - x0 < 16) {
      scalar(y, grown.x, grown.br().x);
      continue;
    }
    if (grown.x < x0) scalar(y, grown.x, x0);
    if (x1 < grown.br().x) scalar(y, x1, grown.br().x);
    const uint8_t* levels = gray.ptr<uint8_t>(y);
    const uint8_t* distance = dist.ptr<uint8_t>(y);
    const uint8_t* in = label.ptr<uint8_t>(y);
    // The last 16 pixels start where the ones before them ended (no pixel counted twice).
    for (int x = x0; x < x1;) {
      const int at = std::min(x, x1 - 16);
      const cv::v_uint8x16 d = cv::v_load(distance + at);
      cv::v_uint8x16 fg = (d == zero) & (cv::v_load(in + at - cols) != zero) &
                          (cv::v_load(in + at + cols) != zero) &
                          (cv::v_load(in + at - 1) != zero) & (cv::v_load(in + at + 1) != zero);
      cv::v_uint8x16 bg = (d == three) | (d == four);
      if (at < x) {  // The overlap: drop the lanes already counted.
        alignas(16) uint8_t fresh[16];
        for (int k = 0; k < 16; ++k) fresh[k] = at + k >= x ? 0xFF : 0;
        const cv::v_uint8x16 keep = cv::v_load_aligned(fresh);
        fg &= keep;
        bg &= keep;
      }
      const cv::v_uint8x16 v = cv::v_load(levels + at);
      // Sums of 16 levels (psadbw against zero) and of the lanes' ones.
      fg_sum += cv::v_reduce_sad(v & fg, zero);
      bg_sum += cv::v_reduce_sad(v & bg, zero);
      fg_n += cv::v_reduce_sad(one & fg, zero);
      bg_n += cv::v_reduce_sad(one & bg, zero);
      x = at + 16;
    }
  }
  sums.fg_sum += fg_sum;
  sums.bg_sum += bg_sum;
  sums.fg_n += static_cast<int>(fg_n);
  sums.bg_n += static_cast<int>(bg_n);
  return sums;
#else
  return RimLevelSumsReference(gray, mask, dist, label, grown);
#endif
}

SoftCentroidSums SoftCentroidReference(const cv::Mat& gray, const cv::Mat& mask,
                                       const cv::Mat& dist, const cv::Rect& grown, double bg,
                                       double fg) {
  SoftCentroidSums sums;
  for (int y = grown.y; y < grown.br().y; ++y) {
    const uint8_t* levels = gray.ptr<uint8_t>(y);
    const uint8_t* inside = mask.data ? mask.ptr<uint8_t>(y) : nullptr;
    const uint8_t* distance = dist.ptr<uint8_t>(y);
    for (int x = grown.x; x < grown.br().x; ++x) {
      if ((inside && !inside[x]) || distance[x] > 2) continue;
      const double w = track_internal::Membership(levels + x, 1, &bg, &fg, 0.0, false);
      sums.w += w;
      sums.x += w * x;
      sums.y += w * y;
    }
  }
  return sums;
}

namespace {
#if CV_SIMD128_64F
// The soft centroid's sums over `grown`, 16 pixels at a time: `weigh(v16, c16, at, rw, rx)` adds
// the weights of the chunk of levels starting at column `at` (`v16`, widened to 16 bits, its two
// halves) of the pixels `c16` marks (all ones: within the soft band, and not yet added, for the
// last chunk of a row overlaps the one before it) to the row's sums of w and w * x, in the
// order of x.
template <typename WeighChunk>
SoftCentroidSums SumChunks(const cv::Mat& gray, const cv::Mat& dist, const cv::Rect& grown,
                           WeighChunk weigh) {
  const cv::v_float64x2 zero = cv::v_setzero_f64();
  const cv::v_uint8x16 near = cv::v_setall_u8(2);
  cv::v_float64x2 sw = zero, sx = zero, sy = zero;
  alignas(16) uint8_t fresh[16];
  for (int y = grown.y; y < grown.br().y; ++y) {
    const uint8_t* levels = gray.ptr<uint8_t>(y);
    const uint8_t* distance = dist.ptr<uint8_t>(y);
    const cv::v_float64x2 vy = cv::v_setall_f64(static_cast<double>(y));
    cv::v_float64x2 rw = zero, rx = zero;  // The row's sums of w and w * x.
    for (int x = grown.x; x < grown.br().x;) {
      const int at = std::min(x, grown.br().x - 16);  // The last 16 overlap: lanes dropped.
      cv::v_uint8x16 counted = cv::v_load(distance + at) <= near;
      if (at < x) {
        for (int k = 0; k < 16; ++k) fresh[k] = at + k >= x ? 0xFF : 0;
        counted &= cv::v_load_aligned(fresh);
      }
      cv::v_uint16x8 v16[2], c16[2];
      cv::v_expand(cv::v_load(levels + at), v16[0], v16[1]);
      cv::v_expand(counted, c16[0], c16[1]);
      weigh(v16, c16, at, rw, rx);
      x = at + 16;
    }
    sw += rw;
    sx += rx;
    sy += rw * vy;
  }
  SoftCentroidSums sums;
  sums.w = cv::v_reduce_sum(sw);
  sums.x = cv::v_reduce_sum(sx);
  sums.y = cv::v_reduce_sum(sy);
  return sums;
}
#endif

SoftCentroidSums SoftCentroidLanes(const cv::Mat& gray, const cv::Mat& mask, const cv::Mat& dist,
                                   const cv::Rect& grown, double bg, double fg, bool table_ok) {
#if CV_SIMD128_64F
  const double d = fg - bg, den = d * d;
  // Membership with one channel and no deadband: clamp((v - bg) * d / den, 0, 1), 0 when the
  // levels are too alike (then every weight is 0).
  if (!mask.empty() || grown.width < 16 || !(den > 1.0)) {
    return SoftCentroidReference(gray, mask, dist, grown, bg, fg);
  }
  const cv::v_float64x2 vbg = cv::v_setall_f64(bg), vd = cv::v_setall_f64(d);
  const cv::v_float64x2 vden = cv::v_setall_f64(den), zero = cv::v_setzero_f64();
  const cv::v_float64x2 unit = cv::v_setall_f64(1.0);
  // The weight is a function of the level alone: on the large blobs (the whole 16-pixel chunks of
  // the box, overlaps counted, cover at least two tables), each level's weight is computed once,
  // by the same operations, into a table (the uncounted pixels' 0 in its second half), and the
  // pixels' weights are read from it: no division a pixel (issue 45: the soft centroid was a
  // twentieth of a frame's time on ViSP's mire-2). The same weights, added in the same order.
  const int chunks_per_row = (grown.width + 15) / 16;
  if (table_ok && chunks_per_row * grown.height * 16 >= 2 * 256) {
    alignas(16) double table[512];
    for (int v = 0; v < 256; v += 2) {
      const cv::v_float64x2 level(static_cast<double>(v), static_cast<double>(v + 1));
      cv::v_store(table + v, cv::v_min(cv::v_max(((level - vbg) * vd) / vden, zero), unit));
      cv::v_store(table + 256 + v, zero);
    }
    const cv::v_uint16x8 uncounted_offset = cv::v_setall_u16(256);
    alignas(16) uint16_t index[16];
    return SumChunks(gray, dist, grown,
                     [&](const cv::v_uint16x8 (&v16)[2], const cv::v_uint16x8 (&c16)[2], int at,
                         cv::v_float64x2& rw, cv::v_float64x2& rx) {
                       // Each pixel's table index: its level, in the second half when it is not
                       // counted.
                       for (int h = 0; h < 2; ++h) {
                         cv::v_store_aligned(
                             index + 8 * h,
                             v16[h] + (uncounted_offset & (c16[h] == cv::v_setzero_u16())));
                       }
                       cv::v_float64x2 xs(static_cast<double>(at), static_cast<double>(at + 1));
                       const cv::v_float64x2 two = cv::v_setall_f64(2.0);
                       for (int e = 0; e < 16; e += 2) {
                         const cv::v_float64x2 w(table[index[e]], table[index[e + 1]]);
                         rw += w;
                         rx += w * xs;
                         xs += two;  // Whole numbers: exact.
                       }
                     });
  }
  return SumChunks(gray, dist, grown,
                   [&](const cv::v_uint16x8 (&v16)[2], const cv::v_uint16x8 (&c16)[2], int at,
                       cv::v_float64x2& rw, cv::v_float64x2& rx) {
                     // Uncounted pixels' weights are set to 0 (adding 0 leaves the sums as they
                     // were).
                     for (int h = 0; h < 2; ++h) {
                       cv::v_uint32x4 v32[2], c32[2];
                       cv::v_expand(v16[h], v32[0], v32[1]);
                       cv::v_expand(c16[h], c32[0], c32[1]);
                       for (int q = 0; q < 2; ++q) {
                         const cv::v_int32x4 level = cv::v_reinterpret_as_s32(v32[q]);
                         const cv::v_int32x4 take = cv::v_reinterpret_as_s32(c32[q]);
                         const cv::v_float64x2 halves[2] = {cv::v_cvt_f64(level),
                                                            cv::v_cvt_f64_high(level)};
                         const cv::v_float64x2 keeps[2] = {cv::v_cvt_f64(take),
                                                           cv::v_cvt_f64_high(take)};
                         for (int e = 0; e < 2; ++e) {
                           const int x_first = at + 8 * h + 4 * q + 2 * e;
                           cv::v_float64x2 w =
                               cv::v_min(cv::v_max(((halves[e] - vbg) * vd) / vden, zero), unit);
                           w = cv::v_select(keeps[e] != zero, w, zero);
                           const cv::v_float64x2 xs(static_cast<double>(x_first),
                                                    static_cast<double>(x_first + 1));
                           rw += w;
                           rx += w * xs;
                         }
                       }
                     }
                   });
#else
  return SoftCentroidReference(gray, mask, dist, grown, bg, fg);
#endif
}
}  // namespace

SoftCentroidSums SoftCentroid(const cv::Mat& gray, const cv::Mat& mask, const cv::Mat& dist,
                              const cv::Rect& grown, double bg, double fg) {
  return SoftCentroidLanes(gray, mask, dist, grown, bg, fg, true);
}

SoftCentroidSums SoftCentroidComputed(const cv::Mat& gray, const cv::Mat& mask,
                                      const cv::Mat& dist, const cv::Rect& grown, double bg,
                                      double fg) {
  return SoftCentroidLanes(gray, mask, dist, grown, bg, fg, false);
}

void BlendPatchReference(const cv::Mat& image, const cv::Point2d& centre, double rate,
                         cv::Mat& running, cv::Mat& rounded, cv::Mat& patch) {
  cv::getRectSubPix(image, running.size(), centre, patch, CV_32F);
  cv::addWeighted(running, 1.0 - rate, patch, rate, 0.0, running);
  running.convertTo(rounded, CV_8U);
}

void BlendPatch(const cv::Mat& image, const cv::Point2d& centre, double rate, cv::Mat& running,
                cv::Mat& rounded, cv::Mat& patch) {
  const cv::Size size = running.size();
  // getRectSubPix's placement: its top-left sample at the centre (as a float) less half the
  // size less a half, split into whole pixels and the bilinear fractions.
  const cv::Point2f c(static_cast<float>(centre.x) - (size.width - 1) * 0.5f,
                      static_cast<float>(centre.y) - (size.height - 1) * 0.5f);
  const cv::Point ip(cvFloor(c.x), cvFloor(c.y));
  if (image.type() != CV_8UC1 || running.type() != CV_32FC1 || size.width < 8 || ip.x < 0 ||
      ip.y < 0 || ip.x + size.width + 1 > image.cols || ip.y + size.height + 1 > image.rows) {
    BlendPatchReference(image, centre, rate, running, rounded, patch);
    return;
  }
  const float a = c.x - static_cast<float>(ip.x), b = c.y - static_cast<float>(ip.y);
  const float w00 = (1.f - a) * (1.f - b), w01 = a * (1.f - b), w10 = (1.f - a) * b, w11 = a * b;
  const float keep = static_cast<float>(1.0 - rate), take = static_cast<float>(rate);
  rounded.create(size, CV_8UC1);  // Kept from frame to frame: the same size.
  const auto pixel = [&](const uint8_t* p0, const uint8_t* p1, int x, float* r, uint8_t* o) {
    const float sample = ((p0[x] * w00 + p0[x + 1] * w01) + p1[x] * w10) + p1[x + 1] * w11;
    r[x] = r[x] * keep + sample * take;
    o[x] = cv::saturate_cast<uint8_t>(r[x]);
  };
  for (int y = 0; y < size.height; ++y) {
    const uint8_t* p0 = image.ptr<uint8_t>(ip.y + y) + ip.x;
    const uint8_t* p1 = image.ptr<uint8_t>(ip.y + y + 1) + ip.x;
    float* r = running.ptr<float>(y);
    uint8_t* o = rounded.ptr<uint8_t>(y);
    int x = 0;
#if CV_SIMD128
    const cv::v_float32x4 v00 = cv::v_setall_f32(w00), v01 = cv::v_setall_f32(w01);
    const cv::v_float32x4 v10 = cv::v_setall_f32(w10), v11 = cv::v_setall_f32(w11);
    const cv::v_float32x4 vkeep = cv::v_setall_f32(keep), vtake = cv::v_setall_f32(take);
    // Four levels at `p` as floats. (Through an aligned copy: OpenCV's v_load_expand_q reads the
    // four bytes as one int, which a pointer at any column need not align; the copy compiles to
    // the same single load.)
    const auto floats = [](const uint8_t* p) {
      alignas(4) uint8_t four[4];
      std::memcpy(four, p, sizeof four);
      return cv::v_cvt_f32(cv::v_reinterpret_as_s32(cv::v_load_expand_q(four)));
    };
    // Each running value is read and written once (the tail is scalar: a vector overlapping the
    // last ones would blend them twice).
    for (; x + 8 <= size.width; x += 8) {
      cv::v_int32x4 level[2];
      for (int h = 0; h < 2; ++h) {
        const int k = x + 4 * h;
        const cv::v_float32x4 sample =
            ((floats(p0 + k) * v00 + floats(p0 + k + 1) * v01) + floats(p1 + k) * v10) +
            floats(p1 + k + 1) * v11;
        const cv::v_float32x4 blended = cv::v_load(r + k) * vkeep + sample * vtake;
        cv::v_store(r + k, blended);
        level[h] = cv::v_round(blended);
      }
      cv::v_pack_u_store(o + x, cv::v_pack(level[0], level[1]));
    }
#endif
    for (; x < size.width; ++x) pixel(p0, p1, x, r, o);
  }
}

void ProjectLevelsReference(const cv::Mat& bgr, const cv::Mat& projection, cv::Mat& out) {
  CV_Assert(bgr.type() == CV_8UC3 && projection.type() == CV_32FC1 && projection.total() == 4);
  out.create(bgr.size(), CV_8UC1);
  const float* m = projection.ptr<float>();
  for (int y = 0; y < bgr.rows; ++y) {
    const uint8_t* row = bgr.ptr<uint8_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      const uint8_t* p = row + 3 * x;
      // One IEEE float operation at a time (volatile: no contraction into a fused multiply-add
      // whatever the build targets), the vector lanes' order.
      volatile float acc = m[0] * static_cast<float>(p[0]);
      acc = acc + m[1] * static_cast<float>(p[1]);
      acc = acc + m[2] * static_cast<float>(p[2]);
      acc = acc + m[3];
      o[x] = cv::saturate_cast<uint8_t>(static_cast<float>(acc));
    }
  }
}

#if SOFTSIGHT_SSSE3_GRAY
namespace {
// When the 16 BGR pixels at `p` (48 bytes) are gray, their first bytes into `o` and true: the
// levels of 16 gray pixels when the projection leaves a gray level as it is (a gray recording
// handed over as BGR, with the gray selection's projection of equal weights). The gray test of
// ProjectLevels' gray16 (each byte but every third equals the byte after it) with one-instruction
// byte alignment, then three byte shuffles instead of 16 lookups.
__attribute__((target("ssse3"))) bool GrayFirstOfThree16(const uint8_t* p, uint8_t* o) {
  const __m128i c0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
  const __m128i c1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16));
  const __m128i c2 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 32));
  // Byte i of next_k is byte i + 1 of the 48 (the last one, past them, is ignored).
  const __m128i next0 = _mm_alignr_epi8(c1, c0, 1), next1 = _mm_alignr_epi8(c2, c1, 1);
  const __m128i next2 = _mm_srli_si128(c2, 1);
  const __m128i ignore0 = _mm_setr_epi8(0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0);
  const __m128i ignore1 = _mm_setr_epi8(0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0);
  const __m128i ignore2 = _mm_setr_epi8(-1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1);
  const __m128i same = _mm_and_si128(
      _mm_and_si128(_mm_or_si128(_mm_cmpeq_epi8(c0, next0), ignore0),
                    _mm_or_si128(_mm_cmpeq_epi8(c1, next1), ignore1)),
      _mm_or_si128(_mm_cmpeq_epi8(c2, next2), ignore2));
  if (_mm_movemask_epi8(same) != 0xFFFF) return false;
  const __m128i m0 = _mm_setr_epi8(0, 3, 6, 9, 12, 15, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
  const __m128i m1 = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, 2, 5, 8, 11, 14, -1, -1, -1, -1, -1);
  const __m128i m2 = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 1, 4, 7, 10, 13);
  const __m128i levels = _mm_or_si128(_mm_or_si128(_mm_shuffle_epi8(c0, m0), _mm_shuffle_epi8(c1, m1)),
                                      _mm_shuffle_epi8(c2, m2));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(o), levels);
  return true;
}

// GrayFirstOfThree16 along a whole row (at least 16 pixels; the last 16 overlap the ones before
// them, as MapBgrRows16's), in one call: called once per 16 pixels, the call cost about as much
// as its work (issue 45). False at the first 16 pixels that are not gray, some of the row then
// written: the caller converts the row again the general way, to the same levels.
__attribute__((target("ssse3"))) bool GrayFirstOfThreeRow(const uint8_t* row, uint8_t* o,
                                                          int cols) {
  for (int x = 0; x < cols; x += 16) {
    if (x + 16 > cols) x = cols - 16;
    if (!GrayFirstOfThree16(row + 3 * x, o + x)) return false;
  }
  return true;
}

bool HasSsse3() {
  static const bool has = __builtin_cpu_supports("ssse3");
  return has;
}
}  // namespace
#endif

#if CV_SIMD128
// Each BGR pixel of `bgr` (CV_8UC3, at least 16 wide) -> one level of `out` (CV_8UC1, same size),
// 16 pixels at a time: `four(b, g, r)` turns four pixels' channels, widened to 32 bits, into
// their four levels (v_int32x4), which are packed with saturation (saturate_cast).
namespace {
// `shortcut(pixels, levels)`, when it returns true, has written the 16 pixels' levels another way.
template <typename Four, typename Shortcut>
void MapBgrRows16(const cv::Mat& bgr, cv::Mat& out, const Four& four, const Shortcut& shortcut) {
  for (int y = 0; y < bgr.rows; ++y) {
    const uint8_t* row = bgr.ptr<uint8_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    // The last 16 pixels overlap the ones before them when the width is no multiple of 16: the
    // same pixels give the same levels, and nothing outside the row is read.
    for (int x = 0; x < bgr.cols; x += 16) {
      if (x + 16 > bgr.cols) x = bgr.cols - 16;
      if (shortcut(row + 3 * x, o + x)) continue;
      cv::v_uint8x16 b8, g8, r8;
      cv::v_load_deinterleave(row + 3 * x, b8, g8, r8);
      cv::v_uint16x8 b16[2], g16[2], r16[2];
      cv::v_expand(b8, b16[0], b16[1]);
      cv::v_expand(g8, g16[0], g16[1]);
      cv::v_expand(r8, r16[0], r16[1]);
      cv::v_int16x8 packed[2];
      for (int h = 0; h < 2; ++h) {
        cv::v_uint32x4 b32[2], g32[2], r32[2];
        cv::v_expand(b16[h], b32[0], b32[1]);
        cv::v_expand(g16[h], g32[0], g32[1]);
        cv::v_expand(r16[h], r32[0], r32[1]);
        packed[h] = cv::v_pack(four(b32[0], g32[0], r32[0]), four(b32[1], g32[1], r32[1]));
      }
      cv::v_store(o + x, cv::v_pack_u(packed[0], packed[1]));  // Saturated: saturate_cast.
    }
  }
}
}  // namespace
#endif

void ProjectLevels(const cv::Mat& bgr, const cv::Mat& projection, cv::Mat& out) {
#if CV_SIMD128
  CV_Assert(bgr.type() == CV_8UC3 && projection.type() == CV_32FC1 && projection.total() == 4);
  if (bgr.cols < 16) {
    ProjectLevelsReference(bgr, projection, out);
    return;
  }
  // `out` may be reallocated here only (create keeps a buffer of the same size and type: the
  // tracker's windows reuse theirs from frame to frame).
  out.create(bgr.size(), CV_8UC1);
  const float* m = projection.ptr<float>();
  const cv::v_float32x4 wb = cv::v_setall_f32(m[0]), wg = cv::v_setall_f32(m[1]);
  const cv::v_float32x4 wr = cv::v_setall_f32(m[2]), offset = cv::v_setall_f32(m[3]);
  // Four pixels' levels, widened to 32 bits, -> their rounded projections.
  const auto four = [&](const cv::v_uint32x4& b, const cv::v_uint32x4& g,
                        const cv::v_uint32x4& r) {
    cv::v_float32x4 acc = wb * cv::v_cvt_f32(cv::v_reinterpret_as_s32(b));
    acc = acc + wg * cv::v_cvt_f32(cv::v_reinterpret_as_s32(g));
    acc = acc + wr * cv::v_cvt_f32(cv::v_reinterpret_as_s32(r));
    return cv::v_round(acc + offset);  // Nearest even, as cvRound.
  };
  // A gray pixel's (v, v, v) level, for each v, from `four` itself, saturated as MapBgrRows16's
  // packs saturate: the same bits. Kept per thread for the last few projections (each tracker's
  // is set once, a session has a few; a table costs a few hundred pixels' projections).
  struct GrayTable {
    float m[4] = {0, 0, 0, 0};
    bool valid = false;
    bool identity = false;  // level[v] == v for every v.
    uint8_t level[256] = {};
  };
  thread_local std::array<GrayTable, 8> tables;
  thread_local size_t next_table = 0;
  GrayTable* found = nullptr;
  for (GrayTable& t : tables) {
    if (t.valid && std::memcmp(t.m, m, sizeof(t.m)) == 0) found = &t;
  }
  if (found == nullptr) {
    found = &tables[next_table];
    next_table = (next_table + 1) % tables.size();
    for (int v = 0; v < 256; v += 4) {
      const cv::v_uint32x4 levels(v, v + 1, v + 2, v + 3);
      int projected[4];
      cv::v_store(projected, four(levels, levels, levels));
      for (int k = 0; k < 4; ++k) {
        found->level[v + k] = static_cast<uint8_t>(std::clamp(projected[k], 0, 255));
      }
    }
    found->identity = true;
    for (int v = 0; v < 256; ++v) found->identity = found->identity && found->level[v] == v;
    std::memcpy(found->m, m, sizeof(found->m));
    found->valid = true;
  }
  const GrayTable& table = *found;
#if SOFTSIGHT_SSSE3_GRAY
  const bool identity = table.identity && HasSsse3();
#endif
  // A gray recording handed over as BGR (ViSP's mire-2): a run of 16 gray pixels is looked up,
  // at a third of the projection's instructions (issue 45: the projection was a tenth of the
  // ZNCC session there). Gray: each of the 48 bytes but every third equals the byte after it.
  const cv::v_uint8x16 ignore0(0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0);
  const cv::v_uint8x16 ignore1(0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0);
  const cv::v_uint8x16 ignore2(255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255);
  const auto gray16 = [&](const uint8_t* p, uint8_t* o) {
#if SOFTSIGHT_SSSE3_GRAY
    // The table leaves every level as it is (the gray selection's equal weights, issue 45: the
    // test and lookups were most of the projection's instructions on mire-2): the levels are the
    // bytes.
    if (identity) return GrayFirstOfThree16(p, o);
#endif
    const cv::v_uint8x16 c0 = cv::v_load(p), c1 = cv::v_load(p + 16), c2 = cv::v_load(p + 32);
    const cv::v_uint8x16 next0 = cv::v_extract<1>(c0, c1), next1 = cv::v_extract<1>(c1, c2);
    const cv::v_uint8x16 next2 = cv::v_extract<1>(c2, c2);  // Its last byte is ignored.
    if (!cv::v_check_all(((c0 == next0) | ignore0) & ((c1 == next1) | ignore1) &
                         ((c2 == next2) | ignore2))) {
      return false;
    }
    for (int k = 0; k < 16; ++k) o[k] = table.level[p[3 * k]];
    return true;
  };
#if SOFTSIGHT_SSSE3_GRAY
  if (identity) {
    for (int y = 0; y < bgr.rows; ++y) {
      if (GrayFirstOfThreeRow(bgr.ptr<uint8_t>(y), out.ptr<uint8_t>(y), bgr.cols)) continue;
      cv::Mat out_row = out.row(y);  // A header of the row: written in place.
      MapBgrRows16(bgr.row(y), out_row, four, gray16);
    }
    return;
  }
#endif
  MapBgrRows16(bgr, out, four, gray16);
#else
  ProjectLevelsReference(bgr, projection, out);
#endif
}

cv::Mat ScaledTemplate(const cv::Mat& original, const cv::Size& size) {
  if (size == original.size()) return original;
  cv::Mat scaled;
  const bool smaller = size.area() < original.size().area();
  cv::resize(original, scaled, size, 0, 0, smaller ? cv::INTER_AREA : cv::INTER_LINEAR);
  return scaled;
}

void TurnedTemplate(const cv::Mat& original, const cv::Size& size, double turn_deg,
                    const cv::Mat& shape, cv::Mat* out, cv::Mat* mask, cv::Matx23d* map) {
  const cv::Mat scaled = ScaledTemplate(original, size);
  if (turn_deg == 0.0) {
    *out = scaled.clone();
    *mask = shape.empty() ? cv::Mat() : shape.clone();
    *map = cv::Matx23d(1, 0, 0, 0, 1, 0);
    return;
  }
  // cv::getRotationMatrix2D turns a positive angle counter-clockwise on the screen: the minus
  // keeps the header's convention.
  const cv::Mat m = cv::getRotationMatrix2D(HalfSize(size), -turn_deg, 1.0);
  *map = cv::Matx23d(m);
  cv::warpAffine(scaled, *out, m, size, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  // What turned in from outside the template (or outside its round shape) does not count.
  const cv::Mat inside = shape.empty() ? cv::Mat(size, CV_8UC1, cv::Scalar(255)) : shape;
  cv::warpAffine(inside, *mask, m, size, cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  if (!shape.empty()) cv::bitwise_and(*mask, shape, *mask);
}

cv::Mat MarkerProjection(const cv::Mat& bgr, const cv::Mat& mask) {
  // Candidates: the box's principal colour axis (marker against band, when they dominate the
  // box), luma, and the axis from the colour of the box's edge to the colour at its centre (a
  // yellow dot on a green cart over a blue backdrop: the principal axis is cart against
  // backdrop, in which the dot hardly differs from its cart).
  const cv::Point c(bgr.cols / 2, bgr.rows / 2);
  const cv::Rect centre = cv::Rect(c.x - 1, c.y - 1, 3, 3) & cv::Rect(0, 0, bgr.cols, bgr.rows);
  cv::Mat border_mask(bgr.size(), CV_8UC1, cv::Scalar(255));
  if (bgr.cols > 2 && bgr.rows > 2) border_mask(cv::Rect(1, 1, bgr.cols - 2, bgr.rows - 2)).setTo(0);
  const cv::Scalar inner = cv::mean(bgr(centre)), edge = cv::mean(bgr, border_mask);
  cv::Vec3d axis(inner[0] - edge[0], inner[1] - edge[1], inner[2] - edge[2]);
  cv::Mat towards_centre;
  if (const double l1 = std::abs(axis[0]) + std::abs(axis[1]) + std::abs(axis[2]); l1 > 0) {
    axis /= l1;
    double offset = 0;
    for (int k = 0; k < 3; ++k) offset -= 255.0 * std::min(0.0, axis[k]);
    towards_centre = (cv::Mat_<float>(1, 4) << axis[0], axis[1], axis[2], offset);
  }
  const cv::Mat principal = ContrastProjection(bgr);
  const cv::Mat candidates[] = {principal, cv::Mat(), towards_centre};
  // The one in which the marker at the centre is most isolated from its surroundings (see
  // BlobMeter::isolation); the principal axis when none shows a blob there.
  cv::Mat best = principal, gray;
  double best_isolation = -1;
  for (size_t k = 0; k < 3; ++k) {
    if (k == 2 && towards_centre.empty()) continue;
    BlobChannelOf(bgr, candidates[k], gray);
    BlobMeter trial;
    cv::Point2d centroid;
    if (trial.Learn(gray, mask, &centroid) && trial.isolation() > best_isolation) {
      best_isolation = trial.isolation();
      best = candidates[k];
    }
  }
  return best;
}

bool LearnChromaAxis(const cv::Mat& bgr, ChromaAxis* out) {
  if (bgr.type() != CV_8UC3 || bgr.cols < 5 || bgr.rows < 5) return false;
  cv::Vec3d centre(0, 0, 0), edge(0, 0, 0);
  int centre_n = 0, edge_n = 0;
  for (int y = 0; y < bgr.rows; ++y) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3d c = ChromaticityOfLevels(row[x][0], row[x][1], row[x][2]);
      if (std::abs(2 * x - (bgr.cols - 1)) <= 2 && std::abs(2 * y - (bgr.rows - 1)) <= 2) {
        centre += c;
        ++centre_n;
      } else if (x == 0 || y == 0 || x == bgr.cols - 1 || y == bgr.rows - 1) {
        edge += c;
        ++edge_n;
      }
    }
  }
  if (centre_n == 0 || edge_n == 0) return false;
  const cv::Vec3d axis = centre / centre_n - edge / edge_n;
  const double span = std::sqrt(axis.dot(axis));
  if (!(span >= kMinChromaSpan)) return false;
  out->background = edge / edge_n;
  out->axis = axis / span;
  out->span = span;
  return true;
}

namespace {

// One pixel of the chroma channel (the reference's, and the vector loop's tail).
inline uint8_t ChromaLevel(const uint8_t* bgr, const ChromaAxis& chroma, double scale) {
  const cv::Vec3d c = ChromaticityOfLevels(bgr[0], bgr[1], bgr[2]);
  return cv::saturate_cast<uint8_t>(40.0 + scale * (c - chroma.background).dot(chroma.axis));
}

}  // namespace

void ChromaChannelReference(const cv::Mat& bgr, const ChromaAxis& chroma, cv::Mat& out) {
  CV_Assert(bgr.type() == CV_8UC3);
  out.create(bgr.size(), CV_8UC1);
  const double scale = 160.0 / chroma.span;
  for (int y = 0; y < bgr.rows; ++y) {
    const uint8_t* row = bgr.ptr<uint8_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < bgr.cols; ++x) o[x] = ChromaLevel(row + 3 * x, chroma, scale);
  }
}

// Per pixel, as the reference, in float vector lanes (4 pixels a vector, not the 2 of double
// ones, and a division instead of the scales' table, which vector lanes cannot look up): the
// level 40 + scale * ((b * a0 + g * a1 + r * a2) / (b + g + r + kChromaDarkLevels) - bg . a),
// the reference's expression rearranged (c . a - bg . a, c = (b, g, r) / the damped sum), rounded
// to nearest even and saturated to 0..255. The double reference's level and this one differ by
// one where the value lies within float's rounding of a half (tested: at most 1 level, in a few
// of every 8-bit colour). The template tracker's blob is measured in this channel every frame on
// colour footage: 137k instructions of a VGA frame of three templates in double lanes (issue 45).
void ChromaChannel(const cv::Mat& bgr, const ChromaAxis& chroma, cv::Mat& out) {
#if CV_SIMD128
  CV_Assert(bgr.type() == CV_8UC3);
  if (bgr.cols < 16) {
    ChromaChannelReference(bgr, chroma, out);
    return;
  }
  out.create(bgr.size(), CV_8UC1);
  const double scale = 160.0 / chroma.span;
  const cv::v_float32x4 a0 = cv::v_setall_f32(static_cast<float>(chroma.axis[0]));
  const cv::v_float32x4 a1 = cv::v_setall_f32(static_cast<float>(chroma.axis[1]));
  const cv::v_float32x4 a2 = cv::v_setall_f32(static_cast<float>(chroma.axis[2]));
  const cv::v_float32x4 dark = cv::v_setall_f32(static_cast<float>(kChromaDarkLevels));
  const cv::v_float32x4 along = cv::v_setall_f32(static_cast<float>(chroma.background.dot(chroma.axis)));
  const cv::v_float32x4 gain = cv::v_setall_f32(static_cast<float>(scale));
  const cv::v_float32x4 level40 = cv::v_setall_f32(40.0f);
  // Four pixels' levels, widened to 32 bits, -> their rounded channel levels.
  const auto four = [&](const cv::v_uint32x4& b32, const cv::v_uint32x4& g32,
                        const cv::v_uint32x4& r32) {
    const cv::v_float32x4 b = cv::v_cvt_f32(cv::v_reinterpret_as_s32(b32));
    const cv::v_float32x4 g = cv::v_cvt_f32(cv::v_reinterpret_as_s32(g32));
    const cv::v_float32x4 r = cv::v_cvt_f32(cv::v_reinterpret_as_s32(r32));
    const cv::v_float32x4 dot = b * a0 + g * a1 + r * a2;
    const cv::v_float32x4 sum = b + g + r + dark;
    return cv::v_round(level40 + gain * (dot / sum - along));
  };
  MapBgrRows16(bgr, out, four, [](const uint8_t*, uint8_t*) { return false; });
#else
  ChromaChannelReference(bgr, chroma, out);
#endif
}

void LogChromaticity(const cv::Mat& bgr, cv::Mat& out) {
  CV_Assert(bgr.type() == CV_8UC3);
  static const std::array<float, 256> kLog = [] {
    std::array<float, 256> table{};
    for (int v = 0; v < 256; ++v) table[v] = static_cast<float>(std::log(v + kLogChromaDarkLevels));
    return table;
  }();
  out.create(bgr.size(), CV_32FC2);
  for (int y = 0; y < bgr.rows; ++y) {
    const uint8_t* in = bgr.ptr<uint8_t>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < bgr.cols; ++x, in += 3, o += 2) {
      const float g = kLog[in[1]];
      o[0] = kLog[in[2]] - g;
      o[1] = kLog[in[0]] - g;
    }
  }
}

double TwoChannelZncc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  CV_Assert(a.type() == CV_32FC2 && b.type() == CV_32FC2 && a.size() == b.size());
  CV_Assert(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == a.size()));
  // Sums of each channel, of squares and of products, in doubles: a template holds at most a few
  // thousand pixels.
  double n = 0;
  cv::Vec2d sa(0, 0), sb(0, 0), saa(0, 0), sbb(0, 0), sab(0, 0);
  for (int y = 0; y < a.rows; ++y) {
    const cv::Vec2f* pa = a.ptr<cv::Vec2f>(y);
    const cv::Vec2f* pb = b.ptr<cv::Vec2f>(y);
    const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(y);
    for (int x = 0; x < a.cols; ++x) {
      if (m != nullptr && m[x] == 0) continue;
      n += 1;
      for (int c = 0; c < 2; ++c) {
        sa[c] += pa[x][c];
        sb[c] += pb[x][c];
        saa[c] += double(pa[x][c]) * pa[x][c];
        sbb[c] += double(pb[x][c]) * pb[x][c];
        sab[c] += double(pa[x][c]) * pb[x][c];
      }
    }
  }
  if (n < 2) return kNoRival;
  double cross = 0, va = 0, vb = 0;
  for (int c = 0; c < 2; ++c) {
    cross += sab[c] - sa[c] * sb[c] / n;
    va += saa[c] - sa[c] * sa[c] / n;
    vb += sbb[c] - sb[c] * sb[c] / n;
  }
  // No variation (below float rounding of the sums): no shape to compare.
  if (!(va > 1e-9 * n && vb > 1e-9 * n)) return kNoRival;
  return cross / std::sqrt(va * vb);
}

bool CoreColour(const cv::Mat& bgr, const cv::Point2d& centre, double radius, cv::Vec3d* chroma) {
  CV_Assert(bgr.type() == CV_8UC3);
  const double r = std::max(radius, 1.0);
  const cv::Rect box(static_cast<int>(std::floor(centre.x - r)),
                     static_cast<int>(std::floor(centre.y - r)),
                     static_cast<int>(std::ceil(2 * r)) + 2, static_cast<int>(std::ceil(2 * r)) + 2);
  if ((box & cv::Rect(0, 0, bgr.cols, bgr.rows)) != box) return false;
  // Whole levels summed in integers: the double sums they were are exact (far below 2^53), so
  // the same. A row's pixels within the radius are one run (the distance grows with |dx| on
  // either side of the centre), found by the same test from both ends of the box's row, and
  // summed without a test each (issue 45: this ran on every frame's match, per pixel in doubles).
  const auto outside = [&](int x, int y) {
    const double dx = x - centre.x, dy = y - centre.y;
    return dx * dx + dy * dy > r * r;
  };
  int64_t sum_b = 0, sum_g = 0, sum_r = 0;
  int n = 0;
  for (int y = box.y; y < box.br().y; ++y) {
    const uint8_t* row = bgr.ptr<uint8_t>(y);
    int x0 = box.x, x1 = box.br().x - 1;  // Inclusive.
    while (x0 <= x1 && outside(x0, y)) ++x0;
    while (x1 >= x0 && outside(x1, y)) --x1;
    for (int x = x0; x <= x1; ++x) {
      sum_b += row[3 * x];
      sum_g += row[3 * x + 1];
      sum_r += row[3 * x + 2];
    }
    n += std::max(0, x1 - x0 + 1);
  }
  if (n == 0) return false;
  const cv::Vec3d sum(static_cast<double>(sum_b), static_cast<double>(sum_g),
                      static_cast<double>(sum_r));
  const double total = sum[0] + sum[1] + sum[2];
  if (!(total >= kDarkCoreLevels * n)) return false;
  *chroma = sum / total;
  return true;
}

namespace {
// The row spans of FillUnmasked's and ReachesEdge's fills on a continuous 8-bit patch of `total`
// pixels, `cols` a row: a pixel is the marker's when its marker-likeness (level ^ flip) is above
// `above`. The spans are a dot's rows, mostly under 16 pixels wide: the seeds beside a span and
// the scan leftwards are taken 16 pixels at a time too, a span's last chunk masked to it, where
// the pixel-at-a-time tails cost ~20 instructions a pixel (issue 45: the fills took ~400-480
// instructions a span on ViSP's mire-2). The same span, and the same seeds in the same order
// (left to right), as a pixel at a time: Fill's component and the reference flood's pass (the
// tests compare them).
struct SpanScan {
  const uint8_t* levels;
  int cols;
  int total;
  int flip;
  int above;
#if CV_SIMD128
  cv::v_uint8x16 flip16, above16;
#endif
  SpanScan(const uint8_t* levels_in, int cols_in, int total_in, int flip_in, int above_in)
      : levels(levels_in), cols(cols_in), total(total_in), flip(flip_in), above(above_in) {
#if CV_SIMD128
    flip16 = cv::v_setall_u8(static_cast<uint8_t>(flip));
    above16 = cv::v_setall_u8(static_cast<uint8_t>(std::clamp(above, 0, 255)));
#endif
  }
  bool marker(int i) const { return (levels[i] ^ flip) > above; }
#if CV_SIMD128
  // marker() for the 16 pixels from i, as a bit each (whole levels: exact in 8-bit lanes).
  unsigned markers16(int i) const {
    return static_cast<unsigned>(cv::v_signmask((cv::v_load(levels + i) ^ flip16) > above16));
  }
#endif
  // The first column of the run of marker pixels that ends at `x` (a marker pixel) in the row
  // starting at pixel `row`.
  int Left(int row, int x) const {
#if CV_SIMD128
    while (x >= 16) {
      const unsigned run = markers16(row + x - 16);
      // Bit 15 is the pixel left of x: the marker pixels next to it are ~run's leading zeros
      // once its 16 bits are shifted to the top.
      if (run != 0xFFFFu) return x - __builtin_clz(~run << 16);
      x -= 16;
    }
#endif
    while (x > 0 && marker(row + x - 1)) --x;
    return x;
  }
  // The last column of the run that starts at `x`.
  int Right(int row, int x) const {
#if CV_SIMD128
    while (x + 16 <= cols - 1) {
      const unsigned run = markers16(row + x + 1);
      if (run != 0xFFFFu) return x + __builtin_ctz(~run);
      x += 16;
    }
#endif
    while (x < cols - 1 && marker(row + x + 1)) ++x;
    return x;
  }
  // Pushes onto `stack` the first pixel ({x, y}) of each run, left to right, of the marker
  // pixels of columns left..right of row y whose `visited` byte (a patch-sized array beside
  // `levels`) is not `tag`: the fill's seeds beside a span. Plain pointers and a tag, no
  // callbacks: with them the compiler kept the loop's state on the stack.
  void Seeds(int y, int left, int right, const uint8_t* visited, uint8_t tag,
             std::vector<cv::Point>& stack) const {
    const int r = y * cols;
    const uint8_t* row_levels = levels + r;
    const uint8_t* row_visited = visited + r;
    bool in_run = false;  // The pixel before x is an open marker pixel of [left, right].
    int x = left;
#if CV_SIMD128
    const cv::v_uint8x16 tag16 = cv::v_setall_u8(tag);
    const int last_load = total - r - 16;  // The last x whose 16 pixels lie in the patch.
    for (; x <= right && x <= last_load; x += 16) {
      const cv::v_uint8x16 open = (cv::v_load(row_visited + x) != tag16) &
                                  ((cv::v_load(row_levels + x) ^ flip16) > above16);
      unsigned run = static_cast<unsigned>(cv::v_signmask(open));
      if (right + 1 - x < 16) run &= (1u << (right + 1 - x)) - 1u;  // The span's last chunk.
      for (unsigned starts = run & ~((run << 1) | (in_run ? 1u : 0u)); starts != 0;
           starts &= starts - 1) {
        stack.push_back({x + __builtin_ctz(starts), y});
      }
      in_run = (run >> 15) & 1u;
    }
#endif
    for (; x <= right; ++x) {
      const bool in = row_visited[x] != tag && marker(r + x);
      if (in && !in_run) stack.push_back({x, y});
      in_run = in;
    }
  }
};
}  // namespace

void BlobMeter::FloodUnmasked(const cv::Mat& gray, cv::Point seed, int* pass) {
  const int cols = gray.cols, rows = gray.rows;
  const int area = cols * rows;
  if (edge_size_ != gray.size()) {
    // The patch's edge pixels, for this size (the tracker's patch keeps its size while the
    // scale does).
    edge_.assign(static_cast<size_t>(area), 0);
    for (int x = 0; x < cols; ++x) edge_[x] = edge_[static_cast<size_t>(area - cols + x)] = 1;
    for (int y = 0; y < rows; ++y) edge_[y * cols] = edge_[y * cols + cols - 1] = 1;
    edge_size_ = gray.size();
  }
  if (next_.size() < static_cast<size_t>(area)) next_.resize(static_cast<size_t>(area));
  heads_.fill(-1);
  // A pixel is visited when its byte holds this flood's tag: the bytes are cleared only when the
  // tag wraps or the patch's size changes, not for every flood (issue 45: clearing the patch took
  // a third as many instructions as the flood, which mostly stops after its core's 9 pixels).
  if (seen_size_ != gray.size()) {
    seen_.assign(static_cast<size_t>(area), 0);
    seen_size_ = gray.size();
    seen_tag_ = 0;
  }
  if (++seen_tag_ == 0) {  // Wrapped: the old tags would read as this flood's.
    std::fill(seen_.begin(), seen_.end(), 0);
    seen_tag_ = 1;
  }
  const uint8_t tag = seen_tag_;
  const int flip = bright_ ? 0 : 255;
  const uint8_t* levels = gray.data;  // Continuous: pixel i at levels[i].
  uint8_t* visited = seen_.data();
  const uint8_t* edge = edge_.data();
  int* next = next_.data();
  int* heads = heads_.data();
  const int start = seed.y * cols + seed.x;
  int level = levels[start] ^ flip;
  // The current level's bucket is held in `top` (its first pixel), not in heads[level]: most
  // pushes go to it and every pop takes from it, and through memory each waited for the store
  // before it (issue 45: the flood was a fifth of a frame's time on ViSP's mire-2, for a tenth
  // of its instructions). A level's bucket is left for good once empty (levels only go down),
  // so heads[level] is never read again and need not be written back. Same pushes and pops, in
  // the same order.
  next[start] = -1;
  int top = start;
  visited[start] = tag;
  int core[kCoreSamples];
  size_t cores = 0;
  *pass = -1;
  const int offsets[4] = {1, -1, cols, -cols};  // The reference's order: +x, -x, +y, -y.
  for (;;) {
    while (top < 0) {
      if (--level < 0) {
        core_.assign(core, core + cores);
        return;
      }
      top = heads[level];
    }
    const int p = top;
    top = next[p];
    if (edge[p]) {
      *pass = level;
      break;
    }
    if (cores < kCoreSamples) {
      core[cores++] = level;
      if (cores == kCoreSamples) {
        // The core is taken (the rest of the flood only looks for the pass), and every pixel
        // more marker-like than `level` has been taken without reaching the edge: the pass is
        // at most `level`. The flood would take the rest of the marker's pixels one at a time
        // (issue 45: a sixth of the ZNCC session's time on ViSP's mire-2); fills of whole row
        // spans find the same level in a few tries. The flood goes on from here when they
        // cannot (the budget: a quarter of the patch's pixels as spans).
        const int found = PassByFills(gray, seed, level, area / 4);
        if (found >= 0) {
          ++passes_by_fills_;
          *pass = found;
          break;
        }
        ++fills_given_up_;
      }
    }
    // Off the patch's edge: the four neighbours are in the patch.
    for (const int offset : offsets) {
      const int q = p + offset;
      if (visited[q] == tag) continue;
      visited[q] = tag;
      const int l = levels[q] ^ flip;  // A path's level is its least marker-like.
      if (l >= level) {
        next[q] = top;
        top = q;
      } else {
        next[q] = heads[l];
        heads[l] = q;
      }
    }
  }
  core_.assign(core, core + cores);
  last_pass_ = *pass;
}

int BlobMeter::PassByFills(const cv::Mat& gray, cv::Point seed, int upper, int budget) {
  // Whether the level-t fill reaches the edge only falls as t rises, and t = 0 takes every
  // pixel: the pass is the last t that reaches it. From the last pass g: g, then g + 1 (the
  // usual answer in two fills), else outwards in doubling steps and halving between.
  int lo = 0;          // Reaches the edge.
  int hi = upper + 1;  // Does not (the flood has taken everything above `upper`).
  const auto test = [&](int t) {
    const int r = ReachesEdge(gray, seed, t, &budget);
    if (r > 0) lo = t;
    if (r == 0) hi = t;
    return r;
  };
  const int g = std::clamp(last_pass_, 0, upper);
  if (g > 0 && test(g) < 0) return -1;
  if (lo == g) {
    for (int step = 1; hi - lo > 1; step *= 2) {  // Upwards until a fill does not reach.
      const int t = std::min(g + step, hi - 1);
      if (test(t) < 0) return -1;
      if (hi == t) break;
    }
  } else {
    for (int step = 1; hi - lo > 1; step *= 2) {  // Downwards until one does.
      const int t = std::max(g - step, lo + 1);
      if (test(t) < 0) return -1;
      if (lo == t) break;
    }
  }
  while (hi - lo > 1) {
    if (test(lo + (hi - lo) / 2) < 0) return -1;
  }
  return lo;
}

int BlobMeter::ReachesEdge(const cv::Mat& gray, cv::Point seed, int t, int* budget) {
  const int cols = gray.cols, rows = gray.rows;
  if (marks_size_ != gray.size()) {
    marks_.assign(static_cast<size_t>(cols) * rows, 0);
    marks_size_ = gray.size();
    mark_ = 0;
  }
  if (++mark_ == 0) {  // Wrapped: the old marks would read as this fill's.
    std::fill(marks_.begin(), marks_.end(), 0);
    mark_ = 1;
  }
  uint8_t* marks = marks_.data();
  const uint8_t mark = mark_;
  // Marker-likeness t or more: above t - 1.
  const SpanScan scan(gray.data, cols, cols * rows, bright_ ? 0 : 255, t - 1);
  int spans = *budget;  // A local: through the pointer it was loaded and stored every span.
  const auto done = [&](int answer) {
    *budget = spans;
    return answer;
  };
  stack_.clear();
  stack_.push_back(seed);  // Of level t or more: t is at most the flood's level.
  while (!stack_.empty()) {
    const cv::Point p = stack_.back();
    stack_.pop_back();
    const int row = p.y * cols;
    if (marks[row + p.x] == mark) continue;  // Its span was marked from another seed.
    if (--spans < 0) return done(-1);
    if (p.y == 0 || p.y == rows - 1) return done(1);
    const int left = scan.Left(row, p.x), right = scan.Right(row, p.x);
    if (left == 0 || right == cols - 1) return done(1);
    std::memset(marks + row + left, mark, static_cast<size_t>(right - left + 1));
    // A seed for each run of unmarked pixels of level t or more beside the span.
    for (const int y : {p.y - 1, p.y + 1}) {
      scan.Seeds(y, left, right, marks, mark, stack_);
    }
  }
  return done(0);
}

bool BlobMeter::FillUnmasked(const cv::Mat& gray, cv::Point seed, int cut) {
  const int cols = gray.cols, rows = gray.rows;
  if (label_.size() == gray.size() && label_.type() == CV_8UC1 && label_.isContinuous()) {
    // The last component's rows (or a fill's that stopped at the edge) are all there is to clear.
    const cv::Rect dirty = label_dirty_ & cv::Rect(0, 0, cols, rows);
    for (int y = dirty.y; y < dirty.br().y; ++y) {
      std::memset(label_.data + static_cast<size_t>(y) * cols + dirty.x, 0,
                  static_cast<size_t>(dirty.width));
    }
  } else {
    ZeroedMask(gray.size(), label_);
  }
  uint8_t* label = label_.data;  // Continuous, as gray.
  // In marker-likeness (v ^ flip) a pixel is the marker's when above `cut`.
  const SpanScan scan(gray.data, cols, cols * rows, bright_ ? 0 : 255, cut);
  int x0 = seed.x, y0 = seed.y, x1 = seed.x, y1 = seed.y;  // Inclusive.
  // Every span marked lies in the box so far: it is written where the fill stops.
  const auto stop = [&](bool separated) {
    label_dirty_ = cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
    return separated;
  };
  int64_t count = 0, sum_x = 0, sum_y = 0;
  stack_.clear();
  stack_.push_back(seed);
  bool first = true;  // The seed counts whatever its level (as Fill labels it).
  while (!stack_.empty()) {
    const cv::Point p = stack_.back();
    stack_.pop_back();
    const int row = p.y * cols;
    if (label[row + p.x]) continue;  // Its span was filled from another seed.
    if (!first && !scan.marker(row + p.x)) continue;
    first = false;
    // The whole span of marker pixels through p: a component pixel on the patch's edge is not
    // separated from its surroundings (Fill's answer, whatever it had filled by then).
    if (p.y == 0 || p.y == rows - 1) return stop(false);
    const int left = scan.Left(row, p.x), right = scan.Right(row, p.x);
    if (left == 0 || right == cols - 1) return stop(false);
    std::memset(label + row + left, 1, static_cast<size_t>(right - left + 1));
    const int64_t length = right - left + 1;
    count += length;
    sum_x += (static_cast<int64_t>(left) + right) * length / 2;
    sum_y += static_cast<int64_t>(p.y) * length;
    x0 = std::min(x0, left);
    x1 = std::max(x1, right);
    y0 = std::min(y0, p.y);
    y1 = std::max(y1, p.y);
    // A seed for each run of unfilled marker pixels beside the span, above and below.
    for (const int y : {p.y - 1, p.y + 1}) {
      scan.Seeds(y, left, right, label, 1, stack_);  // Filled pixels are 1.
    }
  }
  box_ = cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
  fill_count_ = count;
  fill_sum_x_ = sum_x;
  fill_sum_y_ = sum_y;
  filled_moments_ = true;
  return stop(true);
}

bool LearnTemplateBlob(const cv::Mat& templ, const cv::Mat& mask, cv::Mat* projection,
                       BlobMeter* meter, cv::Point2d* anchor) {
  *projection = templ.channels() == 3 ? MarkerProjection(templ, mask) : cv::Mat();
  cv::Mat gray;
  BlobChannelOf(templ, *projection, gray);
  return meter->Learn(gray, mask, anchor);
}

}  // namespace softsight::template_internal
