// Colour-intensity tracking (paper section 2.1): filter -> HSV -> binarise -> morphology ->
// blobs -> centroid from moments, with region-of-interest tracking and honest loss detection.
//
// The tracker itself (ColourTracker, built by CreateTracker(spec) with method "colour") reports
//   Observation::position_px = centroid (m10/m00, m01/m00) of the chosen blob's binary mask,
//                              pixel-centre convention (x = column), sub-pixel;
//   Observation::score       = blob area / reference area (the marker's area when it was
//                              acquired): ~1 for a fully visible marker, lower when partly covered.
// A blob whose area is below min_area_fraction of the reference area counts as not found.
#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"

namespace softsight {

// An inclusive range of one 8-bit HSV channel. For hue (0..179) lo > hi wraps around 0:
// {170, 10} means 170..179 and 0..10 (red).
struct HsvRange {
  int lo = 0;
  int hi = 255;
};

struct ColourParams {
  // ---- Pre-filter -------------------------------------------------------------------------------
  enum class Filter { kNone, kGaussian, kMedian };
  // kGaussian is cheap and removes sensor noise; kMedian keeps edges sharper but costs more.
  Filter filter = Filter::kNone;
  // Odd kernel side in pixels, >= 3. Larger smooths more and blurs small markers.
  int filter_ksize = 5;

  // ---- Threshold (OpenCV 8-bit HSV: H 0..179, S and V 0..255) -------------------------------------
  HsvRange h{0, 179};
  HsvRange s{0, 255};
  HsvRange v{0, 255};
  // Automatic threshold: when set, h/s/v are ignored and pixels are split into marker and
  // background by Otsu's criterion on their colour distance (mean absolute BGR difference) to
  // this nominal colour. The threshold is learned once, on the first acquisition's region, and
  // kept until init(): give `roi` (or init's hint) so the marker is a fair share of that region;
  // on a whole frame the marker is too small a class for Otsu's split to be meaningful.
  std::optional<cv::Vec3b> auto_bgr;

  // ---- Morphology: opening (removes specks) then closing (fills holes) ----------------------------
  enum class Shape { kRect, kEllipse, kCross };
  int morph_size = 3;                // Structuring element side in px, odd; 1 disables both.
  Shape morph_shape = Shape::kEllipse;

  // ---- Blob selection ----------------------------------------------------------------------------
  double min_area_px = 12.0;         // Smaller blobs are specks.
  double max_area_px = 0.0;          // 0: no upper limit.
  // Compactness area^2 / (2*pi*J), J the blob's polar second moment about its centroid (pixels
  // as unit squares): 1 for a disc, 0.95 square, 0.8 for a 2:1 ellipse, < 0.1 for a cable or an
  // edge. Moment-based, so it is stable for small blobs where a perimeter estimate is not.
  double min_circularity = 0.5;
  // A blob smaller than this fraction of the marker's reference area (its area when acquired)
  // counts as not found, so a mostly covered marker is not reported at a shifted position.
  double min_area_fraction = 0.25;
  // A blob larger than this multiple of the reference area is not the marker (a patch of skin, a
  // cable bundle); 0: no limit.
  double max_area_factor = 4.0;

  // ---- Search ------------------------------------------------------------------------------------
  // Where the first acquisition looks (a dragged rectangle); the chosen blob's centroid lies in it.
  // Without it the first acquisition takes the largest acceptable blob of the frame. Later
  // re-acquisitions search the whole frame, preferring blobs near the last known position whose
  // area and circularity match the reference.
  std::optional<cv::Rect> roi;
  // Side of the square window searched around the constant-velocity prediction while tracking;
  // at least 4 reference radii. Smaller is faster but needs widening sooner for fast markers.
  // 0: search the whole frame every frame, choosing the blob nearest the prediction (several
  // times slower; gives the same result while the marker stays inside the window).
  int window_px = 64;
  // When the marker is not in the window, or a blob touches its border, the window doubles this
  // often (within the same frame) before the whole frame is searched.
  int widen_steps = 2;
  // Whole-frame acquisition first tests one pixel per factor x factor cell to find candidates,
  // then analyses each at full resolution: the same result at a fraction of the cost.
  // 1: full resolution only. 2, 4, 8: that factor. 0 (default): the largest factor for which the
  // smallest acceptable blob (radius >= factor) still holds several sample points.
  int acquire_downsample = 0;

  // Returns true when every field is usable; otherwise false with `error` naming the field.
  bool Check(std::string* error) const;
};

}  // namespace softsight
