// ColourTracker, part 2 of 3: detection. Classify, filter and clean a region, label its blobs
// and measure each (centroids, shape, holes, colour against its surroundings, the rim fit of a
// partly hidden round marker).
#include "softsight/track/colour_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "track/chromaticity.h"
#include "track/colour_tracker_impl.h"
#include "track/colour_tracker_parts.h"
#include "track/soft_centroid.h"
#include "track/track_options.h"

namespace softsight {

using namespace colour_internal;  // NOLINT: the tracker's own constants and helpers.

void ColourTracker::find_blobs(const cv::Mat& frame_bgr, int downsample,
                               std::vector<ColourBlob>* blobs) {
  check_frame(frame_bgr);
  blobs->clear();
  const cv::Rect frame_rect(cv::Point(0, 0), frame_bgr.size());
  if (downsample > 1) {
    coarse_to_fine(frame_bgr, frame_rect, downsample, blobs);
  } else {
    complete_blobs(frame_bgr, frame_rect, blobs);
  }
  std::sort(blobs->begin(), blobs->end(), CentroidBefore);
}

cv::Mat ColourTracker::prepare(const cv::Mat& src, cv::Mat& store) {
  const int channels = gray_ ? 1 : 3;
  if (src.channels() == channels) return src;
  cv::Mat converted = Scratch(store, src.size(), CV_MAKETYPE(CV_8U, channels));
  cv::cvtColor(src, converted, channels == 1 ? cv::COLOR_BGR2GRAY : cv::COLOR_GRAY2BGR);
  return converted;
}

bool ColourTracker::membership(const cv::Mat& frame_bgr, cv::Mat& mask) const {
  cv::Mat src = frame_bgr;
  const int channels = gray_ ? 1 : 3;
  if (src.channels() != channels) {
    cv::cvtColor(frame_bgr, src, channels == 1 ? cv::COLOR_BGR2GRAY : cv::COLOR_GRAY2BGR);
  }
  if (gray_) {
    cv::inRange(src, cv::Scalar(gray_->lo), cv::Scalar(gray_->hi), mask);
  } else {
    mask.create(src.size(), CV_8UC1);
    fine_hsv_.Classify(src, mask);
  }
  return true;
}

void ColourTracker::classify(const cv::Mat& src, bool coarse, cv::Mat& mask, bool dimmed) {
  if (!gray_ && src.channels() == 1) {
    // A flat region's plane (analyse_region): each level stands for the BGR pixel (v, v, v).
    (dimmed ? *dim_hsv_ : coarse ? coarse_hsv_ : fine_hsv_).ClassifyFlat(src, mask);
    return;
  }
  if (gray_) {
    const HsvRange& g = dimmed ? *dim_gray_ : coarse ? *coarse_gray_ : *gray_;
    cv::inRange(src, cv::Scalar(g.lo), cv::Scalar(g.hi), mask);
    return;
  }
  // One pass, bit-exact with cvtColor(BGR2HSV) + inRange (track/colour_kernels.h).
  (dimmed ? *dim_hsv_ : coarse ? coarse_hsv_ : fine_hsv_).Classify(src, mask);
}

void ColourTracker::analyse(const cv::Mat& frame, cv::Rect region,
                            std::vector<ColourBlob>* blobs, bool dimmed) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  region &= frame_rect;
  if (region.empty()) return;
  if (region.area() >= kCoarseMinArea) {
    analyse_region(frame, region, blobs, dimmed);
    return;
  }
  // A window is a few thousand pixels: handing its pieces to OpenCV's thread pool (TBB) costs
  // more than the work (connected components alone doubles). Run the window as one OpenCV
  // parallel region of a single task: OpenCV executes parallel loops nested in it inline. Only
  // OpenCV's own filters, conversions and morphology parallelise; without them (the default
  // pipeline: our kernels alone) the window runs directly, since the region itself costs a few
  // allocations and microseconds per window, and a re-acquisition analyses dozens.
  const bool opencv_parallel = opencv_in_windows_ || frame.channels() != (gray_ ? 1 : 3);
  if (!opencv_parallel) {
    analyse_region(frame, region, blobs, dimmed);
    return;
  }
  cv::parallel_for_(cv::Range(0, 1),
                    [&](const cv::Range&) { analyse_region(frame, region, blobs, dimmed); });
}

cv::Rect ColourTracker::ClassifyRegion(const cv::Mat& filtered, cv::Mat& mask,
                                      const cv::Rect& inner, bool dimmed) {
  const cv::Rect all(cv::Point(0, 0), mask.size());
  // The margin around the region feeds the pre-filter, the morphology near the region's border
  // and the ring of a blob near it. Without a pre-filter each mask pixel is its own pixel's
  // test, and the margin matters only when the region's own marker-coloured pixels come within
  // `guard` of a side that has a margin: the four morphology passes (radius r each) carry a
  // margin pixel at most 4r into the region, and a pixel there depends on nothing deeper than
  // 8r; a blob's padded box reaches kRingOuter + 1 beyond it, and the morphology grows a blob by
  // r at most. So when the region's pixels keep `guard` away from every side with a margin, the
  // region is what a pass over the margin too would make of it, bit for bit, and the margin
  // (a third of a window at VGA, 18 px of 82) is never classified (issue 45).
  if (params_.filter != ColourParams::Filter::kNone || inner == all) {
    classify(filtered, false, mask, dimmed);
    return NonZeroBounds(mask);
  }
  const int morph_radius = kernel_.empty() ? 0 : params_.morph_size / 2;
  const int guard = std::max(margin_px_, 8 * morph_radius + 1);
  const auto near_a_margin = [&](cv::Rect bounds) {
    bounds += inner.tl();
    return (inner.x > 0 && bounds.x - inner.x < guard) ||
           (inner.y > 0 && bounds.y - inner.y < guard) ||
           (inner.br().x < all.width && inner.br().x - bounds.br().x < guard) ||
           (inner.br().y < all.height && inner.br().y - bounds.br().y < guard);
  };
  cv::Mat inner_mask = mask(inner);
  if (margin_was_needed_) {
    // The last region needed its margin (clutter of the marker's colour all over, as on a
    // poster-covered wall): most likely this one does too, and classifying it in one pass costs
    // less than the region and then its margin's strips. Whether it still does is a scan of the
    // region's mask (a sixteenth of classifying it). Either way the result is the same.
    classify(filtered, false, mask, dimmed);
    const cv::Rect inner_bounds = NonZeroBounds(inner_mask);
    margin_was_needed_ = !inner_bounds.empty() && near_a_margin(inner_bounds);
    return NonZeroBounds(mask);
  }
  classify(filtered(inner), false, inner_mask, dimmed);
  const cv::Rect bounds = NonZeroBounds(inner_mask);
  if (bounds.empty()) return bounds;  // Margin pixels alone set nothing inside (see above).
  margin_was_needed_ = near_a_margin(bounds);
  if (!margin_was_needed_) return bounds + inner.tl();
  // The margin's strips: above and below the region at full width, and beside it (each as at
  // least 16 columns, overlapping the region, whose pixels get the same result again: a strip
  // narrower than a vector would take the scalar test).
  const auto strip = [&](const cv::Rect& r) {
    const cv::Rect part = r & all;
    if (part.empty()) return;
    cv::Mat part_mask = mask(part);
    classify(filtered(part), false, part_mask, dimmed);
  };
  strip(cv::Rect(0, 0, all.width, inner.y));
  strip(cv::Rect(0, inner.br().y, all.width, all.height - inner.br().y));
  if (inner.x > 0) strip(cv::Rect(0, inner.y, std::max(inner.x, 16), inner.height));
  if (inner.br().x < all.width) {
    const int width = std::max(all.width - inner.br().x, 16);
    strip(cv::Rect(all.width - width, inner.y, width, inner.height));
  }
  return NonZeroBounds(mask);
}

