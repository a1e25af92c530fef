// Template-matching tracking (paper section 2.2): SAD, SSD and ZNCC, gray or colour.
//
// The contract. One template per marker, cut from a rectangle on a reference frame (init's hint)
// or given as an image. update() reports the marker's position only when the match is verified;
// otherwise Observation::NotFound says why:
//   found      the best match passes the measure's threshold (min_zncc, and max_sad / max_ssd;
//              0.1 below min_zncc when the match's core shows the marker's own colour), shows
//              the colour of the marker's core when the template was cut from a colour frame (a
//              gray template of a green disc is never found on the blue one), no distinct second
//              peak of the marker's colour in the searched region comes within ambiguity_margin of
//              it (ZNCC), the matched patch is still consistent with the FIRST template at
//              the current scale (ZNCC >= drift_min_zncc), and, when the selected template shows
//              a blob (a dot or sticker standing out from what is around it: its foreground),
//              that blob is in the match: within 2 px of where the template puts it, of about
//              its learned area (0.4x-2.5x), separated from its surroundings. A match the blob
//              lies more than 1 px from is moved onto it (a box mostly of background, e.g. tyre
//              around a sticker, matches the background well after the sticker moved on);
//   ambiguous  two distinct places fit about equally (look-alike markers, e.g. white dots): the
//              tracker never picks one of them;
//   lost       nothing in the searched region fits (or the template's blob is not in the match);
//   out_of_frame  the predicted window lies outside the image.
// The places the tracker would take for its marker (its best match, and a distinct second peak
// that passes min_zncc: a twin) are its candidates() for the session's association, which may
// adopt() the other one when the motion says it is the marker (verified as the tracker's own
// choice would be).
// The reported position is the marker's centre, not the rectangle's: by default the marker's
// centre of point symmetry (a dot's centroid; found once, on the selected template, in the square
// around its blob, so what else the box holds does not pull it), mapped into
// the frame through the match with the first template at the current scale (report: centre
// measures the blob's centroid in every frame instead). A dragged rectangle
// is centred on the marker only to the nearest pixel; report: rect_centre gives the rectangle's
// centre (the paper's position) instead.
//
// Markers that change shape (perspective, a marker approaching the camera to twice its size,
// rotation) are followed by three things, each on by default:
//   - template update: after each verified match the working template is blended towards the
//     patch at the match (update_rate), so it follows slow changes of pose and lighting;
//   - drift correction against the first template: the position is always measured with the first
//     template (scaled), never with the updated one, so an updated template cannot carry the
//     position away; an updated template that no longer resembles the first is discarded;
//   - a scale and turn search: the first template is kept on a ladder of scales (5 % apart) and
//     turns (5 degrees apart); each frame the neighbouring rungs are tried and the best one becomes
//     the scale and turn (scale_search, turn_search); a marker that keeps turning is looked for
//     turned on by its last spin.
// A round mask (round, default on) matches only the ellipse inscribed in the template, so the
// background in the rectangle's corners, which turns with the body, does not count.
//
// Search: while tracking, only a window around the position predicted by constant velocity is
// searched; at start the window around the hint; when the marker outran that window, or after
// a loss, the region within acquire_radius_px of the last known position (and its velocity), at
// most half the distance to the nearest look-alike seen at selection, coarse-to-fine over an
// image pyramid.
// The integer best match is refined to sub-pixel by a 1-D fit per axis on the score surface: a
// parabola for SSD and ZNCC (their surfaces are quadratic near the peak), the equiangular "V" fit
// for SAD (its surface is |d|-like; a parabola would pull the estimate halfway back).
//
// Observation::score, by measure (of the match with the working template):
//   zncc: the ZNCC itself, in [-1, 1], 1 = perfect;
//   sad:  SAD / (N * C), the mean absolute difference per pixel and channel, in grey levels;
//   ssd:  sqrt(SSD / (N * C)), the RMS difference per pixel and channel, in grey levels.
// (N = template pixels, C = channels.) SAD and SSD scores are thus in the same unit.
//
// Gray or colour: gray matches one channel, by default the template's best-contrast projection
// of BGR (contrast_gray), else luma; CV_8UC1 frames (a mono camera) are matched as they are. In
// gray the red, green and blue discs are all dark discs on a light band, and ZNCC (which cancels
// gain and offset) cannot tell them apart: a search that sees two of them reports ambiguous.
// Colour matching is the choice when markers must be told apart by colour.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"

