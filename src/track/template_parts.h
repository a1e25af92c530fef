// The template tracker's parts that are not the tracker's state machine: its constants, the
// similarity map's peaks (integer best, sub-pixel offset, the best rival), masks, the centre of
// symmetry, and the marker's blob inside the template (BlobMeter: its foreground, which every
// match is verified against). Private to track/; tests reach them here.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "track/chromaticity.h"
#include "track/match_kernels.h"
#include "track/soft_centroid.h"

namespace softsight::template_internal {

inline constexpr int kMinTemplatePx = 3;           // Smaller templates have no sub-pixel neighbourhood.
inline constexpr int kMinRungPx = 5;               // Smallest side of a scaled first template.
inline constexpr int kMaxTemplateRowBytes = 2048;  // The SAD kernel's 16-bit accumulator limit.
inline constexpr int kMinCoarseTemplatePx = 8;     // Coarsest pyramid template side.
inline constexpr int kRefineMarginPx = 2;          // Search margin per pyramid level while refining.
inline constexpr int kCandidates = 3;              // Coarse peaks refined to full resolution.
inline constexpr int kMaxRecentre = 4;             // Re-centrings of the final window onto its peak.
inline constexpr int kFineMarginPx = 3;            // First-template search around the working match.
// The tracking window is converted with this much around it: the later windows (the
// measurement, kFineMarginPx around the match; the neighbouring rungs of the scale search; the
// template update's patch) lie in it while the marker is found near where it was predicted,
// which is most frames; one that does not is converted on its own. (Converting all of them,
// kFineMarginPx and more around the whole window, cost more than the few it saves.)
inline constexpr int kAroundPx = 2;
// While tracking, the window this far around the predicted place is searched first; the
// search_margin_px window only when that one does not decide (NearSearchDecides).
inline constexpr int kNearMarginPx = 4;
// ... and before it, a window this far around the prediction, moved onto its best while that
// lies on its edge (9 placements a try, not 81): it decides when its best lies inside it within
// the near window, a local peak of it, its best unless a higher peak lies within kNearMarginPx
// of the prediction too (two peaks a few pixels apart: not a marker's dot).
inline constexpr int kFirstNearMarginPx = 1;
// The measurement climbs likewise from the working template's match within kFineMarginPx (the
// first and the working template mostly agree to a pixel).
inline constexpr int kFirstFineMarginPx = 1;
// The look-alike scan matches at full resolution only within this many pixels of the places its
// half-resolution template fits by min_zncc less this much (LookAlikeZncc).
inline constexpr double kLookAlikeSlack = 0.3;
inline constexpr int kLookAlikeReachPx = 4;
inline constexpr double kScaleStep = 1.05;         // Ratio between neighbouring rungs of the ladder.
inline constexpr int kRungsBelow = 19;             // 1.05^-19 = 0.40.
inline constexpr int kRungsAbove = 28;             // 1.05^28 = 3.92.
// A neighbouring rung replaces the current one only when its ZNCC is higher by this much, so
// noise does not make the scale (or the turn) flicker between two rungs that fit equally.
inline constexpr double kScaleHysteresis = 0.003;
// The ladder's second dimension: the first template turned about its centre, in steps of this
// many degrees, all the way round (a sticker on a wheel, a marker on a body that turns). A step
// this size costs a thin 28 px sticker about 0.95 of its ZNCC against itself.
inline constexpr double kTurnStepDeg = 5.0;
inline constexpr int kTurns = 72;  // 360 / kTurnStepDeg.
// A turned rung replaces the current one only when its ZNCC is higher by this much: a disc fits
// about as well turned as not (only the background around it changes), and flickering between
// turns would move its reported point with each step; a sticker 5 degrees off loses far more.
inline constexpr double kTurnHysteresis = 0.02;
// While tracking, the neighbouring rungs are tried every kPoseEvery-th frame, and in any frame
// where the current rung fits worse by kPoseDrop than at the last try (issue 45). Every 6th, not
// 3rd: half the pose search's work; the real and rendered sets' tables the same but the pale
// domes' median, 1.553 -> 1.570 px (a known-failing case, its rungs taking over a frame later).
inline constexpr int kPoseEvery = 6;
inline constexpr double kPoseDrop = 0.005;
// The working template is not blended with a frame's patch where it already matched that patch
// with at least this ZNCC (ZNCC measure only: SAD and SSD follow the light's levels too): the
// blend would change little, and the update (conversion, blend, drift guard, preparation) was
// 13 % of a frame of ViSP's mire-2, whose large dot matches so in most frames (issue 45). A
// change of the marker's look (pose, blur, shading) drops the match below it, and the update
// follows as before.
inline constexpr double kSteadyWorkingZncc = 0.98;
// Below this self-match of the turned template there is no centre of symmetry worth reporting.
inline constexpr double kMinSymmetry = 0.5;

inline constexpr double kNoRival = -std::numeric_limits<double>::infinity();

std::string RectText(const cv::Rect& r);

// Centre-of-template coordinates <-> top-left placement.
cv::Point2d HalfSize(const cv::Size& size);

// Peak offset in [-0.5, 0.5] from three samples of a similarity (higher is better) around its
// integer maximum `c`. A parabola suits quadratic peaks (SSD, ZNCC); the equiangular fit suits
// V-shaped ones (SAD), where a parabola would halve the offset.
double PeakOffset(double l, double c, double r, bool v_shaped);

// Sub-pixel offset of the peak at `best` of a similarity map, per axis.
cv::Point2d SubPixel(const cv::Mat& sim, cv::Point best, bool v_shaped);

// The highest non-NaN value of a CV_32F map; false when every value is NaN.
bool BestIn(const cv::Mat& sim, cv::Point* at);

// The highest local maximum of `sim` farther than `radius` (per axis) from `best`: a distinct
// second place the template fits. A value on the map's edge counts when it is not below its
// neighbours inside (it may be the slope of a peak just outside). False when there is none.
bool RivalIn(const cv::Mat& sim, cv::Point best, int radius, cv::Point* at);
// How far from the best placement a distinct second peak (RivalIn) of a template this size lies.
int RivalRadius(const cv::Size& templ);
// Whether no placement of the window searched `margin_px` around a prediction lies farther than
// `rival_radius` (RivalIn's sense) from a peak `from_prediction` placements off the prediction:
// then that window could report no rival to this peak.
bool NoRivalReachable(int margin_px, cv::Point from_prediction, int rival_radius);

// The ellipse inscribed in a template of `size` (pixel centres within it count).
cv::Mat RoundMask(const cv::Size& size);

// ZNCC of `templ` placed at `top_left` of `image` (one placement, by the vector kernel: the
// scalar reference here was a tenth of the tracker's time).
double ZnccAt(const cv::Mat& image, cv::Point top_left, const PreparedTemplate& templ,
              cv::Mat& result, ZnccScratch& scratch);

// The point about which `templ` is most nearly point-symmetric, in template coordinates: the
// template is matched (ZNCC) against its inner part turned by 180 degrees about a guess c; a
// shift d between the two puts the centre of symmetry at c + d / 2. The guess starts at the
// geometric centre and is refined by turning about the last estimate (sub-pixel, bilinear), so
// the final shift is near zero, where the parabola fit of the peak has no pixel-locking bias.
// `strength` gets the ZNCC of the self-match (1: perfectly symmetric). Falls back to the
// geometric centre.
cv::Point2d SymmetryCentre(const cv::Mat& templ, double* strength);

// The centre of symmetry of the marker, not of the whole box: SymmetryCentre of the square
// around the blob's centroid `blob_centre` that holds the blob (of `blob_area` px) and 2 px
// beyond its rim. What else a dragged box holds (a band's edge on one side, ribs or a shadow on
// the other) is not symmetric about the marker and would pull the box's centre off it: 1.7 px
// on a physically rendered bench, where the marker's own centre is 0.4 px from the truth.
cv::Point2d MarkerSymmetryCentre(const cv::Mat& templ, const cv::Point2d& blob_centre,
                                 double blob_area, double* strength);

// ---- Re-centring on the marker's blob ---------------------------------------------------------
// A marker that is a blob (a dot, a disc: one compact region brighter or darker than what is
// around it) is measured by its soft centroid in every frame: each pixel weighs by how much of it
// is marker, (v - background) / (marker - background) clamped to [0, 1], the blob cut from its
// surroundings half way between its own level and the level at which it would join them. Its
// centroid is the marker's centroid whatever its shape, so it follows perspective, scale and
// rotation exactly, where a template's fixed anchor carries the band's texture turning with the
// body.

inline constexpr double kMinBlobContrast = 12.0;  // Grey levels between marker and background.
// A selected template holds this much of the marker's surroundings on every side of its blob
// (px): the background's level is read 3-4 px outside the blob (BlobMeter::MeasureSegmented).
inline constexpr int kMinSurroundPx = 4;
// A person drags a box around the marker, so the box's centre lies on it: the blob a selection
// reports the marker's centre from lies at most this many of its own radii (of a disc of its
// area) from the centre of the box dragged. A blob farther off is a piece of the marker (a pale
// dome's shaded rim where the exposure clipped the rest to white: 5.9 px off a 32 px box around
// a dome of radius 10, 1.3 of its radius) or something beside it. Boxes drawn around whole
// markers, 0-12 px margins, on every rendered and real scene: at most 0.40.
inline constexpr double kMaxBlobOffBoxCentre = 0.75;
// Of a template's bright and dark blobs at its centre, the one this many times larger is the
// marker (the other a highlight on it, or a dark fleck), whichever stands out more.
inline constexpr double kMarkerOverGlint = 3.0;
// How much lower than drift_min_zncc the first template may fit a match whose blob is found there
// (the marker's blob, of its area, is evidence that the match has not drifted off it).
inline constexpr double kBlobDriftAllowance = 0.2;
// The blob at a match has at least this fraction of the learned blob's area (at the current
// scale), and at most its inverse: a tilt to 60 degrees halves a disc's area.
inline constexpr double kMinBlobAreaRatio = 0.4;
// A blob at a match with less than this fraction of the learned area is cut (Verify): its
// centroid is not the marker's centre.
inline constexpr double kCutBlobAreaRatio = 0.8;
// How far the gray-level match (ZNCC with the first template) lies below the log-chromaticity
// one where the light changed across the marker (a shadow over part of it): 0.38-0.42 measured
// there, at most 0.23 where a match loses both together (motion blur, a turn, perspective).
inline constexpr double kShadedZnccGap = 0.3;
// A match may move onto its blob by at least this much (px; more for larger templates).
inline constexpr double kMinBlobShiftPx = 2.0;
// A blob this close to where the match puts it agrees with the match (px). Beyond it, the
// match has drifted off the marker (the box's surroundings changed with the pose) and the
// blob's centroid is reported: a match carried 1.9 px off a marker's centre on a physically
// rendered bend, where its blob was 1.0 px off.
inline constexpr double kBlobAgreePx = 0.75;

// The one channel a template's blob is measured in: native gray, or colour projected on its
// axis (`projection`, see ContrastProjection; empty: luma).
void BlobChannelOf(const cv::Mat& native, const cv::Mat& projection, cv::Mat& out);

// The Chebyshev distance (max(|dx|, |dy|)) from each pixel of `area` to the nearest nonzero pixel
// of `label` (CV_8UC1) at most 4 away, 5 where there is none, into the same pixels of `dist`
// (CV_8UC1, label's size; nothing else of it is written). Separable: per row, the distance to
// the row's nearest label pixel (16 pixels at a time: the pixels k to either side looked at for
// k = 4 .. 0; a pass each way without vector code), then per pixel the least max(|dy|, that
// distance) over the rows within 4, in 8-bit lanes. Looking at the 81 pixels within 4 of each
// pixel (the reference) was a quarter of the work of three ZNCC templates' frame (issue 45).
// `row_distance` is reused storage.
void CappedChebyshevDistance(const cv::Mat& label, const cv::Rect& area, cv::Mat& dist,
                             std::vector<uint8_t>& row_distance);
// The reference: every pixel within 4 of each pixel looked at.
void CappedChebyshevDistanceReference(const cv::Mat& label, const cv::Rect& area, cv::Mat& dist);

// The ZNCC map of `templ` over `image` (gray or colour, as MatchZncc) where the look-alike scan
// reads it (MatchZncc's values there, bit for bit): every placement within kLookAlikeReachPx of
// one whose match with `half` (the template's half-resolution level, its pyramid's; nullptr:
// none) over the image's half-resolution level scores `floor` - kLookAlikeSlack or more; NaN
// (no match) elsewhere. A place the full-resolution template fits by `floor` fits its
// half-resolution one about as well (both smoothed alike). The whole map was matched before, a
// tenth of mire-2's instructions for its five templates, once (issue 45). The whole map when
// there is no half-resolution level or it passes more than an eighth of its places.
struct LookAlikeScratch {
  cv::Mat half_image, half_sim, wanted, part;
};
void LookAlikeZncc(const cv::Mat& image, const PreparedTemplate& templ,
                   const PreparedTemplate* half, double floor, cv::Mat& sim,
                   LookAlikeScratch& scratch, ZnccScratch& zncc);

// BlobMeter's passes over the pixels of `grown` (inside `gray`, CV_8UC1, and `mask`, empty or
// CV_8UC1 of its size; `dist` the capped Chebyshev distance to the component `label`, both of
// gray's size and continuous). The levels right at the blob: the sums and counts of the marker's
// interior (the component's pixels whose 4 neighbours are all in it) and of the ring 3-4 px
// outside it. A component pixel (distance 0) is off the patch's edge, so its four neighbours are
// in the patch. The sums are of whole levels: exact in a double, and the same in vector lanes.
struct BlobRimSums {
  double fg_sum = 0, bg_sum = 0;
  int fg_n = 0, bg_n = 0;
};
BlobRimSums RimLevelSums(const cv::Mat& gray, const cv::Mat& mask, const cv::Mat& dist,
                         const cv::Mat& label, const cv::Rect& grown);
BlobRimSums RimLevelSumsReference(const cv::Mat& gray, const cv::Mat& mask, const cv::Mat& dist,
                                  const cv::Mat& label, const cv::Rect& grown);
// The soft centroid's sums over the pixels within 2 px of the component (distance <= 2) inside the
// mask: each pixel's Membership between `bg` and `fg` (w), and w * x, w * y. Unmasked in double
// vector lanes, two pixels a vector: each w is the reference's, bit for bit, summed in another
// order (w * y as a row's sum of w times y; the sums agree to ~1e-15 of themselves). The blob is
// measured in every frame (issue 45).
struct SoftCentroidSums {
  double w = 0, x = 0, y = 0;
};
SoftCentroidSums SoftCentroid(const cv::Mat& gray, const cv::Mat& mask, const cv::Mat& dist,
                              const cv::Rect& grown, double bg, double fg);
SoftCentroidSums SoftCentroidReference(const cv::Mat& gray, const cv::Mat& mask,
                                       const cv::Mat& dist, const cv::Rect& grown, double bg,
                                       double fg);
// SoftCentroid with every pixel's weight computed in its lanes, never read from the table of the
// levels' weights it takes on large boxes: the same sums to the bit (the tests compare them).
SoftCentroidSums SoftCentroidComputed(const cv::Mat& gray, const cv::Mat& mask,
                                      const cv::Mat& dist, const cv::Rect& grown, double bg,
                                      double fg);

// A cv::Mat whose copies have their own pixels (cv::Mat's share them): BlobMeter's label_, which
// FillUnmasked clears only where its last component was, would otherwise hold a copy's marks
// there too.
struct OwnPixels : cv::Mat {
  OwnPixels() = default;
  OwnPixels(const OwnPixels& other) : cv::Mat(other.clone()) {}
  OwnPixels& operator=(const OwnPixels& other) {
    if (this != &other) other.copyTo(*this);
    return *this;
  }
  OwnPixels(OwnPixels&&) = default;
  OwnPixels& operator=(OwnPixels&&) = default;
};

class BlobMeter {
 public:
  // Learns the marker's polarity from the selected template (one channel): true when its centre
  // is a blob that lies wholly inside the template (mask), with `centroid` its soft centroid. The
  // polarity is the one in which the centre stands out more from what surrounds it (a bright
  // dot, or a dark one, on a band that may itself be brighter or darker than the background).
  bool Learn(const cv::Mat& gray, const cv::Mat& mask, cv::Point2d* centroid) {
    const cv::Point2d centre = HalfSize(gray.size());
    double best = -1, best_pixels = 0;
    bool best_bright = true;
    learned_contrast_ = 0;
    for (const bool bright : {true, false}) {
      bright_ = bright;
      double low = 0, high = 0;
      contrast_ = 0;
      const bool segmented = Segment(gray, mask, centre, &low, &high);
      learned_contrast_ = std::max(learned_contrast_, contrast_);
      if (!segmented) continue;
      // A highlight or glint on a domed marker stands out more than the marker, and is a small
      // part of it: the much larger blob is the marker.
      const double pixels = cv::countNonZero(label_(box_));
      const bool much_larger = pixels > kMarkerOverGlint * best_pixels;
      const bool much_smaller = best_pixels > kMarkerOverGlint * pixels;
      if (best < 0 || much_larger || (!much_smaller && high - low > best)) {
        best = high - low;
        best_pixels = pixels;
        best_bright = bright;
      }
    }
    if (best < 0) return false;
    bright_ = best_bright;
    double area = 0;
    if (!Measure(gray, mask, centre, centroid, &area)) return false;
    area_ = area;
    double lo = 0, hi = 0;
    cv::minMaxLoc(gray, &lo, &hi, nullptr, nullptr, mask.empty() ? cv::noArray() : mask);
    range_ = hi - lo;
    // The component is kept for asymmetry_px, measured there on first use: most meters are
    // learned to judge a box (JudgeBox) or for the channel SetTemplate does not keep, and never
    // asked (issue 45: the smallest enclosing circle of its pixels cost ~0.75M instructions a
    // meter, 4 % of the ZNCC session's on ViSP's mire-2).
    label_(box_).copyTo(learned_blob_);
    asymmetry_known_ = false;
    return true;
  }