void ColourTracker::analyse_region(const cv::Mat& frame, const cv::Rect& region,
                                   std::vector<ColourBlob>* blobs, bool dimmed) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  const int m = margin_px_;
  const cv::Rect extended =
      cv::Rect(region.x - m, region.y - m, region.width + 2 * m, region.height + 2 * m) &
      frame_rect;
  // A view into the frame (when it has the channels the classifier needs), so near the frame's
  // edges the filter sees the same border as a whole-frame pass would.
  cv::Mat src = prepare(frame(extended), prepared_store_);
  // A gray recording handed over as BGR (b == g == r in the whole region): the colour pipeline
  // reads one plane instead of three interleaved ones, every result the same (the classifier's
  // and the measurement's flat paths). A colour region stops the check at its first chunk.
  flat_pixels_ = false;
  if (!gray_ && params_.filter == ColourParams::Filter::kNone && src.channels() == 3) {
    cv::Mat plane = Scratch(flat_store_, extended.size(), CV_8U);
    if (ExtractFlatPlane(src, plane)) {
      src = plane;
      flat_pixels_ = true;
    }
  }

  // 1. Filter.
  cv::Mat filtered = src;
  if (params_.filter == ColourParams::Filter::kGaussian) {
    filtered = Scratch(filtered_store_, extended.size(), src.type());
    cv::GaussianBlur(src, filtered, cv::Size(params_.filter_ksize, params_.filter_ksize), 0);
  } else if (params_.filter == ColourParams::Filter::kMedian) {
    filtered = Scratch(filtered_store_, extended.size(), src.type());
    cv::medianBlur(src, filtered, params_.filter_ksize);
  }

  // 2. Binarise.
  cv::Mat mask = Scratch(mask_store_, extended.size(), CV_8U);
  const cv::Rect extended_local(cv::Point(0, 0), extended.size());
  const cv::Rect inner_local(region.tl() - extended.tl(), region.size());
  cv::Rect active = ClassifyRegion(filtered, mask, inner_local, dimmed);
  if (active.empty()) return;

  // 3. Opening then closing, only where it can change anything: outside the bounding box of the
  //    marker-coloured pixels the mask is 0 and stays 0 (opening only removes, closing only fills
  //    between pixels), so morphology and labelling work on that box plus the reach of the four
  //    passes. Beyond the box the parent mask holds zeros, exactly what a whole pass would read.
  if (!kernel_.empty()) {
    const int reach = 4 * (params_.morph_size / 2) + 1;
    active = cv::Rect(active.x - reach, active.y - reach, active.width + 2 * reach,
                      active.height + 2 * reach) &
             extended_local;
    cv::Mat cleaned = mask(active);
    if (morph_cross_ || morph_square_) {
      // The reach padding keeps `active`'s border rows zero, so reading the outside as the
      // border (the kernel) equals reading the parent's zeros (morphologyEx on the view).
      OpenClose3x3(cleaned, morph_cross_, morph_store_);
    } else {
      cv::Mat opened = Scratch(morph_store_, active.size(), CV_8U);
      cv::morphologyEx(cleaned, opened, cv::MORPH_OPEN, kernel_);
      cv::morphologyEx(opened, cleaned, cv::MORPH_CLOSE, kernel_);
    }
  }

  // 4. Blobs of the region proper (the margin only fed the filters); the region is 0 outside
  //    `labelled`, so its components are the region's components.
  const cv::Rect labelled = active & inner_local;
  if (labelled.empty()) return;
  const cv::Point offset = labelled.tl() - inner_local.tl();  // Of `labelled` in the region.
  labeller_.Label(mask(labelled));
  const bool open_left = region.x > 0;
  const bool open_top = region.y > 0;
  const bool open_right = region.x + region.width < frame.cols;
  const bool open_bottom = region.y + region.height < frame.rows;
  const std::vector<RunLabeller::Component>& components = labeller_.components();
  for (size_t i = 0; i < components.size(); ++i) {
    const RunLabeller::Component& comp = components[i];
    const cv::Rect& box = comp.box;
    const cv::Rect in_region = box + offset;
    ColourBlob blob;
    blob.area_px = comp.area;
    blob.clipped = (open_left && in_region.x == 0) || (open_top && in_region.y == 0) ||
                   (open_right && in_region.x + in_region.width == region.width) ||
                   (open_bottom && in_region.y + in_region.height == region.height);
    blob.bbox_px = in_region + region.tl();
    blob.at_frame_edge = blob.bbox_px.x == 0 || blob.bbox_px.y == 0 ||
                         blob.bbox_px.x + blob.bbox_px.width == frame.cols ||
                         blob.bbox_px.y + blob.bbox_px.height == frame.rows;
    if (!blob.clipped) {
      if (blob.area_px < params_.min_area_px) continue;
      if (params_.max_area_px > 0 && blob.area_px > params_.max_area_px) continue;
      // 5. Centroid from the binary moments of this blob alone (exact integer sums relative to
      //    its box, as cv::moments of its own pixels), then the box's integer offset in the frame.
      const double m00 = comp.area, inv_m00 = 1.0 / m00;
      const double cx = static_cast<double>(comp.m10) * inv_m00;
      const double cy = static_cast<double>(comp.m01) * inv_m00;
      blob.binary_centroid_px = cv::Point2d(cx + blob.bbox_px.x, cy + blob.bbox_px.y);
      blob.centroid_px = blob.binary_centroid_px;
      // Polar moment of the pixels as unit squares (each adds 1/6 about its own centre).
      const double mu20 = static_cast<double>(comp.m20) - static_cast<double>(comp.m10) * cx;
      const double mu02 = static_cast<double>(comp.m02) - static_cast<double>(comp.m01) * cy;
      const double polar = mu20 + mu02 + m00 / 6.0;
      blob.circularity = m00 * m00 / (2.0 * CV_PI * polar);
      // 6. Colour statistics and the soft centroid, for blobs that may be the marker.
      if (blob.circularity >= params_.min_circularity) {
        measure(filtered, mask, static_cast<int>(i), box, labelled.tl(), extended.tl(), &blob);
        if (blob.rim_placed) blob.centroid_px = blob.rim->centre_px;  // Over the soft centroid.
      }
    }
    blobs->push_back(blob);
  }
}

void ColourTracker::FillHoles(cv::Mat& own, cv::Point own_origin, ColourBlob* blob) {
  // A hole is a part of the blob's background that does not reach the outside: a specular
  // highlight on a glossy marker, a glint, pixels noise pushed out of the range. They are part of
  // the marker: its area, centroid and shape are the filled region's, and its colour and ring
  // are measured around the filled region (a highlight inside is not its surroundings).
  // `own` holds 0 and 255: its outside is marked in place, then the holes are filled and the
  // outside cleared again in one pass.
  constexpr uchar kOutside = 1;
  static_assert(kOutside != kFilledHole && kOutside != 255);
  MarkOutside(own, kOutside, outside_stack_);
  int filled = 0;
  for (int y = 0; y < own.rows; ++y) {
    uchar* w = own.ptr<uchar>(y);
    for (int x = 0; x < own.cols; ++x) {
      if (w[x] == 0) {
        w[x] = kFilledHole;
        ++filled;
      } else if (w[x] == kOutside) {
        w[x] = 0;
      }
    }
  }
  if (filled == 0) return;
  const cv::Moments m = cv::moments(own, true);
  if (!(m.m00 > 0)) return;
  blob->area_px = m.m00;
  blob->binary_centroid_px =
      cv::Point2d(m.m10 / m.m00 + own_origin.x, m.m01 / m.m00 + own_origin.y);
  blob->centroid_px = blob->binary_centroid_px;
  blob->circularity = m.m00 * m.m00 / (2.0 * CV_PI * (m.mu20 + m.mu02 + m.m00 / 6.0));
}

