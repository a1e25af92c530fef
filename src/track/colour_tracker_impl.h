// ColourTracker: the colour-intensity tracker of paper section 2.1 behind the Tracker interface.
// Private to the track module (built through CreateTracker); tests include it for the internals.
//
// Per frame:
//  1. While tracking, analyse a window around the constant-velocity prediction; if no acceptable
//     blob is there, or a blob touches the window's border nearer than the best one (the marker
//     may extend outside), double the window widen_steps times.
//  2. Otherwise acquire on the whole frame (or the ROI before the first success): threshold a
//     shrunk copy to find candidate cells, analyse each candidate at full resolution.
// "Analyse a region" is always the same full-resolution pipeline on the region plus a margin
// wide enough that filter and morphology see exactly what a whole-frame pass would see, so a
// blob that lies inside the region (not touching its border) is bit-identical to the blob a
// whole-frame analysis finds.
#pragma once

#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/tracker.h"
#include "track/colour_kernels.h"
#include "track/rim_fit.h"

namespace softsight {

// One connected component of the marker mask, in frame coordinates. Centroid, circularity and
// the colour statistics are set only for complete blobs (not clipped) of acceptable area, the
// colour statistics only when the blob is compact enough to be a candidate (`measured`).
struct ColourBlob {
  cv::Point2d centroid_px;         // The reported one: soft or binary (ColourParams::centroid).
  cv::Point2d binary_centroid_px;  // m10/m00, m01/m00 of the mask.
  double area_px = 0;              // m00: pixel count.
  double circularity = 0;          // See ColourParams::min_circularity.
  cv::Rect bbox_px;
  bool clipped = false;            // Touches a region edge that is not a frame edge: incomplete.
  // Touches the frame's edge: the marker may go on beyond it, so its centroid is not the
  // marker's centre (never reported).
  bool at_frame_edge = false;
  // How far the binary centroid lies from the centre of the smallest circle enclosing the blob
  // (set with the colour statistics). About 0 for a whole disc, ellipse or any shape symmetric
  // about its centre, whatever its size (uniform shrinking under a dimmer light keeps it 0); a
  // marker partly covered shows the centroid's shift towards what is left of it.
  double asymmetry_px = 0;
  // The same for the blob's convex hull. A dome's highlight or a dark speck at its rim bites a
  // notch out of the blob that shifts its centroid (asymmetry_px) but not its hull's; a cover's
  // straight or convex edge shifts both.
  double hull_asymmetry_px = 0;
  // The radius of that smallest enclosing circle: the scale of the asymmetry (half the length of
  // an elongated sticker, where its centre rests on the two ends' pixels).
  double enclosing_radius_px = 0;
  // How far the binary centroid moves when the blob takes in its pale fringe: the pixels just
  // outside it (within the ring's reach, 4 px) that pass the range with its lower bounds of
  // saturation and brightness halved (a gray range's bound halved, or a dark dot's upper bound
  // raised half way to white). Where a range's floor cuts through the marker (a lit dome's
  // whitened top, the flank a lamp leaves in shade, a clipped plateau at a gray floor), what is
  // marker is uncertain by about this much: it widens the position's sigma.
  double fringe_shift_px = 0;
  // The same move (its direction too) from the fringe's pixels beyond the soft band, which the
  // soft centroid does not weigh. Where the range names a hue, the fringe is paler or darker
  // marker colour (not any bright or dark surface) and the soft centroid takes it in: the band's
  // pixels by their membership, these beyond it whole (fringe_placed). The sigma's half of the
  // whole fringe's shift says how far the edge may still lie either way.
  cv::Point2d fringe_pull_px;
  bool fringe_placed = false;  // centroid_px includes fringe_pull_px.
  bool measured = false;           // The colour statistics below are set.
  // Taken as the tracked marker in a shadow (it fits in everything but brightness where the
  // marker should be): its colour is not the marker's under the usual light, and is not learned.
  bool shaded = false;
  // Segmented by the dim pass (the range's brightness floor lowered): its area and shape are not
  // what the range gives, so they are not learned.
  bool dimmed = false;
  // Mean colour (B, G, R, or the gray level in [0]) of the blob's core (2 px inside its edge, or
  // the whole blob when that is empty) and of its surroundings (a ring 3-4 px outside, pixels of
  // other blobs excluded), with their RMS spread (over channels).
  cv::Vec3d core_colour, ring_colour;
  // Pixels deeper than the soft band inside the edge: of the marker's own colour, not mixed with
  // the background. 0 for a blob too small to have any (its colour is then the whole blob's).
  int core_px = 0;
  double core_sigma = 0, ring_sigma = 0;
  // How clearly the blob stands out from what surrounds it: per quarter of the ring,
  // |core - quarter| / (core spread / 2 + quarter spread + 2), the spreads measured along the
  // colour axis core - quarter; the median over the quarters. A printed or painted marker scores far above a patch of background texture.
  double contrast = 0;
  // The same against the whole ring at once, its spread over every channel: stricter where the
  // surroundings vary (shading, an edge beside the marker). What a whole-frame search with nothing
  // learned and no roi needs (init): there nobody showed the marker, and a patch of texture that
  // differs from part of its surroundings must not pass.
  double whole_ring_contrast = 0;
  // For a blob smaller than a round marker's learned area (set with the colour statistics): the
  // circle of the marker's radius fitted to its edge (track/rim_fit.h), whose centre is the
  // marker's when what is left of it shows enough of its rim (see RimCentre).
  std::optional<RimFit> rim;
  bool rim_placed = false;  // centroid_px is the rim's centre (a good fit: see RimCentre).
};

// What the tracker knows of its marker: learned at the first acquisition, adapted while tracking.
struct ColourModel {
  double area_px = 0;        // Reference area (Observation::score's denominator).
  double first_area_px = 0;  // The area when learned: area_px stays within 1/2..4x of it.
  double circularity = 1;
  cv::Vec3d colour;          // Core colour.
  // The marker's own asymmetry (ColourBlob::asymmetry_px) when whole: learned at acquisition and
  // following only downwards while tracking (a marker first seen partly covered is learned
  // whole later). A blob more asymmetric than this by more than the tolerance is partial.
  double asymmetry_px = 0;
};

class ColourTracker : public Tracker {
 public:
  // `params` must pass Check() (CreateTracker checks).
  explicit ColourTracker(const ColourParams& params);

