// The template tracker (SAD, SSD or ZNCC; CreateTemplateTracker makes it): the search state
// machine, the scale ladder and the working template. Private to track/; tests reach it here.
#pragma once

#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/track/template_tracker.h"
#include "softsight/track/tracker.h"
#include "track/match_kernels.h"
#include "track/template_parts.h"

namespace softsight::template_internal {

class TemplateTracker final : public Tracker {
 public:
  explicit TemplateTracker(const TemplateParams& params) : params_(params) {
    params_.image = params.image.clone();  // Own the pixels; the spec may change later.
  }

  void init(const cv::Mat& frame_bgr, const cv::Rect& hint) override;
  bool start(const Frame& frame) override;
  Observation update(const cv::Mat& frame_bgr) override;
  const std::vector<MarkerCandidate>& candidates() const override { return weighed_; }
  std::optional<Observation> adopt(size_t index) override;
  // The box the template was cut from at the last init with a box: the box dragged, or that box
  // widened to hold the marker's surroundings (BoxShowingTheMarker). Empty after init from an image.
  const cv::Rect& selection_box() const { return selection_box_; }
  void reset() override {
    tracking_ = false;
    last_centre_.reset();
    velocity_px_ = {0, 0};
    turn_step_ = 0;
    repeats_ = 0;
    lost_frames_ = 0;
    pose_zncc_ = kNoRival;
  }