  // After Learn: how far the learned blob's centroid lies from the centre of its smallest
  // enclosing circle, px (about 0 for a whole disc or any shape symmetric about its centre). A
  // crescent (a pale dome whose top the exposure clipped to white) puts the marker's centre
  // anywhere between the two: the reference point of every match carries that (the sigma's).
  double asymmetry_px() {
    if (!asymmetry_known_) {
      asymmetry_ = Asymmetry(learned_blob_);
      asymmetry_known_ = true;
    }
    return asymmetry_;
  }

  // How much the learned blob stands out, after Learn: the levels between it and the level at
  // which it would join its surroundings, as a fraction of the patch's whole range of levels (a
  // channel in which a shadow beside the marker is nearly as dark as the marker scores less than
  // one in which only the marker differs).
  double isolation() const { return range_ > 0 ? contrast_ / range_ : 0.0; }
  // After Learn, true or false: the most levels by which the centre stood out from the level at
  // which it would join the patch's edge, in either polarity (what a refusal reports).
  double learned_contrast() const { return learned_contrast_; }

  // The soft centroid of the marker-side component nearest `guess` (patch coordinates), and its
  // area in px (sum of weights). False when there is no such component within 2 px of the guess,
  // when it touches the patch or mask border (not separated from its surroundings), or when the
  // patch has too little contrast.
  bool Measure(const cv::Mat& gray, const cv::Mat& mask, const cv::Point2d& guess,
               cv::Point2d* centroid, double* area) {
    double low = 0, high = 0;
    if (!Segment(gray, mask, guess, &low, &high)) return false;
    return MeasureSegmented(gray, mask, low, high, centroid, area);
  }

