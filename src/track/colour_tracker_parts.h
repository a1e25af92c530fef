// The colour tracker's constants and small helpers, shared by its three parts (private to the
// track module): colour_tracker.cc (the search: windows, acquisition, relearning, the motion it
// keeps), colour_blobs.cc (detection: classify, morphology, blobs and their statistics, holes,
// the rim fit), colour_verdicts.cc (verification: each candidate's verdict and misfit).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "track/colour_tracker_impl.h"

namespace softsight::colour_internal {

// Whole-frame style searches of regions at least this large use the coarse-to-fine path.
constexpr int kCoarseMinArea = 200 * 200;
// Leniency of the coarse test: it sees unfiltered pixels, which noise pushes a little off the
// marker's range where the filtered ones are inside it.
constexpr int kCoarseHueSlack = 8;
// Growing a region around a clipped blob gives up after this many rounds and analyses the frame.
constexpr int kMaxGrowRounds = 8;
// Coarse candidate cells are grouped by tiles of this many cells a side.
constexpr int kTile = 8;

// ---- Soft centroid and colour statistics (ColourBlob) ----------------------------------------------
// Pixels within this distance of the binary edge (inside or outside) are weighted by their
// membership; deeper ones count 1, the core colour is their mean. 2 px holds an anti-aliased
// edge blurred by a Gaussian of sigma ~1 px.
constexpr int kSoftBand = 2;
// The local background is the ring from kSoftBand + 1 to kRingOuter px outside the blob.
constexpr int kRingOuter = 4;
// Angular sectors of the ring (about the blob's centroid) that give each edge pixel its local
// background.
constexpr int kSectors = 16;
// Memberships within this of 0 or 1 snap to it (the rest is stretched linearly to keep 0.5 at
// 0.5): background texture and noise next to the marker then add no weight, while an edge,
// whose pixels' coverages spread evenly over 0..1, keeps its total weight and its centre.
constexpr double kMembershipDeadband = 0.12;
// Noise floor (gray levels) in the contrast's denominator: perfectly flat synthetic colours
// would otherwise make any difference infinitely significant.
constexpr double kContrastNoiseFloor = 2.0;
// The core's own spread counts half in the contrast: a marker's core varies by itself when the
// marker is blurred by its motion (its colour ramps along the streak: a dot moving three of its
// widths a frame still stands out), while a patch of background texture differs from its
// surroundings by less than they vary, whatever its core does.
constexpr double kCoreSigmaWeight = 0.5;
// The contrast in chromaticity (track/chromaticity.h): judged only where the marker's chromaticity
// differs from its surroundings' by kMinChromaContrastSpan at least (a tinted patch of the bench
// differs by less; coloured markers by 0.1-0.4), with kChromaNoiseFloor as its noise floor (two
// grey levels at mid brightness).
constexpr double kMinChromaContrastSpan = 0.05;
constexpr double kChromaNoiseFloor = 0.005;
// The contrast against the whole ring in chromaticity, which a whole-frame search with nothing
// learned (init) relies on, only where the blob's chromaticity differs from its whole ring's by
// this much: coloured domes on a bench's actuator differ by 0.20-0.34 (physically rendered,
// under front and side light), a peg hole's shadow or a tinted patch of wood by up to 0.16.
constexpr double kMinWholeRingChromaSpan = 0.18;

// ---- Verification (ColourTracker::judge) -----------------------------------------------------------
// A candidate whose contrast is below this does not stand out from its surroundings.
constexpr double kMinContrast = 2.0;
// Without a learned model only compact blobs are accepted (a disc is 1, a 2:1 ellipse 0.8, a disc
// seen at 50 degrees 0.91): elongated patches of the right colour are common on a bench.
constexpr double kMinCircularityWithoutModel = 0.7;
// A whole-frame first acquisition (no learned model, no roi) accepts only a blob with at least
// this many pixels of its own colour (deeper than the soft band inside its edge): the colour of a
// smaller blob is a mixture with its surroundings, and such specks are everywhere in real footage
// (the yellow rim of a highlight on an orange object, a glint on a blue one).
constexpr int kMinCorePxWithoutModel = 9;
// Tolerances of the colour check against the learned (or nominal) core colour: the angle between
// the BGR vectors (tint, insensitive to illumination gain) and the brightness ratio. A same-hue
// blob at 60 % of the marker's brightness or 9 degrees off in tint is something else.
constexpr double kChromaTolerance = 0.15;   // radians
constexpr double kBrightnessTolerance = 1.6;
// The learned shape: a candidate less circular than the model by this much is at its limit
// (and never below min_circularity).
constexpr double kShapeTolerance = 0.3;
// A pixel of a blob's own mask that was a hole (see FillHoles): part of its region, not of its
// colour.
constexpr uchar kFilledHole = 128;
// A partly hidden round marker is placed at the centre of its visible rim (RimCentre) when it
// was learned round (circularity >= 0.85) and large enough for a rim (area >= 28 px, radius 3),
// the blob has less than 0.97 of its area, at least 170 degrees of the rim show (half the disc,
// less the pixels where the cut meets the rim), and the rim points lie within 0.5 px RMS.
constexpr double kMinRimCircularity = 0.85;
constexpr double kMinRimArea = 28.0;
constexpr double kWholeRimFraction = 0.97;
constexpr double kMinRimArcDeg = 170.0;
constexpr double kMaxRimRmsPx = 0.5;
// The rim fit's inlier tolerance (px; FitRimOfRadius's default) and how far the edge off the
// circle may bulge outwards and still be a cut (px): a chord of pixels is straight to about half
// a pixel; an ellipse's arc bulges by its sagitta, several pixels for a disc seen at a slant.
constexpr double kRimInlierPx = 0.75;
constexpr double kMaxCutBulgePx = 1.0;
// Adaptation while tracking only from frames where the marker's shape is within kAdaptShape of
// the learned one (a partial cover changes it; growth and tilt change it slowly); the reference
// area stays within kAdaptMinRange..kAdaptMaxRange times the first one. A jump in area is not
// learned because it is not accepted (min_area_fraction, max_area_factor).
constexpr double kAdaptShape = 0.1;
constexpr double kAdaptMinRange = 0.5;
constexpr double kAdaptMaxRange = 4.0;
// A blob whose asymmetry (ColourBlob::asymmetry_px) exceeds the learned marker's by more than
// this many of its radii, and at least kPartialMinPx, is a marker partly covered: the centroid of
// what is visible lies that far from the marker's centre, so it is not reported. A tenth of the
// radius: a disc a quarter covered by a straight edge shifts its visible centroid by 0.22 radii,
// a twentieth covered by 0.05; 1 px keeps the pixel grid's own wobble of small markers out.
constexpr double kPartialRadii = 0.1;
constexpr double kPartialMinPx = 1.0;
// A blob with less than this fraction of the learned area is partial too (see judge()).
constexpr double kWholeAreaFraction = 0.55;
// A marker partly seen where it should be is held there (its window searched, nothing else) for
// at most this many frames: a second at 30 fps, long enough for a hand or a tool to pass.
constexpr int kHoldCoveredFrames = 30;
// A lone candidate within this of where a candidate tied before (in a first acquisition without
// a model or roi) has not moved since: it is that candidate (sensor noise moves a static blob's
// centroid by hundredths of a pixel).
constexpr double kRivalStillPx = 0.5;
// Two blobs of the marker's range whose boxes come within this of each other, in the roi
// (px) may be pieces of one marker that compression or noise split (a dim dome whose middle lost
// its colour in JPEG's blocks; see ColourTracker::a_larger_piece_beside) ...
constexpr double kPieceGapPx = 3.0;
// ... when the other blob has at least this multiple of its area (markers of about one size side
// by side, as a plate's dots, are not pieces of each other).
constexpr double kPieceAreaRatio = 2.0;

// A marker lost this many frames in a row, with exactly one candidate near where it was last
// seen that fits it in everything but brightness (same chroma, size, shape, contrast), is taken
// to be under a new light and its colour relearned. Half a second at 30 fps: a passing shadow or a
// hand does not relearn anything.
constexpr int kRelearnAfterFrames = 15;
// How near, in learned radii (plus one per frame lost): it may have moved while it was lost.
constexpr double kRelearnRadii = 6.0;
// A blob where the tracked marker should be (within its radius plus a frame's motion) that fits
// it in everything but brightness is the marker in a shadow, taken at once; its misfit is raised
// by this, so the marker at its own brightness wins where both are in view.
constexpr double kShadowMisfit = 1.0;
// The dim pass: a marker whose pixels have fallen below its range's brightness floor (a shadow
// over part of the bench, the dim edge of the light, a ball falling out of the lamp's cone) shows
// only a sliver of its brightest pixels in range. Its window is classified again with the floor
// at this fraction of the range's (the light halved), hue and saturation as configured. Floors
// below kDimMinFloor are not lowered: the pass would see nearly the same pixels.
constexpr double kDimFloor = 0.5;
constexpr int kDimMinFloor = 20;

// ---- Automatic colour (ColourParams::auto_bgr) -------------------------------------------------------
constexpr int kAutoHueTolerance = 12;        // hue units (2 degrees each)
constexpr int kAutoGraySaturation = 40;      // below: the nominal colour is a gray level

// A Mat header of `size` and `type` over `store`, which reallocates only when it is too small, so
// frames of a steady size allocate nothing. The header is continuous and has no parent matrix,
// so OpenCV's filters never read stale bytes beyond it as "neighbouring pixels".
inline cv::Mat Scratch(cv::Mat& store, cv::Size size, int type) {
  const size_t bytes = static_cast<size_t>(size.area()) * CV_ELEM_SIZE(type);
  if (store.empty() || static_cast<size_t>(store.cols) < bytes) {
    store.create(1, static_cast<int>(std::max<size_t>(bytes, 64)), CV_8U);
  }
  return cv::Mat(size, type, store.data);
}

inline double DistanceToRect(const cv::Point2d& p, const cv::Rect& r) {
  // Pixel areas: column j covers [j - 0.5, j + 0.5].
  const double dx = std::max({r.x - 0.5 - p.x, 0.0, p.x - (r.x + r.width - 0.5)});
  const double dy = std::max({r.y - 0.5 - p.y, 0.0, p.y - (r.y + r.height - 0.5)});
  return std::hypot(dx, dy);
}

inline bool CentroidBefore(const ColourBlob& a, const ColourBlob& b) {
  if (a.centroid_px.y != b.centroid_px.y) return a.centroid_px.y < b.centroid_px.y;
  if (a.centroid_px.x != b.centroid_px.x) return a.centroid_px.x < b.centroid_px.x;
  return a.area_px < b.area_px;
}

inline bool SameBlob(const ColourBlob& a, const ColourBlob& b) {
  return a.bbox_px == b.bbox_px && a.area_px == b.area_px && a.centroid_px == b.centroid_px;
}

// A pseudo-angle of (dx, dy) in [0, 4): monotonic in atan2 (one unit per quadrant), without a
// transcendental function. 0 for (0, 0).
inline double DiamondAngle(double dx, double dy) {
  const double sum = std::abs(dx) + std::abs(dy);
  if (sum == 0) return 0;
  if (dy >= 0) return dx >= 0 ? dy / sum : 1 - dx / sum;
  return dx < 0 ? 2 - dy / sum : 3 + dx / sum;
}

// Chamfer (3-4) distance to the edge of the nonzero pixels of `inside`, in thirds of a pixel,
// into `distance` (CV_16U, same size): for an outside pixel, to the nearest inside one; for an
// inside pixel, to the nearest outside one (pixels beyond the image count as inside, as erosion
// by OpenCV's default border does). The measurement no longer computes it: EdgeZones
// (track/colour_kernels.h) answers the only questions it asked of it, and is tested against it.
inline void ChamferToEdge(const cv::Mat& inside, cv::Mat& distance) {
  constexpr int kFar = 0x3fff;
  const int w = inside.cols, h = inside.rows;
  // Two transforms in one map: a pixel's seeds are its neighbours of the other kind (one step
  // away); through a neighbour of its own kind it inherits that one's distance plus the step.
  // `inside` holds 0 or 255, so a pixel's kind is its low bit; `same` is all ones when the
  // neighbour's kind is the pixel's, and masks in the neighbour's distance.
  auto relax = [](int d, int k, const uchar* in, const uint16_t* dist, int x, int step) {
    const int same = ((in[x] & 1) ^ k) - 1;
    return std::min(d, step + (dist[x] & same));
  };
  auto forward = [&](const uchar* in, const uchar* in_up, uint16_t* row, const uint16_t* up,
                     int x) {
    const int k = in[x] & 1;
    int d = kFar;
    if (x > 0) d = relax(d, k, in, row, x - 1, 3);
    if (up) {
      if (x > 0) d = relax(d, k, in_up, up, x - 1, 4);
      d = relax(d, k, in_up, up, x, 3);
      if (x + 1 < w) d = relax(d, k, in_up, up, x + 1, 4);
    }
    row[x] = static_cast<uint16_t>(d);
  };
  auto backward = [&](const uchar* in, const uchar* in_down, uint16_t* row, const uint16_t* down,
                      int x) {
    const int k = in[x] & 1;
    int d = row[x];
    if (x + 1 < w) d = relax(d, k, in, row, x + 1, 3);
    if (down) {
      if (x + 1 < w) d = relax(d, k, in_down, down, x + 1, 4);
      d = relax(d, k, in_down, down, x, 3);
      if (x > 0) d = relax(d, k, in_down, down, x - 1, 4);
    }
    row[x] = static_cast<uint16_t>(d);
  };
  for (int y = 0; y < h; ++y) {
    const uchar* in = inside.ptr<uchar>(y);
    uint16_t* row = distance.ptr<uint16_t>(y);
    if (y == 0 || w < 3) {
      const uchar* in_up = y > 0 ? inside.ptr<uchar>(y - 1) : nullptr;
      const uint16_t* up = y > 0 ? distance.ptr<uint16_t>(y - 1) : nullptr;
      for (int x = 0; x < w; ++x) forward(in, in_up, row, up, x);
      continue;
    }
    const uchar* in_up = inside.ptr<uchar>(y - 1);
    const uint16_t* up = distance.ptr<uint16_t>(y - 1);
    forward(in, in_up, row, up, 0);
    for (int x = 1; x + 1 < w; ++x) {  // Every neighbour exists: no bounds tests.
      const int k = in[x] & 1;
      int d = relax(kFar, k, in, row, x - 1, 3);
      d = relax(d, k, in_up, up, x - 1, 4);
      d = relax(d, k, in_up, up, x, 3);
      d = relax(d, k, in_up, up, x + 1, 4);
      row[x] = static_cast<uint16_t>(d);
    }
    forward(in, in_up, row, up, w - 1);
  }
  for (int y = h - 1; y >= 0; --y) {
    const uchar* in = inside.ptr<uchar>(y);
    uint16_t* row = distance.ptr<uint16_t>(y);
    if (y == h - 1 || w < 3) {
      const uchar* in_down = y + 1 < h ? inside.ptr<uchar>(y + 1) : nullptr;
      const uint16_t* down = y + 1 < h ? distance.ptr<uint16_t>(y + 1) : nullptr;
      for (int x = w - 1; x >= 0; --x) backward(in, in_down, row, down, x);
      continue;
    }
    const uchar* in_down = inside.ptr<uchar>(y + 1);
    const uint16_t* down = distance.ptr<uint16_t>(y + 1);
    backward(in, in_down, row, down, w - 1);
    for (int x = w - 2; x >= 1; --x) {
      const int k = in[x] & 1;
      int d = relax(row[x], k, in, row, x + 1, 3);
      d = relax(d, k, in_down, down, x + 1, 4);
      d = relax(d, k, in_down, down, x, 3);
      d = relax(d, k, in_down, down, x - 1, 4);
      row[x] = static_cast<uint16_t>(d);
    }
    backward(in, in_down, row, down, 0);
  }
}

inline double Norm(const cv::Vec3d& v, int channels) {
  double sum = 0;
  for (int c = 0; c < channels; ++c) sum += v[c] * v[c];
  return std::sqrt(sum);
}

inline int MorphShape(ColourParams::Shape shape) {
  switch (shape) {
    case ColourParams::Shape::kRect: return cv::MORPH_RECT;
    case ColourParams::Shape::kCross: return cv::MORPH_CROSS;
    case ColourParams::Shape::kEllipse: break;
  }
  return cv::MORPH_ELLIPSE;
}

// The coarse test with a pre-filter: hue widened by kCoarseHueSlack each side, lower S and V
// bounds lowered by a quarter and the upper ones raised a quarter of the way to 255.
inline HsvBox CoarseBox(const ColourParams& p) {
  const HsvRange h = p.h.hue_widened(kCoarseHueSlack);
  const HsvRange s{p.s.lo * 3 / 4, p.s.hi + (255 - p.s.hi) / 4};
  const HsvRange v{p.v.lo * 3 / 4, p.v.hi + (255 - p.v.hi) / 4};
  return HsvBox::Make(h, s, v);
}

}  // namespace softsight::colour_internal