 private:
  bool adapts() const { return params_.update_rate > 0; }
  // The template searched with: the updated one, or the first template at the current scale.
  const PreparedTemplate& search_template() const {
    return adapts() ? working_ : current().templ;
  }
  static int RungKey(int scale, int turn) { return scale * kTurns + turn; }
  const Rung& current() const { return rungs_.at(RungKey(rung_, turn_)); }
  void ToNative(const cv::Mat& frame, cv::Mat& out) const;
  void ConvertAround(const cv::Mat& frame, const cv::Rect& rect);
  void Native(const cv::Mat& frame, const cv::Rect& rect, cv::Mat& out);
  // The one channel the blob is measured in: native gray, or colour projected on its axis.
  void BlobChannel(const cv::Mat& native, cv::Mat& out) const {
    BlobChannelOf(native, blob_projection_, out);
  }
  std::optional<cv::Point2d> BlobShift(const cv::Mat& frame, const Fix& fix);
  // The template placed with its centre at `centre_px` shows another colour than the marker's
  // core (core_colour_) there; false when that colour is unknown or cannot be judged.
  bool OtherColourAt(const cv::Mat& frame, const cv::Point2d& centre_px) const;
  // The hit's core shows the marker's colour (within kSameColourDistance).
  bool ColourAgreesAt(const cv::Mat& frame, const Hit& hit) const;
  // The chromaticity distance of the core at `centre_px` from the marker's; empty when unknown.
  std::optional<double> ColourDistanceAt(const cv::Mat& frame, const cv::Point2d& centre_px) const;
  // Whether a selected box (its native pixels, and its BGR ones when the frame has colour) shows
  // a marker's blob at its centre, as SetTemplate learns it; changes nothing.
  struct BoxVerdict {
    bool marker = false;
    cv::Point2d centroid;  // The blob's, in the box.
    double contrast = 0;   // Levels it stands out by (the most seen when there is no marker).
    cv::Rect blob_box;     // The blob's bounding box, in the box.
    double area = 0;       // The blob's, px.
    // The blob SetTemplate will report the marker's centre from (the matched channel's, or the
    // chromaticity's where the marker stands out more there), in the box, and its area.
    cv::Point2d reported_centroid;
    double reported_area = 0;
  };
  BoxVerdict JudgeBox(const cv::Mat& native, const cv::Mat& selection_bgr) const;
  // Sets projection_ for a selection at `box` and cuts its native pixels.
  void PrepareSelection(const cv::Mat& frame_bgr, const cv::Rect& box, cv::Mat& native);
  cv::Rect BoxShowingTheMarker(const cv::Mat& frame_bgr, const cv::Rect& hint, cv::Mat& native,
                               double* contrast, double* off_centre);
  // A point of the selected template in a rung of `size`. Template coordinates scale about the
  // pixel edges: u' + 0.5 = (u + 0.5) * size'/size.
  cv::Point2d ToRung(const cv::Point2d& p, const cv::Size& size) const {
    return {(p.x + 0.5) * size.width / original_.cols - 0.5,
            (p.y + 0.5) * size.height / original_.rows - 0.5};
  }
  cv::Mat MaskFor(const cv::Size& size) const {
    return params_.round_mask ? RoundMask(size) : cv::Mat();
  }
  // `selection_bgr`: the template as selected in colour (empty on gray footage), in which its
  // blob is measured when the marker's colour differs from its surroundings' (ChromaAxis).
  void SetTemplate(const cv::Mat& templ, const std::string& where,
                   const cv::Mat& selection_bgr = cv::Mat());
  const Rung* RungAt(int scale, int turn);
  void Similarity(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& sim);
  double ScoreOf(double similarity) const;
  // The match passes the measure's thresholds; with `colour_agrees` (its core shows the
  // marker's colour) min_zncc is lowered by kColourZnccAllowance, and `followed` (found in the
  // tracking window, where the motion put it) by kBlobDriftAllowance more for a marker with a
  // blob, which Verify then requires at the match.
  bool Accept(const Hit& m, bool colour_agrees = false, bool followed = false) const;
  // Accept for a match on `frame`, with its colour judged there; a match `followed` (found where
  // the motion put it) whose core shows the marker's colour also passes when a place within
  // kShadeFreeReachPx of it matches the first template in log-chromaticity by min_zncc
  // (ShadeFreePeakNear): a shadow across the marker's surroundings pulls its gray-level match far
  // below what a person sees. *shaded: the peak it was accepted at so, else empty (Verify then
  // measures the marker there: VerifyShaded).
  struct ShadeFreePeak {
    cv::Point2d top_left;  // The template's top-left corner, px (sub-pixel).
    double zncc = 0;
  };
  bool AcceptOn(const cv::Mat& frame, const Hit& m, bool followed,
                std::optional<ShadeFreePeak>* shaded);
  std::optional<ShadeFreePeak> ShadeFreePeakNear(const cv::Mat& frame, cv::Point origin);
  cv::Rect WindowAround(const cv::Point2d& centre_px, const cv::Size& size, int margin_px) const;
  std::optional<Hit> Search(const cv::Mat& frame, cv::Rect region, const PreparedTemplate& templ,
                            bool find_rival);
  std::optional<Hit> Refine(const cv::Mat& frame, cv::Point top_left);
  // The match in the window kNearMarginPx around `predicted` (the marker's centre), when it
  // decides the tracking window's search; empty when the whole window must be searched.
  std::optional<Hit> NearSearch(const cv::Mat& frame, const cv::Point2d& predicted);
  std::optional<Hit> Acquire(const cv::Mat& frame);
  // Where Acquire searches: around the last known position (within the acquire radius, or half
  // the distance to the nearest look-alike), else the whole frame.
  cv::Rect AcquisitionRegion(const cv::Mat& frame, const cv::Size& size) const;
  // The acquisition pyramid of the search template (coarse_), when it is empty.
  void BuildAcquisitionPyramid(const PreparedTemplate& templ);
  // The best `peaks` separated peaks of sim_ (a template of `coarse` size) into candidates_.
  void FindCoarsePeaks(const cv::Size& coarse, int peaks);
  // Peak `p` of pyramid level `top` refined down to level 1, as far as it goes; *level is the
  // level the returned point is in.
  cv::Point RefineThroughLevels(cv::Point p, int top, int* level);
  std::optional<Fix> Measure(const cv::Mat& frame, const cv::Point2d& centre_px);
  double RungZncc(const cv::Mat& frame, int scale, int turn, const cv::Point2d& centre_px);
  // RungZncc of the current rung from the measurement's map (fine_sim_), when Measure matched
  // that rung's ZNCC around every placement RungZncc would try; false otherwise.
  bool CurrentRungZnccMeasured(const cv::Mat& frame, const cv::Point2d& centre_px, double* zncc);
  void UpdatePose(const cv::Mat& frame, const Fix& fix, int last_turn);
  void TurnedTo();
  void UpdateTemplate(const cv::Mat& frame, const cv::Point2d& centre_px);
  void RestoreWorkingTemplate();
  void ScanForLookAlikes(const cv::Mat& frame, const cv::Point2d& centre_px);
  // ScanForLookAlikes's map of the search template `templ` over region_, into sim_.
  void LookAlikeMap(const PreparedTemplate& templ);
  // Lists a place the template fits (its centre in the frame) among the candidates weighed.
  void Weigh(const cv::Point2d& centre_px, double zncc, CandidateVerdict verdict);
  // Verifies the match centred at `matched` and, when it holds, moves the tracker on to it.
  // `working_zncc` is the working template's ZNCC there (kNoRival: not matched with it).
  // `shaded`: the match was accepted in log-chromaticity alone, at that peak; VerifyShaded
  // measures it there.
  Observation Verify(const cv::Mat& frame_bgr, const cv::Point2d& matched, double score,
                     int last_turn, double working_zncc,
                     const std::optional<ShadeFreePeak>& shaded = std::nullopt);
  Observation VerifyShaded(const ShadeFreePeak& peak, double score);
  double rung_scale() const { return std::pow(kScaleStep, rung_ - kRungsBelow); }
  Observation Lose(MarkerStatus why, int candidates = 0) {
    tracking_ = false;  // Keep last_centre_: the next acquisition looks around it.
    velocity_px_ = {0, 0};
    turn_step_ = 0;
    repeats_ = 0;
    pose_zncc_ = kNoRival;
    ++lost_frames_;
    return Observation::NotFound(why, candidates);
  }