  // Measure of the component the last successful Locate found, with the same `gray` and `mask`
  // (and guess): the segmentation is not done a second time (issue 45: it was 9 % of a frame of
  // three ZNCC templates on colour footage, where the blob is measured in every frame).
  bool MeasureLocated(const cv::Mat& gray, const cv::Mat& mask, cv::Point2d* centroid,
                      double* area) {
    return MeasureSegmented(gray, mask, located_low_, located_high_, centroid, area);
  }

  // The marker-side component nearest `guess`, as Measure finds it, with its binary centroid and
  // pixel count: a quick check that the blob is there (a fraction of Measure's cost).
  bool Locate(const cv::Mat& gray, const cv::Mat& mask, const cv::Point2d& guess,
              cv::Point2d* centroid, double* area) {
    if (!Segment(gray, mask, guess, &located_low_, &located_high_)) return false;
    double m00 = 0, m10 = 0, m01 = 0;
    if (filled_moments_) {
      // FillUnmasked counted the component as it filled it: the binary moments cv::moments
      // gives, exact whole numbers (relative to the box), without a pass over label_.
      m00 = static_cast<double>(fill_count_);
      m10 = static_cast<double>(fill_sum_x_ - fill_count_ * box_.x);
      m01 = static_cast<double>(fill_sum_y_ - fill_count_ * box_.y);
    } else {
      const cv::Moments m = cv::moments(label_(box_), true);
      m00 = m.m00;
      m10 = m.m10;
      m01 = m.m01;
    }
    if (!(m00 > 0)) return false;
    *centroid = cv::Point2d(box_.tl()) + cv::Point2d(m10 / m00, m01 / m00);
    *area = m00;
    return true;
  }