namespace {

// Distances to a blob's edge, in thirds of a pixel (EdgeZones): `near` is within kSoftBand of the
// edge, `reach` within kRingOuter outside it. Only those comparisons are read, so EdgeZones'
// stand-in, which answers them as ChamferToEdge's distance does, serves.
constexpr int kNearThirds = 3 * kSoftBand, kReachThirds = 3 * kRingOuter;
static_assert(kNearThirds == kZoneNear && kReachThirds == kZoneReach && kZoneFar > kReachThirds);
// The ring's second moments are kept per quarter (four sectors each), for the contrast.
constexpr int kRingQuarters = 4;

// The local background varies around a marker (the body's edge, texture): the ring is split into
// kSectors angular sectors about the blob's centroid, and an edge pixel's background is
// interpolated between the two sectors nearest its direction. The sector of pixel (x, y), as a
// continuous coordinate in [0, kSectors).
struct RingSectors {
  cv::Point2d centre;  // The blob's binary centroid, in the pixels' coordinates.
  // Inlined: with the flat variants of its two callers GCC made it a call per ring pixel.
  [[gnu::always_inline]] double operator()(int x, int y) const {
    const double u = DiamondAngle(x - centre.x, y - centre.y) * (kSectors / 4.0);
    return std::clamp(u, 0.0, kSectors - 1e-9);
  }
};

// Whether the blob `own` (255) has pixels deeper than kSoftBand inside its edge.
bool HasDeepCore(const cv::Mat& own, const cv::Mat& distance) {
  for (int y = 0; y < own.rows; ++y) {
    const uchar* ow = own.ptr<uchar>(y);
    const uchar* d = distance.ptr<uchar>(y);
    for (int x = 0; x < own.cols; ++x) {
      if (ow[x] == 255 && d[x] > kNearThirds) return true;
    }
  }
  return false;
}

// Pass 1 of a blob's measurement: the colour of its core and of the ring around it, overall, per
// sector and per quarter of the ring, and (colour only) the same in chromaticity.
struct RingStatistics {
  cv::Vec3d core_sum, core_sq, ring_sum, ring_sq;
  // Second moments (lower triangle) of the core and of each quarter of the ring.
  cv::Matx33d core_outer = cv::Matx33d::zeros();
  std::array<cv::Matx33d, kRingQuarters> quarter_outer{};
  std::array<cv::Vec3d, kSectors> sector_sum{};
  std::array<int, kSectors> sector_n{};
  double core_n = 0, ring_n = 0;
  // In chromaticity: the core's and each quarter's sum and second moments.
  cv::Vec3d core_chroma_sum = cv::Vec3d(0, 0, 0);
  cv::Matx33d core_chroma_outer = cv::Matx33d::zeros();
  std::array<cv::Vec3d, kRingQuarters> quarter_chroma_sum{};
  std::array<cv::Matx33d, kRingQuarters> quarter_chroma_outer{};
};

// Inlined: GCC left it a call per pixel of the loop below (issue 45; a few percent of it).
[[gnu::always_inline]] inline void AddChromaticity(const uchar* c, cv::Vec3d& sum,
                                                   cv::Matx33d& outer) {
  const cv::Vec3d chroma = ChromaticityOfLevels(c[0], c[1], c[2]);
  sum += chroma;
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l <= k; ++l) outer(k, l) += chroma[k] * chroma[l];
  }
}

// AddChromaticity's first channel of the flat pixel (v, v, v): its sum and its product (0, 0),
// the same numbers the three channels' add (GatherRingStatisticsOf copies them over).
[[gnu::always_inline]] inline void AddFlatChromaticity(int v, cv::Vec3d& sum, cv::Matx33d& outer) {
  const double chroma = ChromaticityOfLevels(v, v, v)[0];
  sum[0] += chroma;
  outer(0, 0) += chroma * chroma;
}

// Adds a pixel's levels to integer sums and lower-triangle second moments: (0,0) (1,0) (1,1)
// (2,0) (2,1) (2,2).
void AddLevels(const uchar* c, int channels, int64_t* sum, int64_t* outer) {
  if (channels == 3) {
    const int b = c[0], g = c[1], r = c[2];
    sum[0] += b;
    sum[1] += g;
    sum[2] += r;
    outer[0] += b * b;
    outer[1] += g * b;
    outer[2] += g * g;
    outer[3] += r * b;
    outer[4] += r * g;
    outer[5] += r * r;
  } else {
    sum[0] += c[0];
    outer[0] += c[0] * c[0];
  }
}

int LowerTriangle(int k, int l) { return k * (k + 1) / 2 + l; }

