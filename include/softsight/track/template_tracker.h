// Template-matching tracking (paper section 2.2): SAD, SSD and ZNCC, gray or colour.
//
// One template per marker, cut from a rectangle on a reference frame (init's hint) or given as an
// image. While tracking, only a window around the position predicted by constant velocity is
// searched; at start and after a loss the tracker acquires coarse-to-fine over an image pyramid,
// around the last known position (or over the whole frame). The integer best match is refined
// to sub-pixel by a 1-D fit per axis on the score surface: a parabola for SSD and ZNCC (their
// surfaces are quadratic near the peak), the equiangular "V" fit for SAD (its surface is |d|-like;
// a parabola would pull the estimate halfway back to the integer position).
//
// Reported position: the template's centre in the pixel-centre convention. For a template cut
// from rect [x, y, w, h] that centre is (x + (w-1)/2, y + (h-1)/2), so it is the marker's
// centroid exactly when the marker sits centred in the rectangle. A rectangle placed off-centre
// by a fraction of a pixel carries that offset into every position as a constant bias
// (centre_on_symmetry removes it for symmetric markers).
//
// Observation::score, by measure:
//   zncc: the ZNCC itself, in [-1, 1], 1 = perfect;
//   sad:  SAD / (N * C), the mean absolute difference per pixel and channel, in grey levels;
//   ssd:  sqrt(SSD / (N * C)), the RMS difference per pixel and channel, in grey levels.
// (N = template pixels, C = channels.) SAD and SSD scores are thus in the same unit.
//
// Gray or colour: gray matches one channel, by default the template's best-contrast projection
// of BGR (contrast_gray), else luma. In gray the red, green and blue discs are all dark discs on
// a light band, and ZNCC (which cancels gain and offset) cannot tell them apart; a whole-frame
// search may find another marker. Acquisition therefore looks around the last known position
// (acquire_radius_px), and colour matching is the choice when markers must be told apart on the
// whole frame.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"

namespace softsight {

class Tracker;

enum class MatchMeasure { kSad, kSsd, kZncc };

// The largest template (pixels x channels) the matching kernels' 32-bit sums take:
// 255^2 * 33025 < 2^31. About 181 x 181 gray or 104 x 104 colour.
inline constexpr int kMaxTemplateValues = 33025;

struct TemplateParams {
  MatchMeasure measure = MatchMeasure::kZncc;
  bool colour = false;  // Match on BGR instead of gray (3x the work).
  // Where the template comes from: a rectangle on a reference frame, or an image file (loaded by
  // the caller into `image`, BGR or gray). When `image` is empty the tracker takes it from init()'s
  // hint. A non-empty hint always wins (that is how a person re-selects a template at run time).
  int template_frame = 0;
  std::optional<cv::Rect> rect;
  cv::Mat image;
  std::string image_file;  // Where `image` was read from, so a saved config names it.
  // Match only the ellipse inscribed in the template rectangle (a disc for a square one), so the
  // background in the rectangle's corners, which rotates with the body, is ignored. Measured on
  // the rendered bending scene it changes the error by < 0.01 px (the disc edge dominates), and
  // masked ZNCC needs a slower fused kernel, so it is off by default.
  bool round_mask = false;
  // Report the template's centre of point symmetry instead of its geometric centre. A dragged
  // rectangle is centred on the marker only to the nearest pixel, so the geometric centre is off
  // the marker's centroid by up to half a pixel per axis, in every frame; for a symmetric marker
  // (a disc) the centre of symmetry is its centroid. Off by default (the documented contract is
  // the rectangle's centre).
  bool centre_on_symmetry = false;
  // Gray mode only: the single channel matched is not luma but BGR projected on the template's
  // principal colour axis (largest colour variance in the template: the marker against what is
  // around it), weights of L1 norm 1 plus an offset, so values stay 0..255 grey levels and SAD/SSD
  // thresholds keep their meaning. Why: in luma a green disc (gray 142) is only ~50 levels below
  // the pale band around it, so the band's own structure right at the disc's rim (highlight, ribs,
  // background through the silicone) shifts where the rim appears, and that shift turns with the
  // body: measured on the rendered bending scene (25 px templates, 100 frames) luma gives
  // 0.18-0.19 px RMS and 6 misses, the projection 0.084-0.090 px and none (colour: 0.087-0.090).
  // Matching costs the same (one channel); converting the window with cv::transform instead of
  // cvtColor adds ~2 us per window (benchmark: +4-8 us per frame for 3 markers). Gain and offset
  // still cancel in ZNCC (the projection is linear). With a mono camera (B = G = R) it is the
  // channel mean, i.e. luma. The weights are fixed when the template is selected: light whose
  // colour changes a lot afterwards lowers the contrast they were chosen for. Default true;
  // false: plain luma (the paper's gray).
  bool contrast_gray = true;

  // ---- Loss detection: a best match worse than these is "not found" ----------------------------
  // Default 0.8: the paper's "realistic match". Higher rejects more partly covered markers and
  // more frames under blur or lighting change. SAD and SSD matches must pass it too (one ZNCC at
  // the best placement, a shape check): grey-level closeness alone accepts smooth background
  // patches once the light has changed.
  double min_zncc = 0.8;
  // SAD: largest mean absolute difference per pixel and channel (grey levels), default 20.
  // SAD and SSD do not cancel lighting changes: a gain of 1.4 on a grey-100 marker already moves
  // every pixel by 40, so these thresholds trade robustness to light against occlusion rejection.
  double max_sad = 20.0;
  // SSD: largest RMS difference per pixel and channel (grey levels), default 25.
  double max_ssd = 25.0;

  // ---- Search
  // ------------------------------------------------------------------------------------ While
  // tracking, the window is the template grown by this margin on every side, centred on the
  // constant-velocity prediction. It must exceed the largest change of velocity between two
  // frames (px/frame^2); the cost grows with its square. Default 8.
  int search_margin_px = 8;
  // At start (with a hint) and after a loss, look this far around the last known position;
  // 0 searches the whole frame. Small keeps look-alike markers (red and blue are nearly the same
  // grey) from being taken for a hidden one; large re-finds a marker that moved far while hidden.
  // Without a known position (template from a file, or after reset()) the whole frame is searched.
  int acquire_radius_px = 64;
  // Acquisition pyramid: at most this many levels (1 = full resolution only). Fewer are used when
  // the template would shrink below 8 px at the coarsest level.
  int pyramid_levels = 3;

  // ---- Slow template update (off by default)
  // ------------------------------------------------------- After each accepted match, template =
  // (1 - rate) * template + rate * matched patch (cut at the sub-pixel position). Follows slow
  // changes of pose and lighting; 0 keeps the template fixed.
  double update_rate = 0.0;
  // Drift guard: an updated template whose ZNCC with the original falls below this is discarded
  // and the original restored, so the template cannot wander onto the background.
  double drift_min_zncc = 0.9;

  // Returns true when every field is usable; otherwise false with `error` naming the field.
  bool Check(std::string* error) const;
};

const char* MatchMeasureName(MatchMeasure measure);  // "sad", "ssd", "zncc"

// Builds a template tracker (CreateTracker does this for the methods sad, ssd and zncc).
// Throws InputError naming the field when `params` fail Check().
std::unique_ptr<Tracker> CreateTemplateTracker(const TemplateParams& params);

}  // namespace softsight