  TemplateParams params_;
  cv::Mat original_;                    // The selected template, native (gray or BGR).
  cv::Point2d anchor_px_{0, 0};         // The reported point, in the selected template.
  // The ladder: the first template at each scale (0 .. kRungsBelow + kRungsAbove; kRungsBelow is
  // the selection's) and turn (0 .. kTurns - 1), prepared on first use (a map: the references
  // RungAt hands out stay valid). The current rung always exists.
  std::map<int, Rung> rungs_;
  // Per scale of the ladder, the first template scaled to it and the mask at its size, from which
  // each of its turns is made (RungAt: the scale's resize and mask were made again for every turn
  // tried, issue 45). Emptied with rungs_.
  struct Scaled {
    cv::Mat image, mask;
  };
  std::map<int, Scaled> scaled_;
  int rung_ = 0;                        // The current scale.
  int turn_ = 0;                        // The current turn, in kTurnStepDeg steps.
  int turn_step_ = 0;                   // Turn steps between the last two matches (its spin).
  // The current rung's ZNCC when the neighbouring rungs were last tried (kNoRival: try them next
  // frame), and the frames since.
  double pose_zncc_ = kNoRival;
  int pose_skips_ = 0;
  int working_key_ = -1;                // The rung the working template's mask belongs to.
  PreparedTemplate working_;            // The updated template (update_rate > 0).
  cv::Mat working_f_;                   // Its CV_32F running blend.
  cv::Mat working_mask_;                // Its mask (or empty), for its current size.
  std::vector<PreparedTemplate> coarse_;  // Acquisition pyramid of the search template, [0] unused.
  std::optional<cv::Point2d> last_centre_;  // Last known template centre (last match or hint).
  cv::Point2d velocity_px_{0, 0};       // Per frame; zero unless the last two frames matched.
  int repeats_ = 0;                     // Repeated frames in a row (track/repeated_frames.h).
  // The footage was seen repeating frames: the next frame may show the marker where it was, or
  // a step on, so the tracking window spans both.
  bool footage_repeats_ = false;
  bool tracking_ = false;               // The previous update found the marker (or the hint).
  int lost_frames_ = 0;                 // Updates since the marker was last found.
  // Distance to the nearest look-alike seen around the marker (at the selected scale), or
  // infinity: re-acquisition never looks half of it away from the last position, so a marker
  // covered beside its twin is lost, not swapped.
  cv::Rect selection_box_;  // See selection_box().
  double look_alike_px_ = std::numeric_limits<double>::infinity();
  bool scan_pending_ = false;           // Scan for look-alikes at the first match after a hint.