namespace softsight {

class Tracker;

enum class MatchMeasure { kSad, kSsd, kZncc };

// The point a match reports: the marker's centre (the template's centre of symmetry, or its blob's
// soft centroid measured in every frame), or the dragged rectangle's centre.
enum class TemplateReport { kCentre, kSymmetry, kRectCentre };

// The largest template (pixels x channels) the matching kernels' 32-bit sums take:
// 255^2 * 33025 < 2^31. About 181 x 181 gray or 104 x 104 colour.
inline constexpr int kMaxTemplateValues = 33025;

struct TemplateParams {
  MatchMeasure measure = MatchMeasure::kZncc;
  bool colour = false;  // Match on BGR instead of gray (3x the work).
  // Where the template comes from: a rectangle on a reference frame, or an image (read by the
  // caller, e.g. the config reader from `template.file`, into `image`, BGR or gray). When `image` is empty the tracker takes it from init()'s
  // hint. A non-empty hint always wins (that is how a person re-selects a template at run time).
  // With both `image` and `rect` (a template selected live and saved), the image is the template
  // and `rect`, its size, is where it was selected on `template_frame`: init() without a hint
  // starts tracking there, exactly as the selection did, instead of searching the whole frame.
  int template_frame = 0;
  std::optional<cv::Rect> rect{};
  cv::Mat image{};
  // Match only the ellipse inscribed in the template rectangle (a disc for a square one), so the
  // background in the rectangle's corners, which rotates with the body or is clutter behind a
  // plate, does not count. Default true; false matches the whole rectangle (the paper's, and a
  // faster unmasked ZNCC kernel).
  bool round_mask = true;
  // Which point is reported (see the contract above). Default kCentre. kSymmetry: on colour footage where
  // the marker stands out more in its chromaticity than in the matched channel, its blob's soft
  // centroid in that chromaticity, measured in every frame (shading does not move it); else the
  // marker's centre
  // of point symmetry (a dot's or disc's centroid; measured on the square around the template's
  // blob where it shows one, else on the whole template), carried by the match with the first
  // template, and moved onto the blob's centroid where the two disagree by more than 0.75 px;
  // a template without a clear one (self-match of the turned template below 0.5) reports its
  // rectangle's centre. kCentre: when the selected template shows a blob (one compact region
  // brighter or darker than what is around it, wholly inside the template), its soft centroid,
  // measured again in every frame at the match (where it cannot be separated, the centre of
  // symmetry). On the rendered bending scene (30 frames) the blob is the less accurate (0.125 vs
  // 0.087 px RMS: the band's shading and ribs at the disc's rim enter its levels); on the rendered
  // plate (white dots on a dark plate) it is the more accurate (0.001 vs 0.048 px). kRectCentre: the
  // rectangle's centre, (x + (w-1)/2, y + (h-1)/2), scaled with the marker: the marker's centroid
  // only when the rectangle was centred on it (the paper's position).
  TemplateReport report = TemplateReport::kCentre;
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

  // ---- Verification: a best match worse than these is "not found" ----------------------------
  // Default 0.8: the paper's "realistic match". Higher rejects more partly covered markers and
  // more frames under blur or lighting change. A match whose core shows the marker's own colour
  // (a template cut from a colour frame) passes 0.1 lower: its colour is a second piece of
  // evidence, and a blurred or turning marker matches its gray levels less well. SAD and SSD matches must pass it too (one ZNCC at
  // the best placement, a shape check): grey-level closeness alone accepts smooth background
  // patches once the light has changed.
  double min_zncc = 0.8;
  // SAD: largest mean absolute difference per pixel and channel (grey levels), default 20.
  // SAD and SSD do not cancel lighting changes: a gain of 1.4 on a grey-100 marker already moves
  // every pixel by 40, so these thresholds trade robustness to light against occlusion rejection.
  double max_sad = 20.0;
  // SSD: largest RMS difference per pixel and channel (grey levels), default 25.
  double max_ssd = 25.0;
  // A second peak of the searched region, at least half a template away from the best, whose
  // ZNCC is within this of the best's makes the match ambiguous (not found): two look-alike
  // markers in view are never guessed between. Default 0.1; 0 turns the check off. Larger
  // refuses more (and needs the markers further apart).
  double ambiguity_margin = 0.1;