// Pass 1 over the padded box: `pixels` (filtered), `own` (the blob, 255), `distance` (its edge
// zones), `others` (every blob of the mask). Core pixels are the blob's deeper than `core_depth`
// (a filled hole is not the marker's colour); ring pixels lie outside every blob, beyond the soft
// band and within the ring's reach.
// The channels are a constant of the template (3 or 1), as in SoftCentroidSumsOf. With kFlat,
// `pixels` is a flat region's one plane (ColourTracker::flat_pixels_), each level v the BGR
// pixel (v, v, v): every channel's sum, every second moment and every chromaticity's sum and
// product then adds the same numbers in the same order, so the first is accumulated and copied
// to the others at the end, bit for bit what the three channels give.
template <int kChannels, bool kFlat = false>
RingStatistics GatherRingStatisticsOf(const cv::Mat& pixels, const cv::Mat& own,
                                      const cv::Mat& distance, const cv::Mat& others,
                                      int core_depth, const RingSectors& sector_of) {
  static_assert(!kFlat || kChannels == 3);
  RingStatistics s;
  constexpr int channels = kChannels;
  constexpr int stored = kFlat ? 1 : kChannels;  // Bytes a pixel in `pixels`.
  constexpr bool chromatic = channels == 3;
  // The levels' sums and second moments are sums of integers, accumulated as integers: every
  // partial sum of the doubles they were summed in before was an exact integer (far below 2^53),
  // so the totals are the same bits in any order. Ring sums per sector, second moments per
  // quarter.
  std::array<int64_t, 3> core_sum_i{};
  std::array<int64_t, 6> core_outer_i{};
  std::array<std::array<int64_t, 3>, kSectors> sector_sum_i{};
  std::array<std::array<int64_t, 6>, kRingQuarters> quarter_outer_i{};
  // The core's chromaticity sums in locals (registers), not through `s`, which the compiler
  // cannot keep out of memory across the loop.
  cv::Vec3d core_chroma_sum = s.core_chroma_sum;
  cv::Matx33d core_chroma_outer = s.core_chroma_outer;
  // Counts as integers (a double's count of ones is that integer exactly).
  int core_n = 0, ring_n = 0;
  for (int y = 0; y < own.rows; ++y) {
    const uchar* p = pixels.ptr<uchar>(y);
    const uchar* ow = own.ptr<uchar>(y);
    const uchar* d = distance.ptr<uchar>(y);
    const uchar* ot = others.ptr<uchar>(y);
    const auto core_pixel = [&](int x) {
      const uchar* c = p + x * stored;
      AddLevels(c, stored, core_sum_i.data(), core_outer_i.data());
      if (kFlat) {
        AddFlatChromaticity(c[0], core_chroma_sum, core_chroma_outer);
      } else if (chromatic) {
        AddChromaticity(c, core_chroma_sum, core_chroma_outer);
      }
      ++core_n;
    };
    const auto ring_pixel = [&](int x) {
      const uchar* c = p + x * stored;
      const int sector = static_cast<int>(sector_of(x, y));
      AddLevels(c, stored, sector_sum_i[sector].data(),
                quarter_outer_i[sector * kRingQuarters / kSectors].data());
      const int quarter = sector * kRingQuarters / kSectors;
      if (kFlat) {
        AddFlatChromaticity(c[0], s.quarter_chroma_sum[quarter], s.quarter_chroma_outer[quarter]);
      } else if (chromatic) {
        AddChromaticity(c, s.quarter_chroma_sum[quarter], s.quarter_chroma_outer[quarter]);
      }
      ++s.sector_n[sector];
      ++ring_n;
    };
    int x = 0;
#if CV_SIMD128
    // 16 pixels sorted at once into the core's and the ring's, each then visited by its bit, in
    // raster order (the core's and the ring's sums are apart, so each adds its pixels in the
    // order the loop below would): most of the padded box is neither, and the tests pixel by
    // pixel were a third of the pass (issue 45).
    for (; x + 16 <= own.cols; x += 16) {
      using namespace cv;
      const v_uint8x16 o = v_load(ow + x), dd = v_load(d + x), t = v_load(ot + x);
      const v_uint8x16 zero = v_setzero_u8();
      const v_uint8x16 core = (o == v_setall_u8(255)) &
                              (dd > v_setall_u8(static_cast<uchar>(core_depth)));
      const v_uint8x16 ring = (o == zero) & (dd > v_setall_u8(kNearThirds)) &
                              (dd <= v_setall_u8(kReachThirds)) & (t == zero);
      for (unsigned bits = static_cast<unsigned>(v_signmask(core)); bits; bits &= bits - 1) {
        core_pixel(x + __builtin_ctz(bits));
      }
      for (unsigned bits = static_cast<unsigned>(v_signmask(ring)); bits; bits &= bits - 1) {
        ring_pixel(x + __builtin_ctz(bits));
      }
    }
#endif
    for (; x < own.cols; ++x) {
      if (ow[x] == 255 && d[x] > core_depth) {
        core_pixel(x);
      } else if (!ow[x] && d[x] > kNearThirds && d[x] <= kReachThirds && !ot[x]) {
        ring_pixel(x);
      }
    }
  }
  if (kFlat) {  // The first channel's sums and moments are every channel's.
    const auto copy = [](int64_t* sum, int64_t* outer) {
      sum[1] = sum[2] = sum[0];
      for (int i = 1; i < 6; ++i) outer[i] = outer[0];
    };
    const auto copy_chroma = [](cv::Vec3d& sum, cv::Matx33d& outer) {
      sum[1] = sum[2] = sum[0];
      for (int k = 0; k < 3; ++k) {
        for (int l = 0; l <= k; ++l) outer(k, l) = outer(0, 0);
      }
    };
    copy(core_sum_i.data(), core_outer_i.data());
    for (int i = 0; i < kSectors; ++i) sector_sum_i[i][1] = sector_sum_i[i][2] = sector_sum_i[i][0];
    for (int q = 0; q < kRingQuarters; ++q) {
      for (int i = 1; i < 6; ++i) quarter_outer_i[q][i] = quarter_outer_i[q][0];
      copy_chroma(s.quarter_chroma_sum[q], s.quarter_chroma_outer[q]);
    }
    copy_chroma(core_chroma_sum, core_chroma_outer);
  }
  s.core_chroma_sum = core_chroma_sum;
  s.core_chroma_outer = core_chroma_outer;
  s.core_n = core_n;
  s.ring_n = ring_n;
  for (int k = 0; k < channels; ++k) {
    s.core_sum[k] = static_cast<double>(core_sum_i[k]);
    s.core_sq[k] = static_cast<double>(core_outer_i[LowerTriangle(k, k)]);
    for (int l = 0; l <= k; ++l) {
      s.core_outer(k, l) = static_cast<double>(core_outer_i[LowerTriangle(k, l)]);
    }
    int64_t ring_total = 0, ring_squares = 0;
    for (int i = 0; i < kSectors; ++i) {
      s.sector_sum[i][k] = static_cast<double>(sector_sum_i[i][k]);
      ring_total += sector_sum_i[i][k];
    }
    for (int q = 0; q < kRingQuarters; ++q) {
      ring_squares += quarter_outer_i[q][LowerTriangle(k, k)];
      for (int l = 0; l <= k; ++l) {
        s.quarter_outer[q](k, l) = static_cast<double>(quarter_outer_i[q][LowerTriangle(k, l)]);
      }
    }
    s.ring_sum[k] = static_cast<double>(ring_total);
    s.ring_sq[k] = static_cast<double>(ring_squares);
  }
  return s;
}

RingStatistics GatherRingStatistics(const cv::Mat& pixels, bool flat, const cv::Mat& own,
                                    const cv::Mat& distance, const cv::Mat& others, int core_depth,
                                    const RingSectors& sector_of) {
  if (flat) {
    return GatherRingStatisticsOf<3, true>(pixels, own, distance, others, core_depth, sector_of);
  }
  return pixels.channels() == 3
             ? GatherRingStatisticsOf<3>(pixels, own, distance, others, core_depth, sector_of)
             : GatherRingStatisticsOf<1>(pixels, own, distance, others, core_depth, sector_of);
}

// The spread (RMS) along `direction` of `n` values with mean `mean` and second moments `second`
// (lower triangle; `dims` channels). 0 for no direction or no values.
double SpreadAlong(const cv::Vec3d& direction, const cv::Matx33d& second, const cv::Vec3d& mean,
                   double n, int dims) {
  const double length = std::sqrt(direction.dot(direction));
  if (!(length > 0) || !(n > 0)) return 0.0;
  const cv::Vec3d u = direction / length;
  double variance = 0;
  for (int k = 0; k < dims; ++k) {
    for (int l = 0; l < dims; ++l) {
      const double moment = (k >= l ? second(k, l) : second(l, k)) / n;
      variance += u[k] * u[l] * (moment - mean[k] * mean[l]);
    }
  }
  return std::sqrt(std::max(0.0, variance));
}

// The contrast in chromaticity of the blob's core against ring pixels whose chromaticities sum
// to `ring_sum` (second moments `ring_outer`, `n` of them): 0 where the blob's chromaticity
// differs from theirs by less than `min_span`.
double ChromaContrast(const RingStatistics& s, const cv::Vec3d& ring_sum,
                      const cv::Matx33d& ring_outer, double n, double min_span) {
  const cv::Vec3d core_chroma = s.core_chroma_sum / s.core_n;
  const cv::Vec3d ring_chroma = ring_sum / n;
  const cv::Vec3d direction = core_chroma - ring_chroma;
  const double distance = std::sqrt(direction.dot(direction));
  if (distance < min_span) return 0.0;
  const double core_along = SpreadAlong(direction, s.core_chroma_outer, core_chroma, s.core_n, 3);
  const double ring_along = SpreadAlong(direction, ring_outer, ring_chroma, n, 3);
  return distance / (kCoreSigmaWeight * core_along + ring_along + kChromaNoiseFloor);
}