  // Tests only: segment with the reference flood and fill (the pixel-at-a-time priority queue
  // of vectors and the stack fill, Segment's definition) even where the fast ones apply.
  void use_reference(bool reference) { reference_ = reference; }
  // Tests only: how many floods took their pass from PassByFills, and how many went on to the
  // edge when the fills ran out of budget.
  int passes_by_fills() const { return passes_by_fills_; }
  int fills_given_up() const { return fills_given_up_; }
  // After Segment: the component's pixels (1) and its box (what the tests compare).
  const cv::Mat& label() const { return label_; }

  double area() const { return area_; }  // At selection, px.
  // The bounding box of the component the last Segment found (patch coordinates): after Learn,
  // the learned blob's.
  const cv::Rect& blob_box() const { return box_; }

 private:
  // asymmetry_px of the learned component `blob` (label_ over box_ at Learn).
  static double Asymmetry(const cv::Mat& blob) {
    std::vector<cv::Point> points;
    cv::findNonZero(blob, points);
    if (points.size() < 3) return 0.0;
    cv::Point2f centre;
    float radius = 0;
    cv::minEnclosingCircle(points, centre, radius);
    const cv::Moments m = cv::moments(blob, true);
    if (!(m.m00 > 0)) return 0.0;
    return cv::norm(cv::Point2d(m.m10 / m.m00, m.m01 / m.m00) - cv::Point2d(centre));
  }

  // Measure's work once Segment has found the component (label_, box_) and its levels.
  bool MeasureSegmented(const cv::Mat& gray, const cv::Mat& mask, double low, double high,
                        cv::Point2d* centroid, double* area) {
    const cv::Rect box = box_;
    // The levels right at the blob: the marker's from its interior (pixels whose 4 neighbours are
    // all in the component), the background's from a ring 3-4 px outside it. Levels of the patch
    // would take them from the whole patch, where shading and texture of the surroundings differ
    // from what is at the rim.
    const cv::Rect grown = cv::Rect(box.x - 4, box.y - 4, box.width + 8, box.height + 8) &
                           cv::Rect(0, 0, gray.cols, gray.rows);
    dist_.create(gray.size(), CV_8UC1);
    CappedChebyshevDistance(label_, grown, dist_, row_distance_);
    const BlobRimSums rim = RimLevelSums(gray, mask, dist_, label_, grown);
    const double fg = rim.fg_n > 0 ? rim.fg_sum / rim.fg_n : (bright_ ? high : low);
    const double bg = rim.bg_n > 0 ? rim.bg_sum / rim.bg_n : (bright_ ? low : high);
    if (!(std::abs(fg - bg) >= kMinBlobContrast)) return false;
    // Soft centroid over the component grown by 2 px (its anti-aliased rim), inside the mask.
    const SoftCentroidSums soft = SoftCentroid(gray, mask, dist_, grown, bg, fg);
    const double sw = soft.w, sx = soft.x, sy = soft.y;
    if (!(sw > 0)) return false;
    *centroid = {sx / sw, sy / sw};
    *area = sw;
    return true;
  }

