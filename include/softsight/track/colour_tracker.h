// Colour-intensity tracking (paper section 2.1): filter -> HSV -> binarise -> morphology ->
// blobs -> centroid from moments, with region-of-interest tracking and honest loss detection.
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
  // background by Otsu's criterion on their colour distance to this nominal BGR colour.
  std::optional<cv::Vec3b> auto_bgr;

  // ---- Morphology: opening (removes specks) then closing (fills holes) ----------------------------
  enum class Shape { kRect, kEllipse, kCross };
  int morph_size = 3;                // Structuring element side in px; 1 disables both.
  Shape morph_shape = Shape::kEllipse;

  // ---- Blob selection ----------------------------------------------------------------------------
  double min_area_px = 12.0;         // Smaller blobs are specks.
  double max_area_px = 0.0;          // 0: no upper limit.
  double min_circularity = 0.5;      // 4*pi*area/perimeter^2, 1 for a disc; rejects cables, edges.
  // A blob smaller than this fraction of the marker's reference area (its area when acquired)
  // counts as not found, so a mostly covered marker is not reported at a shifted position.
  double min_area_fraction = 0.25;

  // ---- Search ------------------------------------------------------------------------------------
  std::optional<cv::Rect> roi;       // Where the first acquisition looks (a dragged rectangle).
  int window_px = 64;                // Side of the square window searched around the prediction.
  int widen_steps = 2;               // After a loss, double the window this often, then full frame.

  // Returns true when every field is usable; otherwise false with `error` naming the field.
  bool Check(std::string* error) const;
};

}  // namespace softsight