// The median of `count` values (at most four: insertion sort), sorting them.
double MedianOfFew(std::array<double, kRingQuarters>& values, int count) {
  for (int a = 1; a < count; ++a) {
    for (int b = a; b > 0 && values[b - 1] > values[b]; --b) std::swap(values[b - 1], values[b]);
  }
  return count % 2 ? values[count / 2] : 0.5 * (values[count / 2 - 1] + values[count / 2]);
}

// The blob's contrast (ColourBlob::contrast, whole_ring_contrast) from its core and ring colours
// and the ring's statistics; `axis2` is |core colour - ring colour|^2.
//
// The contrast is judged against each quarter of the ring on its own, along the colour axis that
// separates the marker from that quarter, with that quarter's spread along it: a marker at an
// actuator's edge has a bright band on one side and the body's shaded ribs on the other, and the
// spread of the two together (or shading across the ring, which spreads it along grey while a
// dim saturated marker differs in chroma) would hide a marker a person sees plainly. The median
// over the quarters: a patch of background texture stands out from few of them.
void SetContrast(const RingStatistics& s, int channels, double axis2, ColourBlob* blob) {
  const bool chromatic = channels == 3;
  std::array<double, kRingQuarters> quarter_contrast{};
  int quarters = 0;
  for (int q = 0; q < kRingQuarters; ++q) {
    cv::Vec3d sum(0, 0, 0);
    int n = 0;
    for (int i = q * kSectors / kRingQuarters; i < (q + 1) * kSectors / kRingQuarters; ++i) {
      sum += s.sector_sum[i];
      n += s.sector_n[i];
    }
    if (n < 3) continue;
    const cv::Vec3d mean = sum / n;
    const cv::Vec3d direction = blob->core_colour - mean;
    const double core_along =
        SpreadAlong(direction, s.core_outer, blob->core_colour, s.core_n, channels);
    const double ring_along = SpreadAlong(direction, s.quarter_outer[q], mean, n, channels);
    double contrast = std::sqrt(direction.dot(direction)) /
                      (kCoreSigmaWeight * core_along + ring_along + kContrastNoiseFloor);
    if (chromatic) {
      // A marker differs from its surroundings in chroma where light and texture vary them in
      // brightness: a dim blue dome beside the shaded ribs and lit band of a side-lit body, a
      // green one on speckled silicone. Their dark and bright pixels spread the levels along the
      // marker's direction, not its chromaticity.
      contrast = std::max(contrast, ChromaContrast(s, s.quarter_chroma_sum[q],
                                                   s.quarter_chroma_outer[q], n,
                                                   kMinChromaContrastSpan));
    }
    quarter_contrast[quarters++] = contrast;
  }
  blob->whole_ring_contrast =
      std::sqrt(axis2) /
      (kCoreSigmaWeight * blob->core_sigma + blob->ring_sigma + kContrastNoiseFloor);
  if (chromatic) {
    // Against the whole ring in chroma too: a coloured marker on speckled or shaded silicone
    // stands out in chroma from all of its surroundings at once, while their dark and bright
    // pixels spread the levels; a patch of the bench's texture differs from them in brightness,
    // its chroma about the same (kMinWholeRingChromaSpan).
    cv::Vec3d ring_chroma_sum(0, 0, 0);
    cv::Matx33d ring_chroma_outer = cv::Matx33d::zeros();
    for (int q = 0; q < kRingQuarters; ++q) {
      ring_chroma_sum += s.quarter_chroma_sum[q];
      ring_chroma_outer += s.quarter_chroma_outer[q];
    }
    blob->whole_ring_contrast =
        std::max(blob->whole_ring_contrast, ChromaContrast(s, ring_chroma_sum, ring_chroma_outer,
                                                           s.ring_n, kMinWholeRingChromaSpan));
  }
  blob->contrast = quarters == 0 ? blob->whole_ring_contrast
                                 : MedianOfFew(quarter_contrast, quarters);
}

// Weighted sums of the soft centroid over the padded box, in its coordinates.
struct WeightedSums {
  double w = 0, x = 0, y = 0;
};

// Pass 2: the soft centroid. Deep inside counts 1; near the edge, the membership: where the
// pixel's colour lies between its local background (0) and the core colour (1), on the line
// through them. Pixels of other blobs count 0.
// The channels are a constant of the template (3 or 1): the per-channel loops below unroll, the
// same operations in the same order as with a count known only at run time (issue 45).
// With kFlat, `pixels` is a flat region's plane (see GatherRingStatisticsOf): a level is read
// once and handed on as its three channels.
template <int kChannels, bool kFlat = false>
WeightedSums SoftCentroidSumsOf(const cv::Mat& pixels, const cv::Mat& own,
                                const cv::Mat& distance, const cv::Mat& others,
                                const RingSectors& sector_of, const RingStatistics& s,
                                const ColourBlob& blob) {
  static_assert(!kFlat || kChannels == 3);
  constexpr int channels = kChannels;
  constexpr int stored = kFlat ? 1 : kChannels;
  std::array<cv::Vec3d, kSectors> sector_mean;
  for (int i = 0; i < kSectors; ++i) {
    sector_mean[i] = s.sector_n[i] >= 2 ? s.sector_sum[i] / s.sector_n[i] : blob.ring_colour;
  }
  const cv::Vec3d& f = blob.core_colour;
  WeightedSums sums;
  for (int y = 0; y < own.rows; ++y) {
    const uchar* p = pixels.ptr<uchar>(y);
    const uchar* ow = own.ptr<uchar>(y);
    const uchar* dist = distance.ptr<uchar>(y);
    const uchar* ot = others.ptr<uchar>(y);
    double row_w = 0, row_x = 0;
    // A pixel's weight: 1 deep inside, its membership in the band (of its own blob or outside
    // every other one); others add nothing.
    const auto add = [&](int x) {
      double w = 1.0;
      if (!(ow[x] && dist[x] > kNearThirds)) {
        const uchar* at = p + x * stored;
        const uchar flat[3] = {at[0], at[0], at[0]};
        const uchar* c = kFlat ? flat : at;
        // Sector centres sit at i + 0.5.
        const double u = sector_of(x, y) - 0.5;
        const double lower = std::floor(u);
        const double t = u - lower;
        const int i0 = (static_cast<int>(lower) + kSectors) % kSectors;
        const int i1 = (i0 + 1) % kSectors;
        double background[3], core[3];
        for (int k = 0; k < channels; ++k) {
          background[k] = (1 - t) * sector_mean[i0][k] + t * sector_mean[i1][k];
          core[k] = f[k];
        }
        w = track_internal::Membership(c, channels, background, core, kMembershipDeadband,
                                       ow[x] != 0);
      }
      row_w += w;
      row_x += w * x;
    };
    int x = 0;
#if CV_SIMD128
    // 16 pixels sorted at once, those that weigh visited by their bits in raster order (the
    // same sums in the same order): beyond the band, most of the padded box, adds nothing.
    for (; x + 16 <= own.cols; x += 16) {
      using namespace cv;
      const v_uint8x16 zero = v_setzero_u8();
      const v_uint8x16 in = v_load(ow + x) != zero;
      const v_uint8x16 beyond = v_load(dist + x) > v_setall_u8(kNearThirds);
      const v_uint8x16 weighs = (in & beyond) | (~beyond & (in | (v_load(ot + x) == zero)));
      for (unsigned bits = static_cast<unsigned>(v_signmask(weighs)); bits; bits &= bits - 1) {
        add(x + __builtin_ctz(bits));
      }
    }
#endif
    for (; x < own.cols; ++x) {
      if (!ow[x] && dist[x] > kNearThirds) continue;  // Beyond the band.
      if (!(ow[x] && dist[x] > kNearThirds) && ot[x] && !ow[x]) continue;  // Another blob's.
      add(x);
    }
    sums.w += row_w;
    sums.x += row_x;
    sums.y += row_w * y;
  }
  return sums;
}