  // The marker-side component around `guess`, isolated from the patch's edge: from the most
  // marker-like pixel within 2 px of the guess, the level at which it would join the patch's (or
  // the mask's) edge is the lowest (bright marker) level on the best path out: the pass. The
  // component is cut half way between the marker's own level (its core) and the pass, so a dot on
  // a band over a background (a yellow dot on a green cart on a dark table) is the dot, not the
  // band: a single split of the patch's levels would cut between band and background.
  // `low`/`high` get the background's and marker's levels (for a dark marker, the other way
  // round). False when the marker does not stand out by kMinBlobContrast from its pass.
  bool Segment(const cv::Mat& gray, const cv::Mat& mask, const cv::Point2d& guess, double* low,
               double* high) {
    filled_moments_ = false;
    const std::optional<cv::Point> seed = ExtremeNear(gray, mask, guess);
    if (!seed) return false;
    // Every frame's blob is unmasked (BlobShift), in a continuous patch: there the flood and the
    // fill run on pixel indices (issue 45: the vector-of-points flood, the fill and cv::moments
    // were 16 % of a frame of three ZNCC templates). Same component, same levels, same bits.
    if (!reference_ && mask.empty() && gray.isContinuous()) {
      int pass = -1;
      FloodUnmasked(gray, *seed, &pass);
      return Cut(gray, mask, *seed, pass, low, high);
    }
    // A priority flood from the seed, most marker-like first (256 buckets of marker-likeness):
    // the first edge pixel it takes sets the pass.
    for (auto& bucket : buckets_) bucket.clear();
    ZeroedMask(gray.size(), visited_);
    // Pixels through pointers (this runs on every frame's blob, issue 45): 255 - v is v ^ 255.
    const int flip = bright_ ? 0 : 255;
    const uint8_t* levels = gray.data;
    const size_t step = gray.step[0];
    const uint8_t* inside = mask.data;  // No mask: every pixel of the patch counts.
    const size_t mask_step = inside ? mask.step[0] : 0;
    uint8_t* visited = visited_.data;  // Continuous, gray.cols a row.
    const int cols = gray.cols;
    int level = levels[seed->y * step + seed->x] ^ flip;
    buckets_[level].push_back(*seed);
    visited[seed->y * cols + seed->x] = 1;
    core_.clear();
    int pass = -1;
    while (pass < 0) {
      while (level >= 0 && buckets_[level].empty()) --level;
      if (level < 0) break;
      const cv::Point p = buckets_[level].back();
      buckets_[level].pop_back();
      if (p.x == 0 || p.y == 0 || p.x == gray.cols - 1 || p.y == gray.rows - 1) {
        pass = level;
        break;
      }
      if (core_.size() < kCoreSamples) core_.push_back(level);
      // Off the patch's edge, so the four neighbours are in the patch: only the mask can leave.
      const cv::Point next[4] = {{p.x + 1, p.y}, {p.x - 1, p.y}, {p.x, p.y + 1}, {p.x, p.y - 1}};
      for (const cv::Point& q : next) {
        uint8_t& seen = visited[q.y * cols + q.x];
        if (seen) continue;
        seen = 1;
        if (inside && !inside[q.y * mask_step + q.x]) {
          pass = level;  // The mask's edge: the flood leaves here at this level.
          break;
        }
        const int l = levels[q.y * step + q.x] ^ flip;
        buckets_[std::min(l, level)].push_back(q);  // A path's level is its least marker-like.
      }
    }
    return Cut(gray, mask, *seed, pass, low, high);
  }
  // Segment's end, once the flood has found the pass and the core's levels (core_): the cut and
  // the component above it.
  bool Cut(const cv::Mat& gray, const cv::Mat& mask, cv::Point seed, int pass, double* low,
           double* high) {
    if (pass < 0 || core_.empty()) return false;
    // The marker's own level: the median of its most marker-like pixels (robust to one glint).
    std::nth_element(core_.begin(), core_.begin() + core_.size() / 2, core_.end());
    const int core = core_[core_.size() / 2];
    contrast_ = core - pass;
    if (contrast_ < kMinBlobContrast) return false;
    const double cut = (core + pass) / 2.0;
    const double marker_level = bright_ ? core : 255 - core;
    const double pass_level = bright_ ? pass : 255 - pass;
    *low = std::min(marker_level, pass_level);
    *high = std::max(marker_level, pass_level);
    if (!reference_ && mask.empty() && gray.isContinuous()) {
      // In marker-likeness (v ^ flip) a whole level is beyond the cut exactly when it is above
      // its whole part: v > cut for a bright marker, 255 - v > cut for a dark one.
      return FillUnmasked(gray, seed, static_cast<int>(std::floor(cut)));
    }
    return Fill(gray, mask, seed, bright_ ? cut : 255 - cut);
  }
  // Segment's priority flood for an unmasked, continuous patch: the same pushes and pops in the
  // same order (each bucket last in, first out) as the reference above, on pixel indices, with
  // the buckets as lists threaded through next_ (a pixel is pushed at most once) instead of
  // vectors of points. Sets core_ and *pass (-1: none).
  void FloodUnmasked(const cv::Mat& gray, cv::Point seed, int* pass);
  // The pass of FloodUnmasked's patch without the rest of its flood, once the flood has taken
  // its core: the greatest marker-likeness t for which the pixels of t or more 4-connected to
  // `seed` reach the patch's edge (a path's level is its least marker-like pixel, so that is the
  // level at which the flood would leave), no greater than `upper` (the flood's level, which no
  // pixel left above it reaches the edge from). Searched from the last patch's pass by fills
  // of those pixels a row span at a time. -1 when the fills took more than `budget` spans (a
  // patch of short spans, say noise: the flood is cheaper there).
  int PassByFills(const cv::Mat& gray, cv::Point seed, int upper, int budget);
  // PassByFills' question for one level t (1..255): 1 when the pixels of marker-likeness t or
  // more 4-connected to `seed` (which is one) reach the patch's edge, 0 when not, -1 when
  // *budget (spans) ran out first.
  int ReachesEdge(const cv::Mat& gray, cv::Point seed, int t, int* budget);
  // Fill's component for an unmasked, continuous patch, a row span at a time: the pixels whose
  // marker-likeness is above `cut` 4-connected to `seed` (which counts, as in Fill) into label_
  // and box_, with their count and coordinate sums for Locate. False when it reaches the patch's
  // edge.
  bool FillUnmasked(const cv::Mat& gray, cv::Point seed, int cut);
  // The most marker-like pixel within 2 px of `guess` (the nearest of equals).
  std::optional<cv::Point> ExtremeNear(const cv::Mat& gray, const cv::Mat& mask,
                                       const cv::Point2d& guess) const {
    std::optional<cv::Point> seed;
    int best = -1;
    double nearest = 0;
    const int gx = static_cast<int>(std::lround(guess.x)), gy = static_cast<int>(std::lround(guess.y));
    for (int y = gy - 2; y <= gy + 2; ++y) {
      for (int x = gx - 2; x <= gx + 2; ++x) {
        if (!IsInside(gray, mask, x, y)) continue;
        const int v = gray.at<uint8_t>(y, x);
        const int l = bright_ ? v : 255 - v;
        const double d = (x - guess.x) * (x - guess.x) + (y - guess.y) * (y - guess.y);
        if (l > best || (l == best && d < nearest)) {
          best = l;
          nearest = d;
          seed = cv::Point(x, y);
        }
      }
    }
    return seed;
  }
  // `out` made `size`, CV_8UC1, all 0: create() gives a continuous buffer, cleared by one memset
  // (cv::Mat::setTo fills it byte by byte: issue 45).
  static void ZeroedMask(cv::Size size, cv::Mat& out) {
    out.create(size, CV_8UC1);
    std::memset(out.data, 0, out.total());
  }
  bool IsInside(const cv::Mat& gray, const cv::Mat& mask, int x, int y) const {
    // No mask: no data (cv::Mat::empty() is a call into OpenCV, and this runs for every pixel).
    return x >= 0 && y >= 0 && x < gray.cols && y < gray.rows &&
           (mask.data == nullptr || mask.at<uint8_t>(y, x));
  }
  // 4-connected flood fill of the marker side from `seed` into label_ (its bounding box in
  // box_). False when it reaches the patch's or the mask's edge: not separated there.
  bool Fill(const cv::Mat& gray, const cv::Mat& mask, cv::Point seed, double threshold) {
    ZeroedMask(gray.size(), label_);
    // Its pixels are marked as they are pushed, some outside box_ when it stops at an edge.
    label_dirty_ = cv::Rect(0, 0, gray.cols, gray.rows);
    stack_.clear();
    stack_.push_back(seed);
    // Through pointers, as Segment's flood; the box as its corners, written to box_ on the way
    // out (what box_ |= pixel gave).
    const uint8_t* levels = gray.data;
    const size_t step = gray.step[0];
    const uint8_t* inside = mask.data;
    const size_t mask_step = inside ? mask.step[0] : 0;
    uint8_t* label = label_.data;  // Continuous, gray.cols a row.
    const int cols = gray.cols;
    label[seed.y * cols + seed.x] = 1;
    int x0 = seed.x, y0 = seed.y, x1 = seed.x, y1 = seed.y;  // Inclusive.
    const auto done = [&](bool separated) {
      box_ = cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
      return separated;
    };
    while (!stack_.empty()) {
      const cv::Point p = stack_.back();
      stack_.pop_back();
      if (p.x == 0 || p.y == 0 || p.x == gray.cols - 1 || p.y == gray.rows - 1) return done(false);
      x0 = std::min(x0, p.x);
      y0 = std::min(y0, p.y);
      x1 = std::max(x1, p.x);
      y1 = std::max(y1, p.y);
      // Off the patch's edge: the four neighbours are in the patch; only the mask can leave.
      const cv::Point next[4] = {{p.x + 1, p.y}, {p.x - 1, p.y}, {p.x, p.y + 1}, {p.x, p.y - 1}};
      for (const cv::Point& q : next) {
        if (inside && !inside[q.y * mask_step + q.x]) return done(false);  // The mask's edge.
        uint8_t& in = label[q.y * cols + q.x];
        if (in) continue;
        const double v = levels[q.y * step + q.x];
        if (!(bright_ ? v > threshold : v < threshold)) continue;  // IsMarker.
        in = 1;
        stack_.push_back(q);
      }
    }
    return done(true);
  }

