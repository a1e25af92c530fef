// Colour-intensity tracking (paper section 2.1): filter -> HSV -> binarise -> morphology ->
// blobs -> centroid from moments, with region-of-interest tracking and honest loss detection.
//
// The tracker itself (ColourTracker, built by CreateTracker(spec) with method "colour") reports
//   Observation::position_px = the chosen blob's centroid, pixel-centre convention (x = column),
//                              sub-pixel: by default the soft centroid (edge pixels weighted by
//                              how much of them is marker), or the paper's binary centroid
//                              (m10/m00, m01/m00 of the blob's mask) with centroid = kBinary;
//   Observation::score       = blob area / reference area (the marker's area as learned, updated
//                              slowly while tracking): ~1 when fully visible, lower when covered.
// "Found" means verified: a blob is reported only when it fits the marker's model (size, shape,
// colour against its surroundings), learned when the marker is first acquired; before that only a
// compact, contrasted blob that fits the configured ranges is accepted, and only when no other
// candidate fits about as well (otherwise: not found, MarkerStatus::kAmbiguous).
#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "softsight/core/hsv_range.h"
#include "softsight/core/types.h"

namespace softsight {


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
  // Intensity markers (white or black dots): when set, h/s/v are ignored and a pixel is marker
  // when its gray level (BGR->gray luma, or the frame itself when it is CV_8UC1) lies in this
  // inclusive range 0..255. Works on gray and colour video alike.
  std::optional<HsvRange> gray{};
  // Automatic colour: when set, h/s/v are ignored. The nominal colour (B, G, R) gives the
  // threshold (hue within 12 of the nominal's, saturation and value at least half and
  // 40 % of the nominal's) and is the colour model candidates are verified against
  // until the marker's own colour is learned: a same-hue blob much darker or of another tint is
  // not the marker. A nominal gray (B = G = R, or saturation below 40) tracks by gray level.
  std::optional<cv::Vec3b> auto_bgr{};

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

  // ---- Centroid ----------------------------------------------------------------------------------
  // kSoft: pixels within 2 px of the blob's edge count by their membership, the projection of
  // their colour on the line from the blob's local background colour (a ring 3-4 px outside) to
  // its core colour, clamped to 0..1: anti-aliased and blurred edges then weigh what they cover.
  // With a range that names a hue and a saturation floor, the centroid also takes in the pale
  // fringe beyond those 2 px (pixels up to 4 px outside the blob that pass the range with its
  // saturation and brightness floors halved: a lit dome's whitened top, a shaded flank), which
  // the floor cut off the marker; the sigma covers the edge lying anywhere between the two cuts.
  // kBinary: the paper's centroid of the binary mask (exact for hard-edged, unblurred markers).
  enum class Centroid { kSoft, kBinary };
  Centroid centroid = Centroid::kSoft;
  // A round marker seen smaller than its learned area is taken as partly hidden and placed by
  // the circle of its learned size through its visible rim (default true: a finger or a clamp
  // over part of it does not pull it off). False: always the centroid of what is seen, for
  // markers whose apparent size changes by itself: moving in depth or turning away from the
  // camera (two cameras, track-stereo), where the circle of the old size lands up to 1 px off.
  bool rim_fit = true;

  // ---- Verification ------------------------------------------------------------------------------
  // Each candidate gets a misfit: 0 is a perfect fit, each criterion (area, shape, colour,
  // contrast to its surroundings) reaching 1 at its limit; above 1 it is rejected. When the
  // runner-up's misfit is within this margin of the best one's, the marker is ambiguous and not
  // found. Larger refuses more often; 0 accepts the best even against a twin. (A whole-frame first
  // acquisition, with no model learned and no roi, needs the one candidate that fits at all, with
  // at least 9 pixels of its own colour: see roi.)
  double ambiguity_margin = 0.2;
  // While tracking, the learned area, shape and colour follow the marker by this fraction per
  // frame (only from frames where it fits well: a sudden change is not learned), so a marker that
  // grows to twice its size in perspective keeps fitting. The learned area stays within 1/2..4x
  // of its first value. 0: keep the first model.
  double adapt_rate = 0.05;

  // ---- Search ------------------------------------------------------------------------------------
  // Where the first acquisition looks (a dragged rectangle); the chosen blob's centroid lies in it.
  // Without it the first acquisition searches the whole frame and accepts a blob only when it is
  // the one candidate that fits, and has a core of its own colour (at least 9 pixels deeper than
  // 2 px inside its edge: a speck's colour is a mix with its surroundings, and real footage is
  // full of glints and highlight rims). Later re-acquisitions search the whole frame,
  // preferring candidates that fit the learned model best, near the last known position.
  std::optional<cv::Rect> roi{};
  // The frame (Frame::index) the roi was picked on: a pick or drag at frame N (live, `softsight
  // pick --frame N`, `init --frame N`) says where the marker is then, not at frame 0, where it
  // may have been anywhere. Before this frame the marker is not started (status not_started,
  // nothing reported: where it was then nobody showed, and a whole-frame search could take a
  // look-alike for it); on it the first acquisition looks in the roi and learns the marker's
  // model there, as the pick did. Without a roi it is just the frame tracking starts at.
  // Default 0: from the first frame.
  int roi_frame = 0;
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
  // False when gray frames suffice: a gray-level range, a nominal gray, or an HSV range that takes
  // any hue at zero saturation (white, gray and black markers).
  bool NeedsColour() const;
};

}  // namespace softsight