WeightedSums SoftCentroidSums(const cv::Mat& pixels, bool flat, const cv::Mat& own,
                              const cv::Mat& distance, const cv::Mat& others,
                              const RingSectors& sector_of, const RingStatistics& s,
                              const ColourBlob& blob) {
  if (flat) {
    return SoftCentroidSumsOf<3, true>(pixels, own, distance, others, sector_of, s, blob);
  }
  return pixels.channels() == 3
             ? SoftCentroidSumsOf<3>(pixels, own, distance, others, sector_of, s, blob)
             : SoftCentroidSumsOf<1>(pixels, own, distance, others, sector_of, s, blob);
}

}  // namespace

void ColourTracker::measure(const cv::Mat& filtered, const cv::Mat& mask, int component,
                            const cv::Rect& box, cv::Point labelled_tl, cv::Point origin,
                            ColourBlob* blob) {
  // The blob's box in `filtered`, padded by the ring's reach.
  const cv::Rect box_local = box + labelled_tl;
  const cv::Rect padded =
      cv::Rect(box_local.x - kRingOuter - 1, box_local.y - kRingOuter - 1,
               box_local.width + 2 * kRingOuter + 2, box_local.height + 2 * kRingOuter + 2) &
      cv::Rect(cv::Point(0, 0), filtered.size());
  const cv::Size size = padded.size();
  cv::Mat own = Scratch(blob_store_, size, CV_8U);
  for (int y = 0; y < size.height; ++y) {
    std::memset(own.ptr<uchar>(y), 0, static_cast<size_t>(size.width));
  }
  labeller_.Draw(component, own, padded.tl() - labelled_tl);
  // A hole pixel has the blob on its left and on its right in its row (else its row would join
  // it to the outside): a blob of one run in each of its rows (a disc, most markers) has none.
  const RunLabeller::Component& drawn = labeller_.components()[static_cast<size_t>(component)];
  if (drawn.run_count > drawn.box.height) FillHoles(own, padded.tl() + origin, blob);
  measure_asymmetry(component, padded.tl() - labelled_tl, padded.tl() + origin, blob);
  cv::Mat distance = Scratch(distance_store_, size, CV_8U);
  EdgeZones(own, distance, zone_store_);
  const cv::Mat pixels = filtered(padded);
  const cv::Mat others = mask(padded);
  const int channels = flat_pixels_ ? 3 : pixels.channels();
  const RingSectors sector_of{blob->binary_centroid_px - cv::Point2d(padded.tl() + origin)};

  // The core: deeper than kSoftBand, or the whole blob when it is too small to have such pixels.
  const bool pure_core = HasDeepCore(own, distance);
  const int core_depth = pure_core ? kNearThirds : 0;
  const RingStatistics s = GatherRingStatistics(pixels, flat_pixels_, own, distance, others,
                                                core_depth, sector_of);
  if (s.core_n < 1 || s.ring_n < 3) return;  // Crowded by other blobs: no local background.
  double core_var = 0, ring_var = 0;
  for (int k = 0; k < channels; ++k) {
    blob->core_colour[k] = s.core_sum[k] / s.core_n;
    blob->ring_colour[k] = s.ring_sum[k] / s.ring_n;
    core_var +=
        std::max(0.0, s.core_sq[k] / s.core_n - blob->core_colour[k] * blob->core_colour[k]);
    ring_var +=
        std::max(0.0, s.ring_sq[k] / s.ring_n - blob->ring_colour[k] * blob->ring_colour[k]);
  }
  blob->core_px = pure_core ? static_cast<int>(s.core_n) : 0;
  blob->core_sigma = std::sqrt(core_var);
  blob->ring_sigma = std::sqrt(ring_var);
  const cv::Vec3d axis = blob->core_colour - blob->ring_colour;
  const double axis2 = axis.dot(axis);
  SetContrast(s, channels, axis2, blob);
  blob->measured = true;
  measure_fringe(pixels, own, distance, others, padded.tl() + origin, blob);
  // A round marker partly hidden: the circle of its radius through its edge (not where the
  // frame cuts it).
  if (const std::optional<double> radius = rim_radius_px();
      radius && blob->area_px < kWholeRimFraction * model_->area_px) {
    fit_rim(own, component, padded.tl() - labelled_tl, padded.tl() + origin, *radius, blob);
  }
  if (params_.centroid == ColourParams::Centroid::kBinary || axis2 < 1.0) return;
  const WeightedSums sums =
      SoftCentroidSums(pixels, flat_pixels_, own, distance, others, sector_of, s, *blob);
  if (sums.w <= 0) return;
  // Offsets added as one integer: the same blob in a window and in the whole frame gives the
  // same bits.
  blob->centroid_px = cv::Point2d(sums.x / sums.w + (padded.x + origin.x),
                                  sums.y / sums.w + (padded.y + origin.y));
  if (fringe_places_ && !blob->rim_placed) {
    blob->centroid_px += blob->fringe_pull_px;
    blob->fringe_placed = true;
  }
}

void ColourTracker::measure_fringe(const cv::Mat& pixels, const cv::Mat& own,
                                   const cv::Mat& distance, const cv::Mat& others,
                                   cv::Point own_origin, ColourBlob* blob) {
  // The relaxed range over the whole padded box at once (the vector classifier), read where the
  // ring reaches. `pixels` has the channels of the tracker's mode (prepare()), or is a flat
  // region's plane (flat_pixels_).
  cv::Mat relaxed = Scratch(fringe_store_, pixels.size(), CV_8U);
  if (gray_) {
    cv::inRange(pixels, fringe_gray_.lo, fringe_gray_.hi, relaxed);
  } else if (flat_pixels_) {
    fringe_hsv_.ClassifyFlat(pixels, relaxed);
  } else {
    fringe_hsv_.Classify(pixels, relaxed);
  }
  // All of the fringe (the sigma's term), and its part beyond the soft band (the position's:
  // the band's pixels already weigh in the soft centroid by their membership, and an
  // anti-aliased rim's row of half-saturated pixels is no fringe: counted again, it moved a
  // clean rendered disc's soft centroid by 0.05 px RMS).
  double n = 0, sx = 0, sy = 0, far_n = 0, far_sx = 0, far_sy = 0;
  for (int y = 0; y < own.rows; ++y) {
    const uchar* in = relaxed.ptr<uchar>(y);
    const uchar* ow = own.ptr<uchar>(y);
    const uchar* d = distance.ptr<uchar>(y);
    const uchar* ot = others.ptr<uchar>(y);
    int row_n = 0, row_sx = 0, far_row_n = 0, far_row_sx = 0;
    int x = 0;
#if CV_SIMD128
    // 16 pixels tested at once, the fringe's visited by their bits (integer sums: any order).
    for (; x + 16 <= own.cols; x += 16) {
      using namespace cv;
      const v_uint8x16 zero = v_setzero_u8();
      const v_uint8x16 dist = v_load(d + x);
      const v_uint8x16 fringe = (v_load(in + x) != zero) & (v_load(ow + x) == zero) &
                                (v_load(ot + x) == zero) & (dist <= v_setall_u8(kReachThirds));
      for (unsigned bits = static_cast<unsigned>(v_signmask(fringe)); bits; bits &= bits - 1) {
        ++row_n, row_sx += x + __builtin_ctz(bits);
      }
      const v_uint8x16 far = fringe & (dist > v_setall_u8(kNearThirds));
      for (unsigned bits = static_cast<unsigned>(v_signmask(far)); bits; bits &= bits - 1) {
        ++far_row_n, far_row_sx += x + __builtin_ctz(bits);
      }
    }
#endif
    for (; x < own.cols; ++x) {
      // In the relaxed range, not the blob or another, within the ring's reach.
      if (!in[x] || ow[x] || ot[x] || d[x] > kReachThirds) continue;
      ++row_n, row_sx += x;
      if (d[x] > kNearThirds) ++far_row_n, far_row_sx += x;
    }
    n += row_n, sx += row_sx, sy += static_cast<double>(row_n) * y;
    far_n += far_row_n, far_sx += far_row_sx, far_sy += static_cast<double>(far_row_n) * y;
  }
  if (n == 0) return;
  const cv::Point2d centre = blob->binary_centroid_px - cv::Point2d(own_origin);
  blob->fringe_shift_px = cv::norm(cv::Point2d(sx / n, sy / n) - centre) * n / (blob->area_px + n);
  if (far_n == 0) return;
  blob->fringe_pull_px =
      (cv::Point2d(far_sx / far_n, far_sy / far_n) - centre) * (far_n / (blob->area_px + far_n));
}