  // The marker's level is the median of its this many most marker-like pixels.
  static constexpr size_t kCoreSamples = 9;
  bool bright_ = true;
  double area_ = 0;
  double contrast_ = 0;
  double learned_contrast_ = 0;
  double range_ = 0;
  double asymmetry_ = 0;  // asymmetry_px(), once asymmetry_known_.
  bool asymmetry_known_ = true;  // Nothing learned: 0.
  OwnPixels learned_blob_;  // Learn's component (label_ over box_), for asymmetry_px.
  double located_low_ = 0, located_high_ = 0;  // The last Locate's levels, for MeasureLocated.
  bool reference_ = false;  // use_reference.
  // FillUnmasked's count and coordinate sums of the component (frame of the patch), valid when
  // filled_moments_.
  bool filled_moments_ = false;
  int64_t fill_count_ = 0, fill_sum_x_ = 0, fill_sum_y_ = 0;
  // FloodUnmasked's storage, kept from call to call: the buckets' first pixels, each pixel's
  // next one in its bucket, and the patch's edge pixels (1) for the patch size edge_size_.
  std::array<int, 256> heads_{};
  std::vector<int> next_;
  // PassByFills' start: the last pass found (patches of one marker in consecutive frames mostly
  // leave at the same level, or one off), and its fills' marks: a pixel is in the current fill
  // when it holds mark_ (the marks cleared only when mark_ wraps, or the patch's size changes).
  int last_pass_ = -1;
  int passes_by_fills_ = 0, fills_given_up_ = 0;
  std::vector<uint8_t> marks_;
  uint8_t mark_ = 0;
  cv::Size marks_size_;
  std::vector<uint8_t> edge_;
  cv::Size edge_size_;
  // FloodUnmasked's visited pixels: those whose byte is seen_tag_ (a vector, not a cv::Mat: a
  // copy of the meter gets its own bytes, where a cv::Mat's would be shared and its tags mixed).
  std::vector<uint8_t> seen_;
  cv::Size seen_size_;
  uint8_t seen_tag_ = 0;
  OwnPixels label_;
  // Where label_ may hold marks (the rest is 0): FillUnmasked clears only there, not the whole
  // patch (issue 45: clearing it took more instructions than the fill's component).
  cv::Rect label_dirty_;
  cv::Mat dist_, visited_;
  std::vector<uint8_t> row_distance_;  // CappedChebyshevDistance's scratch.
  cv::Rect box_;
  std::vector<cv::Point> stack_;
  std::array<std::vector<cv::Point>, 256> buckets_;
  std::vector<int> core_;
};

// One match of a template in a searched region.
struct Hit {
  cv::Point top_left;          // Integer best placement in frame coordinates.
  cv::Point2d offset{0, 0};    // Sub-pixel offset from it.
  double similarity = 0;       // Map value at the integer best (higher is better), for ranking.
  double score = 0;            // The reported score (see the header).
  double zncc = 1;             // ZNCC at the same placement (= score for ZNCC).
  double rival_zncc = kNoRival;  // ZNCC of the best distinct second peak in the region.
  cv::Point rival_top_left;    // Its placement (when rival_zncc is finite).
  bool on_inner_edge = false;  // Best on a window edge that is not the frame's: may lie outside.
};

// The first template at one scale and turn: a rung of the ladder.
struct Rung {
  bool tried = false;      // Preparation attempted (templ empty: this scale is impossible).
  PreparedTemplate templ;  // Masked like the working template (turned: also to what turned in).
  cv::Point2d anchor;      // The reported point, in this rung's template coordinates.
  cv::Point2d blob_anchor;  // The template's blob's centroid, likewise.
};

// The first template `original` scaled to `size` as TurnedTemplate scales it (a header of it when
// of that size already).
cv::Mat ScaledTemplate(const cv::Mat& original, const cv::Size& size);
// The first template `original` scaled to `size` and turned by `turn_deg` about its centre (a
// positive angle turns +x towards +y: clockwise on the screen, y pointing down), into `out`,
// with its mask: `shape` (the round mask at `size`, or empty) cut to the pixels that come from
// inside the template. `map` gets the transform from scaled to turned template coordinates.
void TurnedTemplate(const cv::Mat& original, const cv::Size& size, double turn_deg,
                    const cv::Mat& shape, cv::Mat* out, cv::Mat* mask, cv::Matx23d* map);

// The first template's measurement of the marker, in frame coordinates.
struct Fix {
  cv::Point2d centre;    // The matched rung's geometric centre (where the next search looks).
  cv::Point2d reported;  // The rung's anchor: the position reported.
  double zncc = 0;       // ZNCC with the first template at that scale.
  double score = 0;      // The measure's score against it (see the header).
};

// The single channel that shows the template best: BGR projected on the template's principal
// colour axis (the direction of largest colour variance, i.e. marker against band), with weights
// of L1 norm 1 and an offset that keeps every value in 0..255. On a gray template (B = G = R, a
// mono camera) the axis is (1, 1, 1) / 3: the channel mean, which is luma there.
cv::Mat ContrastProjection(const cv::Mat& bgr);

// The template update's blend: the patch of `running`'s size centred at `centre` (in `image`'s
// pixels, its geometric centre, as cv::getRectSubPix places it) sampled bilinearly from `image`
// (CV_8UC1 or CV_8UC3), blended into `running` (CV_32F of the patch's channels) as
// running * (1 - rate) + patch * rate, and `running` rounded (nearest even, saturated) into
// `rounded` (CV_8U). The patch must lie inside `image` with a pixel to spare right and below.
// Gray in float vector lanes, 8 pixels at a time, without the patch's buffer: the three OpenCV
// calls of BlendPatchReference cost ~40 instructions a pixel (the template update, every frame,
// issue 45). The same float arithmetic but for the order of the bilinear weights' products
// (and OpenCV's build may fuse multiply-adds): `running` within a few float roundings of the
// reference's, `rounded` within a level. Colour, or a patch at the image's edge, runs the
// reference with `patch` as its buffer (kept by the caller: no allocation from frame to frame).
void BlendPatch(const cv::Mat& image, const cv::Point2d& centre, double rate, cv::Mat& running,
                cv::Mat& rounded, cv::Mat& patch);
// The definition: cv::getRectSubPix (CV_32F), cv::addWeighted and convertTo(CV_8U), with
// `patch` as the first one's buffer.
void BlendPatchReference(const cv::Mat& image, const cv::Point2d& centre, double rate,
                         cv::Mat& running, cv::Mat& rounded, cv::Mat& patch);

// `bgr` (8-bit BGR) projected with `projection` (1x4 CV_32F: B, G, R weights and an offset, as
// ContrastProjection and MarkerProjection make), as cv::transform does: per pixel, in float,
// ((wb * B + wg * G) + wr * R) + offset, rounded to nearest even and saturated to 0..255, 16
// pixels at a time in float vector lanes. cv::transform's 3-to-1 projection is scalar (~35
// instructions a pixel; the template tracker converts its windows with it every frame, issue 45)
// and OpenCV's build may fuse its multiply-adds, so a level may differ from cv::transform's by 1
// where the sum lies within a rounding of a half (tens in millions of pixels); bit for bit
// ProjectLevelsReference.
void ProjectLevels(const cv::Mat& bgr, const cv::Mat& projection, cv::Mat& out);
// The same, a pixel at a time: the definition.
void ProjectLevelsReference(const cv::Mat& bgr, const cv::Mat& projection, cv::Mat& out);

// The single channel a selected box (BGR, with the template's `mask`) shows its marker in best:
// of the principal colour axis (ContrastProjection), luma (an empty matrix) and the axis from the
// box's edge colour to its centre's, the one in which the blob at the centre is most isolated
// from its surroundings (BlobMeter::isolation). The principal axis when none shows a blob.
cv::Mat MarkerProjection(const cv::Mat& bgr, const cv::Mat& mask);

// ---- The marker's colour, for its blob --------------------------------------------------------
// On colour footage a template's blob is measured in the marker's chromaticity (each pixel's BGR
// over its sum), projected on the axis from the box's edge to its centre. A light from one side
// shades a domed marker from bright to dark across its face: in any gray channel its blob's
// centroid moves 2-4 px towards the lit flank (a physically rendered bench), while the
// chromaticity hardly changes with the light's strength. Dark pixels' chromaticity is noise: the
// sum is damped by kChromaDarkLevels (track/chromaticity.h).
struct ChromaAxis {
  cv::Vec3d background;  // Chromaticity of the box's edge.
  cv::Vec3d axis;        // Unit vector from it towards the marker's (the box's centre).
  double span = 0;       // The marker's distance along the axis.
};
// Below this span the marker's colour is the background's (a white dot on grey): no axis.
inline constexpr double kMinChromaSpan = 0.05;
// The axis of `bgr` (a selected template, 8-bit BGR); false when its centre's chromaticity does
// not differ from its edge's.
bool LearnChromaAxis(const cv::Mat& bgr, ChromaAxis* out);
// One 8-bit channel: the background at 40, the marker at 200. The pixels' arithmetic in float
// vector lanes, 16 pixels at a time: ChromaChannelReference's levels to within one (the template
// tracker's blob is measured in it every frame).
void ChromaChannel(const cv::Mat& bgr, const ChromaAxis& chroma, cv::Mat& out);
// The same, a pixel at a time: the definition.
void ChromaChannelReference(const cv::Mat& bgr, const ChromaAxis& chroma, cv::Mat& out);


// The colour of a marker's core: the chromaticity (B, G, R over their sum) of the mean colour of
// a disc of `radius` px at `centre` in `bgr` (8-bit BGR). A match in one channel is blind to hue:
// three discs of one size look alike to a gray template, and only their colour tells the green
// one it was cut around from the blue one. False when the disc leaves the image or is too dark
// for its colour to mean anything (a mean of B + G + R under kDarkCoreLevels).
inline constexpr double kDarkCoreLevels = 60.0;
bool CoreColour(const cv::Mat& bgr, const cv::Point2d& centre, double radius, cv::Vec3d* chroma);
// Chromaticity distance beyond which a place shows another marker's colour, not this one's. The
// lights a template meets after it was cut move a core's chromaticity by up to about 0.06 (white
// under a warm side light); markers a person tells apart by colour lie 0.3-0.6 apart.
inline constexpr double kOtherColourDistance = 0.15;
// A match whose core shows the marker's own colour (within this distance) is a second, independent
// piece of evidence: it is accepted down to min_zncc - kColourZnccAllowance. A marker smeared by
// fast motion or turned against its template matches its template's gray levels less well
// (0.72-0.79 for a blurred tip that a person sees plainly) while its colour stays its own.
// Only a coloured marker's (one whose core lies kMinCoreChroma or more from grey): every grey
// place agrees with a white dot's colour.
inline constexpr double kSameColourDistance = 0.06;
inline constexpr double kMinCoreChroma = 0.06;
// Whether a core's chromaticity (CoreColour) is a coloured marker's: kMinCoreChroma or more from
// grey. A white or black dot's chromaticity is its surroundings' and the camera noise's.
inline bool IsColouredCore(const cv::Vec3d& chroma) {
  const cv::Vec3d from_grey = chroma - cv::Vec3d(1.0, 1.0, 1.0) / 3.0;
  return std::sqrt(from_grey.dot(from_grey)) >= kMinCoreChroma;
}
inline constexpr double kColourZnccAllowance = 0.1;

// A colour picture's log-chromaticity, CV_32FC2: per pixel log((r + k) / (g + k)) and
// log((b + k) / (g + k)), k = kLogChromaDarkLevels. A shadow falling on part of a template, or a
// change of the light's strength, scales a pixel's three channels alike and leaves these
// unchanged; a colour cast scales each channel by its own factor, which adds a constant that
// ZNCC cancels. k damps the ratios of dark pixels, whose noise is a large part of their levels.
inline constexpr double kLogChromaDarkLevels = 8.0;
// How far (px, per axis) from a match accepted in log-chromaticity alone its place is measured
// there again: the gray-level peak a shadow pulled off the marker lies within a pixel or two.
inline constexpr int kShadeFreeReachPx = 2;
void LogChromaticity(const cv::Mat& bgr, cv::Mat& out);
// ZNCC of two pictures of the same size and type, CV_32FC2, over both channels (each channel's
// mean removed), counting the pixels `mask` (CV_8U, or empty: all) sets; kNoRival when either
// shows no variation there.
double TwoChannelZncc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask);

// The marker's blob in a selected template (its foreground): the channel it shows best
// (`projection`: MarkerProjection on colour, else empty) and the blob learned in it. False
// when the template shows none.
bool LearnTemplateBlob(const cv::Mat& templ, const cv::Mat& mask, cv::Mat* projection,
                       BlobMeter* meter, cv::Point2d* anchor);

}  // namespace softsight::template_internal