  void init(const cv::Mat& frame_bgr, const cv::Rect& hint) override;
  bool start(const Frame& frame) override;
  Observation update(const cv::Mat& frame_bgr) override;
  void reset() override;
  const std::vector<MarkerCandidate>& candidates() const override { return candidates_; }
  std::optional<Observation> adopt(size_t index) override;
  bool membership(const cv::Mat& frame_bgr, cv::Mat& mask) const override;
  std::optional<cv::Rect> search_region() const override {
    return last_search_px_.empty() ? std::nullopt : std::optional<cv::Rect>(last_search_px_);
  }

  // ---- Internals exposed for tests and benchmarks ------------------------------------------------
  // Every complete blob of the frame, whole-frame search at full resolution or coarse-to-fine
  // (downsample >= 2); sorted by (y, x) of the centroid.
  void find_blobs(const cv::Mat& frame_bgr, int downsample, std::vector<ColourBlob>* blobs);
  // The factor the next whole-frame acquisition would use.
  int acquire_downsample() const;
  // Radius of the smallest blob that can count as the marker (a disc of the least acceptable area).
  double min_blob_radius_px() const;
  std::optional<double> reference_area_px() const {
    return model_ ? std::optional<double>(model_->area_px) : std::nullopt;
  }
  const std::optional<ColourModel>& model() const { return model_; }
  // The verdict on `blob` and its misfit (sum of the criteria, each 1 at its limit; infinite for a
  // rejection; kPartial is a blob that fits but is partly hidden, with its finite misfit). With
  // `any_brightness` the learned colour's brightness is not held against it (its chroma is).
  std::pair<CandidateVerdict, double> judge(const ColourBlob& blob,
                                            bool any_brightness = false) const;
  // Bounded side of the last region searched (for tests of the windowing).
  const cv::Rect& last_search_px() const { return last_search_px_; }
  // Tests only: without the tight first window (track_in_windows), the windows it stands for.
  void use_tight_window(bool use) { tight_window_ = use; }