void ColourTracker::measure_asymmetry(int component, cv::Point own_tl, cv::Point own_origin,
                                      ColourBlob* blob) {
  // The binary centroid against the centre of the smallest circle around the blob (its convex
  // hull's points are among each row's leftmost and rightmost pixels). A row's ends are its
  // first run's start and its last run's end (the runs are in raster order; a filled hole lies
  // between them), in the blob's mask's coordinates: the same points a scan of the mask finds,
  // without the scan (issue 45).
  edge_points_.clear();
  const RunLabeller::Component& comp = labeller_.components()[static_cast<size_t>(component)];
  const RunLabeller::Run* runs = labeller_.runs().data() + comp.first_run;
  for (int k = 0; k < comp.run_count;) {
    const int y = runs[k].y;
    const int first = runs[k].x0 - own_tl.x;
    while (k + 1 < comp.run_count && runs[k + 1].y == y) ++k;
    const int last = runs[k].x1 - 1 - own_tl.x;
    ++k;
    edge_points_.emplace_back(first, y - own_tl.y);
    if (last != first) edge_points_.emplace_back(last, y - own_tl.y);
  }
  if (edge_points_.empty()) return;
  // The smallest enclosing circle of the points is that of their convex hull's vertices: a
  // fraction of the points, and OpenCV's incremental algorithm costs about the square of their
  // number in raster order (issue 45).
  cv::convexHull(edge_points_, hull_points_);
  cv::Point2f circle_centre;
  float circle_radius = 0.0f;
  cv::minEnclosingCircle(hull_points_, circle_centre, circle_radius);
  const cv::Point2d binary_centre = blob->binary_centroid_px - cv::Point2d(own_origin);
  blob->asymmetry_px = cv::norm(cv::Point2d(circle_centre) - binary_centre);
  blob->enclosing_radius_px = circle_radius;
  blob->hull_asymmetry_px = blob->asymmetry_px;
  // The hull's asymmetry is read only of a blob more asymmetric than a learned marker by
  // kPartialMinPx at least (judge(): both must exceed the limit, which is never below it).
  if (blob->asymmetry_px <= kPartialMinPx) return;
  const cv::Moments hull = cv::moments(hull_points_);
  if (hull.m00 > 0) {
    const cv::Point2d hull_centre(hull.m10 / hull.m00, hull.m01 / hull.m00);
    blob->hull_asymmetry_px = cv::norm(cv::Point2d(circle_centre) - hull_centre);
  }
}

void ColourTracker::fit_rim(const cv::Mat& own, int component, cv::Point own_tl,
                            cv::Point frame_origin, double radius, ColourBlob* blob) {
  // The fit places the blob (RimCentre, the fit's one reader) only when the blob lies within its
  // circle's box, 2 (radius + 1) px on a side: a blob wider or taller than that is never placed
  // by any fit, and is not fitted (issue 45: such fits were 0.14M of the 1.47M instructions a
  // frame of the colour session on mire-2).
  const double reach = radius + 1.0;
  if (blob->bbox_px.width - 1 > 2 * reach || blob->bbox_px.height - 1 > 2 * reach) return;
  // The edge pixels in raster order: the blob's pixels with a 4-neighbour outside it, visited
  // along the component's runs (raster order) instead of over its whole box. A filled hole's
  // pixels (not in the runs) are never edge pixels: their 4-neighbours are the blob or the hole.
  edge_points_.clear();
  const RunLabeller::Component& comp = labeller_.components()[static_cast<size_t>(component)];
  const RunLabeller::Run* runs = labeller_.runs().data() + comp.first_run;
  // Pixels on the frame's edge are left out (the frame cut the blob there, not a cover): a row
  // on it at once, its first and last columns pixel by pixel.
  for (int k = 0; k < comp.run_count; ++k) {
    const int y = runs[k].y - own_tl.y;
    const int fy = y + frame_origin.y;
    if (fy == 0 || fy == frame_size_.height - 1) continue;
    const uchar* ow = own.ptr<uchar>(y);
    const bool border_row = y == 0 || y == own.rows - 1;  // Then no row above or below.
    const uchar* up = border_row ? ow : own.ptr<uchar>(y - 1);
    const uchar* down = border_row ? ow : own.ptr<uchar>(y + 1);
    for (int x = runs[k].x0 - own_tl.x; x < runs[k].x1 - own_tl.x; ++x) {
      const bool edge = border_row || x == 0 || x == own.cols - 1 || !ow[x - 1] || !ow[x + 1] ||
                        !up[x] || !down[x];
      const int fx = x + frame_origin.x;
      if (edge && fx != 0 && fx != frame_size_.width - 1) edge_points_.emplace_back(fx, fy);
    }
  }
  rim_points_.assign(edge_points_.begin(), edge_points_.end());
  blob->rim = FitRimOfRadius(rim_points_, radius, kRimInlierPx, &rim_angles_);
  // A whole marker seen at a slant (an ellipse narrower than the learned disc) fits the circle
  // along part of its edge too; the rest of its edge bulges outwards where a cut's is straight
  // or pushed in. Its centroid is its centre.
  if (blob->rim) {
    const std::optional<double> bulge =
        OffRimBulgePx(rim_points_, *blob->rim, radius, kRimInlierPx, &off_rim_);
    if (bulge && *bulge > kMaxCutBulgePx) blob->rim.reset();
  }
  if (const std::optional<cv::Point2d> centre = RimCentre(*blob)) {
    blob->centroid_px = *centre;
    blob->rim_placed = true;
  }
}

void ColourTracker::complete_blobs(const cv::Mat& frame, cv::Rect region,
                                   std::vector<ColourBlob>* blobs) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  region &= frame_rect;
  for (int round = 0; round < kMaxGrowRounds && !region.empty(); ++round) {
    pending_.clear();
    analyse(frame, region, &pending_);
    cv::Rect grown = region;
    bool clipped = false;
    const int pad = std::max(16, std::min(region.width, region.height) / 2);
    for (const ColourBlob& b : pending_) {
      if (!b.clipped) continue;
      clipped = true;
      grown |= cv::Rect(b.bbox_px.x - pad, b.bbox_px.y - pad, b.bbox_px.width + 2 * pad,
                        b.bbox_px.height + 2 * pad);
    }
    if (!clipped) {
      blobs->insert(blobs->end(), pending_.begin(), pending_.end());
      return;
    }
    region = grown & frame_rect;
  }
  // Something long and thin keeps leaving the region: the whole frame has no clipped blobs.
  pending_.clear();
  analyse(frame, frame_rect, &pending_);
  blobs->insert(blobs->end(), pending_.begin(), pending_.end());
}