  // The candidates the last update weighed (the best match, a look-alike that fits too) with
  // their template centres, the frame they were weighed on (a header) and the state before that
  // update: adopt() verifies another of them as if it had been chosen.
  std::vector<MarkerCandidate> weighed_;
  std::vector<cv::Point2d> weighed_centres_;
  cv::Mat frame_;
  struct State {
    std::optional<cv::Point2d> last_centre;
    cv::Point2d velocity_px;
    bool tracking = false;
    int repeats = 0, lost_frames = 0, rung = 0, turn = 0, turn_step = 0;
  } saved_;

  // Buffers reused from frame to frame.
  cv::Mat region_, fine_, raw_, sim_, fine_sim_, rung_sim_, patch_, resized_, candidate_, shape_;
  // fine_sim_ holds the current rung's ZNCC map of the window at measured_tl_ (Measure's, until
  // the pose search has used it).
  bool measured_zncc_ = false;
  cv::Point measured_tl_;
  // The frame around the marker in the matched channel(s), converted once per update: the
  // search, the measurement, the scale search and the template update each look at a window of
  // it (they overlap; converting each on its own was a seventh of the tracker's time).
  cv::Mat native_;
  cv::Rect native_rect_;  // Where native_ lies in the frame; empty when not converted.
  std::vector<cv::Mat> levels_;
  std::vector<cv::Point> candidates_;
  cv::Mat level_sim_;
  LookAlikeScratch look_alike_scratch_;
  cv::Mat projection_;  // Gray only: 1x4 BGR weights + offset, or empty for plain luma.
  ZnccScratch zncc_;
  // The marker's blob in the template: every match is verified against it (BlobShift).
  BlobMeter blob_;
  bool blob_ok_ = false;                // The template shows a blob (its foreground).
  // This frame's blob: how far its soft centroid lies from its binary one (0 when only the
  // binary one was needed: the match already on the blob).
  double blob_disagreement_px_ = 0.0;
  // This frame's blob's area over the learned one (at the current scale), or 1 where not measured.
  double blob_area_ratio_ = 1.0;
  bool chroma_ok_ = false;              // ... measured in its chromaticity (chroma_).
  ChromaAxis chroma_;
  // The blob's centroid, measured in every frame, is the reported point (report: centre, or a
  // blob measured in its chromaticity).
  bool blob_reported_ = false;
  cv::Point2d blob_anchor_px_{0, 0};    // Its soft centroid, in the selected template.
  // How far the blob's centroid in the selected template moves between the two channels it
  // stands out in, the matched one and its chromaticity (0 when it shows in only one): where
  // the marker's centre is, is defined no better than that (position_sigma.h).
  double anchor_spread_px_ = 0.0;
  // The colour of the marker's core in the selection (CoreColour), when it was cut from a colour
  // frame: a place of another colour is not the marker, however well it matches.
  std::optional<cv::Vec3d> core_colour_;
  double core_radius_px_ = 0.0;  // The core disc's radius, in the selected template.
  // The selection's log-chromaticity (a coloured marker cut from a colour frame), else empty;
  // at the scale and turn of the rung shade_free_key_ (-1: none yet) with its mask, and the
  // frame's region around a match, for ShadeFreePeakNear.
  cv::Mat shade_free_, shade_free_rung_, shade_free_mask_, shade_free_region_;
  int shade_free_key_ = -1;
  cv::Mat blob_projection_;  // Colour: BGR weights giving the blob channel; else empty.
  cv::Mat blob_native_, blob_gray_;
  cv::Mat blob_continuous_;  // blob_gray_ copied when it is a view (BlobShift).
};

}  // namespace softsight::template_internal