 private:
  // Full-resolution pipeline on `region` (clipped to the frame); appends every blob with its
  // complete/clipped flag. Blobs below min_area_px are skipped unless clipped.
  // With `dimmed`, pixels are classified by the range with its brightness floor lowered (the
  // dim pass of track_in_windows).
  void analyse(const cv::Mat& frame, cv::Rect region, std::vector<ColourBlob>* blobs,
               bool dimmed = false);
  void analyse_region(const cv::Mat& frame, const cv::Rect& region,
                      std::vector<ColourBlob>* blobs, bool dimmed);
  // `src` with the channels the classifier needs (1 in gray mode, else 3), converted into `store`
  // when the frame has the other kind.
  cv::Mat prepare(const cv::Mat& src, cv::Mat& store);
  // Marker mask of `src` (prepared, filtered) into `mask`.
  void classify(const cv::Mat& src, bool coarse, cv::Mat& mask, bool dimmed = false);
  // The fine mask of an analysed region into `mask` (the size of `filtered`, the region `inner`
  // with its margin around it) and the bounding box of its nonzero pixels, which is all the
  // rest of the region's analysis reads of it; the margin is classified only when that can
  // change the region's result (see colour_blobs.cc).
  cv::Rect ClassifyRegion(const cv::Mat& filtered, cv::Mat& mask, const cv::Rect& inner,
                          bool dimmed);
  // Colour statistics and soft centroid of the labeller's `component`, whose box in the labelled
  // mask is `box`; `labelled_tl` is that mask's origin in `filtered` / `mask`, `origin` the
  // latter's in the frame.
  void measure(const cv::Mat& filtered, const cv::Mat& mask, int component, const cv::Rect& box,
               cv::Point labelled_tl, cv::Point origin, ColourBlob* blob);
  // ColourBlob::fringe_shift_px and fringe_pull_px of `blob` from the padded box's `pixels`, its mask `own`, its
  // edge zones `distance` and the other blobs `others`; `own_origin` is the box's place in the
  // frame.
  void measure_fringe(const cv::Mat& pixels, const cv::Mat& own, const cv::Mat& distance,
                      const cv::Mat& others, cv::Point own_origin, ColourBlob* blob);
  // The blob's asymmetry_px and hull_asymmetry_px from the labeller's `component` (its runs,
  // drawn into the blob's mask whose top-left pixel is `own_origin` in the frame and `own_tl` in
  // the labelled mask).
  void measure_asymmetry(int component, cv::Point own_tl, cv::Point own_origin, ColourBlob* blob);
  // A partial round blob: the circle of the marker's `radius` fitted to its edge (not where the
  // frame cuts it), and its centre as the centroid when the fit is good (RimCentre).
  // `own` is the blob's mask (holes filled), drawn from the labeller's `component` (whose runs
  // give its pixels) with its top-left pixel at `own_tl` in the labelled mask.
  void fit_rim(const cv::Mat& own, int component, cv::Point own_tl, cv::Point frame_origin,
               double radius, ColourBlob* blob);
  // Fills the holes of the blob's mask `own` (whose top-left pixel is `own_origin` in the frame)
  // and, when there were any, sets the blob's area, centroids and circularity from the filled
  // mask.
  void FillHoles(cv::Mat& own, cv::Point own_origin, ColourBlob* blob);
  // Every complete blob of `region`: analyse, growing the region around clipped blobs.
  void complete_blobs(const cv::Mat& frame, cv::Rect region, std::vector<ColourBlob>* blobs);
  // Coarse candidates -> full-resolution windows -> complete blobs.
  void coarse_to_fine(const cv::Mat& frame, cv::Rect region, int factor,
                      std::vector<ColourBlob>* blobs);
  // The full-resolution windows (into windows_) around the groups of the candidate cells
  // (points_, cells of `factor` x `factor` pixels of `region`, `cells` of them).
  void cell_group_windows(const cv::Rect& region, int factor, cv::Size cells,
                          const cv::Rect& frame_rect);