namespace {

// One pixel per cell of factor x factor pixels of `src` into `sampled` (one pixel a cell): the
// pixel cv::resize's INTER_NEAREST_EXACT takes, (i + 1/2) * factor, copied directly.
void SampleCells(const cv::Mat& src, int factor, cv::Mat& sampled) {
  const int coarse_cols = sampled.cols, coarse_rows = sampled.rows;
  const int channels = src.channels(), half = factor / 2;
  const size_t row_bytes = static_cast<size_t>(src.cols) * channels;
  for (int y = 0; y < coarse_rows; ++y) {
    // The next sampled row is asked for while this one is copied: every factor-th row of a frame
    // not yet in the cache is a pattern the hardware prefetcher does not follow, and the copy
    // waited on every line.
    if (y + 1 < coarse_rows) {
      const uchar* ahead = src.ptr<uchar>((y + 1) * factor + half);
      for (size_t i = 0; i < row_bytes; i += 64) __builtin_prefetch(ahead + i);
    }
    const uchar* in = src.ptr<uchar>(y * factor + half) + half * channels;
    uchar* out = sampled.ptr<uchar>(y);
    const int step = factor * channels;
    if (channels == 3) {
      // Pixel by pixel as one copy: byte by byte, GCC built vectors from the bytes through the
      // stack, a stall per 16 bytes that cost as much as classifying them.
      for (int x = 0; x < coarse_cols; ++x, in += step, out += 3) std::memcpy(out, in, 3);
    } else {
      for (int x = 0; x < coarse_cols; ++x, in += step) out[x] = in[0];
    }
  }
}

// Drops the lit samples of `mask` with no lit 8-neighbour from `points`.
void DropLoneSamples(const cv::Mat& mask, std::vector<cv::Point>& points) {
  auto alone = [&](const cv::Point& p) {
    for (int y = std::max(0, p.y - 1); y <= std::min(mask.rows - 1, p.y + 1); ++y) {
      const uchar* row = mask.ptr<uchar>(y);
      for (int x = std::max(0, p.x - 1); x <= std::min(mask.cols - 1, p.x + 1); ++x) {
        if ((x != p.x || y != p.y) && row[x]) return false;
      }
    }
    return true;
  };
  points.erase(std::remove_if(points.begin(), points.end(), alone), points.end());
}

// Merges overlapping windows until none overlap, so a blob is analysed (and completed) once.
void MergeOverlappingWindows(std::vector<cv::Rect>& windows) {
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t a = 0; a < windows.size() && !merged; ++a) {
      for (size_t b = a + 1; b < windows.size(); ++b) {
        if ((windows[a] & windows[b]).empty()) continue;
        windows[a] |= windows[b];
        windows.erase(windows.begin() + static_cast<std::ptrdiff_t>(b));
        merged = true;
        break;
      }
    }
  }
}

}  // namespace

void ColourTracker::coarse_to_fine(const cv::Mat& frame, cv::Rect region, int factor,
                                   std::vector<ColourBlob>* blobs) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  region &= frame_rect;
  const int coarse_cols = region.width / factor;
  const int coarse_rows = region.height / factor;
  if (coarse_cols < 4 || coarse_rows < 4) {
    complete_blobs(frame, region, blobs);
    return;
  }
  // One pixel per cell of factor x factor pixels (its centre). Sampling, not averaging: a blob
  // of radius >= factor always holds several sample points, and a sample is a real pixel of the
  // frame, not a mix of marker and background. Columns beyond a multiple of the factor are
  // covered by the last cell's window below.
  const cv::Mat src = frame(cv::Rect(region.x, region.y, coarse_cols * factor, coarse_rows * factor));
  cv::Mat sampled = Scratch(coarse_store_, cv::Size(coarse_cols, coarse_rows), src.type());
  SampleCells(src, factor, sampled);
  const cv::Mat coarse = prepare(sampled, coarse_prepared_store_);
  cv::Mat mask = Scratch(coarse_mask_store_, coarse.size(), CV_8U);
  classify(coarse, true, mask);
  windows_.clear();
  NonZeroPoints(mask, points_);
  // A blob that can be the marker has radius >= factor (as acquire_downsample chooses it), so it
  // holds at least two 8-adjacent sample points: a lone lit sample is a speck of background texture.
  if (min_blob_radius_px() >= factor) DropLoneSamples(mask, points_);
  if (points_.empty()) return;
  cell_group_windows(region, factor, cv::Size(coarse_cols, coarse_rows), frame_rect);
  MergeOverlappingWindows(windows_);
  const size_t first = blobs->size();
  for (const cv::Rect& window : windows_) complete_blobs(frame, window, blobs);
  // Regions grown around clipped blobs may overlap: keep each blob once.
  std::sort(blobs->begin() + static_cast<std::ptrdiff_t>(first), blobs->end(), CentroidBefore);
  blobs->erase(std::unique(blobs->begin() + static_cast<std::ptrdiff_t>(first), blobs->end(),
                           SameBlob),
               blobs->end());
}

void ColourTracker::cell_group_windows(const cv::Rect& region, int factor, cv::Size cells_size,
                                       const cv::Rect& frame_rect) {
  const int coarse_cols = cells_size.width, coarse_rows = cells_size.height;
  // Group the candidate cells by tiles of kTile x kTile cells, 8-connected tiles together:
  // labelling a tile grid is ~60x cheaper than labelling the coarse mask itself.
  const cv::Size grid((coarse_cols + kTile - 1) / kTile, (coarse_rows + kTile - 1) / kTile);
  cv::Mat tiles = Scratch(tiles_store_, grid, CV_8U);
  tiles.setTo(0);
  for (const cv::Point& p : points_) tiles.at<uchar>(p.y / kTile, p.x / kTile) = 255;
  cv::Mat labels = Scratch(coarse_labels_store_, grid, CV_32S);
  int count = 0;
  cv::parallel_for_(cv::Range(0, 1), [&](const cv::Range&) {  // Inline: see analyse().
    count = cv::connectedComponentsWithStats(tiles, labels, coarse_stats_, coarse_centroids_, 8,
                                             CV_32S);
  });
  // The cells' own bounding box per tile group, so windows stay tight.
  boxes_.assign(static_cast<size_t>(count), cv::Rect());
  for (const cv::Point& p : points_) {
    cv::Rect& box = boxes_[static_cast<size_t>(labels.at<int>(p.y / kTile, p.x / kTile))];
    box = box.empty() ? cv::Rect(p.x, p.y, 1, 1) : (box | cv::Rect(p.x, p.y, 1, 1));
  }
  // Each group becomes a full-resolution window: its cells plus one cell all round.
  for (int i = 1; i < count; ++i) {
    const cv::Rect& cells = boxes_[static_cast<size_t>(i)];
    const int x0 = cells.x - 1, y0 = cells.y - 1;
    const int x1 = cells.x + cells.width + 1, y1 = cells.y + cells.height + 1;
    const int right = x1 >= coarse_cols ? region.width : x1 * factor;
    const int bottom = y1 >= coarse_rows ? region.height : y1 * factor;
    const cv::Rect window(region.x + x0 * factor, region.y + y0 * factor,
                          right - x0 * factor, bottom - y0 * factor);
    windows_.push_back(window & frame_rect);
  }
}

}  // namespace softsight