  // ---- Search -------------------------------------------------------------------------------
  // While tracking, the window is the template grown by this margin on every side, centred on the
  // constant-velocity prediction. It must exceed the largest change of velocity between two
  // frames (px/frame^2); the cost grows with its square. Default 8.
  int search_margin_px = 8;
  // When the marker moved beyond the tracking window, or after a loss, the region searched is
  // within this radius of the last known position (moved on by the last velocity); 0: the whole
  // frame. A look-alike seen at selection (a place scoring min_zncc or more) bounds it to half its
  // distance, so a covered marker is not swapped for its twin; small keeps look-alikes out (one in
  // the region makes the search ambiguous at best); large re-finds a marker that moved far while
  // hidden (a cart at 30 px a frame from rest). Without a known position (template from a file,
  // or after reset()) the whole frame is searched. Default 64.
  int acquire_radius_px = 64;
  // Acquisition pyramid: at most this many levels (1 = full resolution only). Fewer are used when
  // the template would shrink below 8 px at the coarsest level.
  int pyramid_levels = 3;

  // ---- Following shape changes (see the contract above) ----------------------------------------
  // Template update: after each verified match, working template = (1 - rate) * working template
  // + rate * the patch at the match (cut at the sub-pixel position, at the current scale). Follows
  // perspective, rotation and lighting; 0 keeps the template fixed (the paper's). Default 0.5.
  double update_rate = 0.5;
  // Drift guard: the matched patch must have at least this ZNCC with the first template at the
  // current scale, else the marker is not found; an updated template below it is discarded and
  // the first template (scaled) restored. It bounds how far the appearance may wander from the
  // selection (a dot foreshortened by a tilt scores lower against its frontal template, but
  // passes 0.6 on the rendered plate tilting to 50 degrees). Where the template shows the
  // marker's blob and the blob is found at the match with its area, 0.2 less is enough (the blob
  // is a second piece of evidence; ViSP's mire-2 big dot, squashed by the plate's tilt, fits
  // 0.59). Default 0.6.
  double drift_min_zncc = 0.6;
  // Scale search: each frame the first template one rung (5 %) larger and smaller is tried at the
  // match, and the better rung is kept when it fits better by a little (hysteresis), so the
  // template follows a marker that approaches or recedes (0.4x .. 4x). Default true; false keeps
  // the selected size.
  bool scale_search = true;
  // Turn search: the first template is also kept turned about its centre in 5 degree steps all
  // the way round; each frame the turns one step either way are tried at the match (from where
  // the marker's last spin carries it), and the better is kept when it fits better by a little,
  // so the template follows a marker that turns (a sticker on a wheel, a marker on a bending body)
  // and the drift guard compares the match with the first template as turned. Measured on a
  // 28 x 8 px sticker on a rim turning 5 degrees a frame: without it a template box is lost
  // after ~4 frames, the drift guard refusing the turned sticker. Default true; false keeps the
  // selected orientation (a marker that must not be taken for a turned look-alike).
  bool turn_search = true;

  // Returns true when every field is usable; otherwise false with `error` naming the field.
  bool Check(std::string* error) const;
};

const char* TemplateReportName(TemplateReport report);  // "centre", "symmetry", "rect_centre"

// Builds a template tracker (CreateTracker does this for the methods sad, ssd and zncc).
// Throws InputError naming the field when `params` fail Check().
std::unique_ptr<Tracker> CreateTemplateTracker(const TemplateParams& params);

}  // namespace softsight