  // The outcome of one search: the chosen blob, or why there is none.
  struct Choice {
    std::optional<ColourBlob> blob;
    MarkerStatus status = MarkerStatus::kLost;
    int tied = 0;  // With kAmbiguous: how many candidates fitted about equally.
    bool hold = false;  // Not found, but partly seen where expected: keep the window there.
  };
  // The marker's centre from a partial blob's rim fit, when the fit is good: half of the rim or
  // more shows, the points on it lie within half a pixel of the circle, and none of the blob's
  // edge lies outside it.
  std::optional<cv::Point2d> RimCentre(const ColourBlob& blob) const;
  // The radius of the circle a round marker's edge pixels lie on; absent for markers that are
  // not round (their model's circularity below 0.85).
  std::optional<double> rim_radius_px() const;
  void check_frame(const cv::Mat& frame) const;
  Observation search(const cv::Mat& frame);  // update() without the snapshot.
  // `last_miss`: how far from its prediction the last frame's window found the marker.
  Choice track_in_windows(const cv::Mat& frame, std::optional<double> last_miss);
  // The marker darker than its range's floor where it should be (a shadow, the dim edge of the
  // light): `window`, around `predicted`, classified with the floor lowered; the one blob within
  // `reach` that fits the marker in everything but brightness, whole, around the sliver of it
  // the range still saw at `sliver`.
  Choice dim_search(const cv::Mat& frame, const cv::Rect& window, const cv::Point2d& predicted,
                    double reach, const cv::Point2d& sliver);
  Choice acquire(const cv::Mat& frame);
  // An acquisition's candidates (blobs_) ranked by cost: the best whole one, the runner-up's
  // cost, and the best partly hidden one's (which is never reported, but is a rival).
  struct Ranking {
    size_t best = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    double second_cost = std::numeric_limits<double>::infinity();
    double partial_cost = std::numeric_limits<double>::infinity();
    bool partial_at_edge = false;  // The best partial one is cut by the frame's edge.
  };
  // Judges every blob into candidates_ and ranks those that fit; `diagonal` is the frame's.
  Ranking rank_candidates(double diagonal);
  // A candidate's cost: its misfit, plus its distance from the last position over `diagonal`.
  double acquisition_cost(double misfit, const cv::Point2d& position_px, double diagonal) const;
  // kAmbiguous, with how many whole candidates cost within `margin` of the best; with
  // `by_uniqueness` every fitting candidate becomes a rival.
  Choice ambiguous_choice(double best_cost, double margin, double diagonal, bool by_uniqueness);
  // Whether the one candidate left, `only`, may be a look-alike among the rivals tied before:
  // it was one of them, in its place still, and another of them has vanished.
  bool a_rival_may_be_it(const ColourBlob& only) const;
  // Whether a blob kPieceAreaRatio times blobs_[chosen]'s area or more (of any shape) lies
  // beside it (within kPieceGapPx) in the roi.
  bool a_larger_piece_beside(size_t chosen) const;
  // After a lasting change of the light: the one blob near where the marker was last seen that
  // fits everything but the learned brightness, if there is exactly one.
  Choice relearn(const cv::Point2d& last_seen);
  Observation report(const Choice& choice);
  void learn(const ColourBlob& blob, bool tracking);
  MarkerCandidate candidate(const ColourBlob& blob, CandidateVerdict verdict, double misfit) const;

  ColourParams params_;
  cv::Mat kernel_;          // Morphology structuring element.
  int margin_px_ = 0;       // Filter radius + 4 morphology radii (+1).
  // Whether the last region analysed needed its margin classified (ClassifyRegion: which way
  // it classifies the next one; the result is the same either way).
  bool margin_was_needed_ = false;
  HsvClassifier fine_hsv_, coarse_hsv_;  // The marker test, and the lenient coarse one.
  // The marker test with the brightness floor lowered (kDimFloor), for the dim pass; absent when
  // lowering changes nothing (a floor near 0).
  std::optional<HsvClassifier> dim_hsv_;
  std::optional<HsvRange> dim_gray_;
  // The range with its floors halved (ColourBlob::fringe_shift_px), and whether it moves the soft
  // centroid: a hue range with a saturation floor.
  HsvClassifier fringe_hsv_;
  HsvRange fringe_gray_{0, 255};
  bool fringe_places_ = false;
  bool morph_cross_ = false, morph_square_ = false;  // kernel_ is 3x3: the vector kernel applies.
  // A window's analysis calls OpenCV functions that may parallelise (gray inRange, a pre-filter,
  // morphology other than 3x3), besides a colour conversion of a frame of the other kind.
  bool opencv_in_windows_ = false;
  std::optional<HsvRange> gray_, coarse_gray_;  // Gray-level mode (`gray`, or a nominal gray).
  std::optional<cv::Vec3d> nominal_;          // auto_bgr: the colour model until one is learned.

  // The marker, learned at acquisition.
  std::optional<ColourModel> model_;
  std::optional<cv::Rect> acquire_roi_;       // Restricts acquisitions until the first success.
  // The candidates that were tied when a first acquisition by uniqueness (no model, no roi) last
  // found several: a later lone candidate in one of their places is one of them still.
  struct Rival {
    cv::Point2d position_px;
    double radius_px = 0;
  };
  std::vector<Rival> rivals_;
  std::vector<MarkerCandidate> candidates_;   // Of the last search.

  // Motion.
  std::optional<cv::Point2d> last_px_;        // Last found position (kept to prefer on re-acquisition).
  cv::Point2d velocity_px_{0, 0};             // Per frame; 0 after a (re-)acquisition.
  bool tracking_ = false;                     // Found in the previous frame.
  // The last windowed search saw a blob of the marker's colour where the marker was expected,
  // too small to be measured: the marker is covered rather than gone.
  bool partly_seen_ = false;
  bool partly_out_ = false;
  int held_frames_ = 0;  // Frames in a row the marker was held covered (partly seen).  // ... and that blob touched the frame's edge: it is leaving the frame.
  // Frames since the marker was last found, and where that was (kept through reset(): the
  // relearning below looks there).
  int lost_frames_ = 0;
  std::optional<cv::Point2d> last_seen_px_;
  cv::Size frame_size_;
  cv::Rect last_search_px_;
  // How far from the prediction the last frame's window chose the marker (absent when it was
  // not so found): how tight a first window this frame may try (track_in_windows).
  std::optional<double> last_miss_px_;
  bool tight_window_ = true;

  // What the tracker knew before the last update() reported, so adopt() can report another of
  // its candidates as if it had chosen that one.
  struct State {
    std::optional<ColourModel> model;
    std::optional<cv::Rect> acquire_roi;
    std::optional<cv::Point2d> last_px, last_seen_px;
    cv::Point2d velocity_px;
    bool tracking = false;
    int held_frames = 0, lost_frames = 0;
  };
  State saved_;

  // Buffers reused frame to frame: raw storage behind Mat headers of the size each frame needs.
  cv::Mat filtered_store_, mask_store_, morph_store_, blob_store_;
  cv::Mat prepared_store_, coarse_prepared_store_, distance_store_, zone_store_;
  cv::Mat fringe_store_;  // measure_fringe's classification of the padded box.
  // analyse_region's region as one plane when it is flat (b == g == r), and whether it is: the
  // measurement then reads each level as the BGR pixel (v, v, v).
  cv::Mat flat_store_;
  bool flat_pixels_ = false;
  cv::Mat coarse_store_, coarse_mask_store_, coarse_labels_store_, tiles_store_;
  cv::Mat coarse_stats_, coarse_centroids_;
  RunLabeller labeller_;
  std::vector<ColourBlob> blobs_, pending_, dim_blobs_;
  std::vector<cv::Rect> windows_, boxes_;
  std::vector<cv::Point> points_;
  std::vector<cv::Point> edge_points_;  // A blob's leftmost and rightmost pixel of each row.
  std::vector<cv::Point> hull_points_;  // Their convex hull.
  std::vector<cv::Point> outside_stack_;  // FillHoles's flood of the outside.
  std::vector<cv::Point2d> rim_points_;  // A partial blob's edge pixels, for its rim fit.
  std::vector<double> rim_angles_;       // Scratch of FitRimOfRadius.
  std::vector<std::pair<double, cv::Point2d>> off_rim_;  // Scratch of OffRimBulgePx.
};

}  // namespace softsight
