// ColourTracker, part 1 of 3: the search (see colour_tracker_impl.h): windows around the
// prediction, whole-frame acquisition, relearning after a change of light, and the motion and
// model it keeps.
#include "softsight/core/format.h"
#include "softsight/track/colour_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "track/colour_tracker_impl.h"
#include "track/colour_tracker_parts.h"
#include "track/position_sigma.h"
#include "track/track_options.h"

namespace softsight {

using namespace colour_internal;  // NOLINT: the tracker's own constants and helpers.

bool ColourParams::Check(std::string* error) const {
  // Each field's range is in its table row (track/colour_options.cc); only rules across fields
  // are written here.
  if (const auto problem = CheckOptions(ColourParamsOptions(), *this)) return Fail(error, *problem);
  std::ostringstream why;
  for (const auto& [name, r] : {std::pair{"s", s}, std::pair{"v", v}}) {
    if (r.lo > r.hi) {
      why << "hsv." << name << ": [" << r.lo << ", " << r.hi << "]: lower bound above upper bound";
      return Fail(error, why.str());
    }
  }
  if (max_area_px != 0.0 && max_area_px < min_area_px) {
    why << "blob.max_area: " << RoundTripNumber(max_area_px)
        << " must be 0 (no limit) or at least blob.min_area (" << RoundTripNumber(min_area_px) << ")";
    return Fail(error, why.str());
  }
  if (roi && (roi->width <= 0 || roi->height <= 0)) {
    why << "roi: [" << roi->x << ", " << roi->y << ", " << roi->width << ", " << roi->height
        << "] needs a positive width and height";
    return Fail(error, why.str());
  }
  if (gray && gray->lo > gray->hi) {
    why << "gray: [" << gray->lo << ", " << gray->hi << "]: lower bound above upper bound";
    return Fail(error, why.str());
  }
  if (gray && auto_bgr) return Fail(error, "gray: give either gray or auto_colour, not both");
  return true;
}

bool ColourParams::NeedsColour() const {
  if (gray) return false;
  if (auto_bgr) {
    cv::Mat bgr(1, 1, CV_8UC3, cv::Scalar((*auto_bgr)[0], (*auto_bgr)[1], (*auto_bgr)[2])), hsv;
    cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
    return hsv.at<cv::Vec3b>(0, 0)[1] >= kAutoGraySaturation;
  }
  return !(h.covers_all_hues() && s.lo == 0);
}

ColourTracker::ColourTracker(const ColourParams& params) : params_(params) {
  CV_Assert(params_.Check(nullptr));
  const int filter_radius = params_.filter == ColourParams::Filter::kNone ? 0
                                                                          : params_.filter_ksize / 2;
  const int morph_radius = params_.morph_size / 2;
  if (params_.morph_size > 1) {
    kernel_ = cv::getStructuringElement(MorphShape(params_.morph_shape),
                                        cv::Size(params_.morph_size, params_.morph_size));
    if (params_.morph_size == 3) {
      morph_square_ = cv::countNonZero(kernel_) == 9;
      morph_cross_ = cv::countNonZero(kernel_ != cv::getStructuringElement(
                                                     cv::MORPH_CROSS, cv::Size(3, 3))) == 0;
    }
  }
  // Opening then closing is four erosions/dilations, each reaching one radius further; the ring
  // around a blob reaches kRingOuter beyond it. With this margin every pixel a blob inside the
  // region depends on is exactly what a whole-frame pass would see.
  margin_px_ = filter_radius + 4 * morph_radius + kRingOuter + 1;
  HsvRange h = params_.h, s = params_.s, v = params_.v;
  gray_ = params_.gray;
  if (params_.auto_bgr) {
    // The nominal colour gives the threshold and, until the marker's own colour is learned, the
    // colour model: generous bounds, since verification rejects a wrong tint or brightness.
    const cv::Vec3b c = *params_.auto_bgr;
    cv::Mat bgr(1, 1, CV_8UC3, cv::Scalar(c[0], c[1], c[2])), hsv;
    cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
    const cv::Vec3b n = hsv.at<cv::Vec3b>(0, 0);
    if (n[1] < kAutoGraySaturation) {
      cv::Mat level;
      cv::cvtColor(bgr, level, cv::COLOR_BGR2GRAY);
      const int l = level.at<uchar>(0, 0);
      const int reach = std::max(40, l * 2 / 5);
      gray_ = HsvRange{std::max(0, l - reach), std::min(255, l + reach)};
      nominal_ = cv::Vec3d(l, 0, 0);
    } else {
      h = HsvRange::HueAround(n[0], kAutoHueTolerance);
      s = HsvRange{std::max(30, n[1] / 2), 255};
      v = HsvRange{std::max(30, n[2] * 2 / 5), 255};
      nominal_ = cv::Vec3d(c[0], c[1], c[2]);
    }
  }
  // The coarse test sees single unfiltered pixels. Without a pre-filter those are exactly what
  // the fine test sees, so it is the fine test; a filter moves colours, and the coarse test is
  // then widened so that a marker whose filtered pixels pass is not missed.
  const bool filtered = params_.filter != ColourParams::Filter::kNone;
  if (gray_) {
    coarse_gray_ = filtered ? HsvRange{gray_->lo * 3 / 4, gray_->hi + (255 - gray_->hi) / 4} : *gray_;
  } else {
    ColourParams derived = params_;
    derived.h = h;
    derived.s = s;
    derived.v = v;
    fine_hsv_ = HsvClassifier(HsvBox::Make(h, s, v));
    fringe_places_ = s.lo > 0 && !h.covers_all_hues();
    fringe_hsv_ =
        HsvClassifier(HsvBox::Make(h, HsvRange{s.lo / 2, s.hi}, HsvRange{v.lo / 2, v.hi}));
    coarse_hsv_ = HsvClassifier(filtered ? CoarseBox(derived) : HsvBox::Make(h, s, v));
    if (v.lo >= kDimMinFloor) {
      const int floor = static_cast<int>(v.lo * kDimFloor);
      dim_hsv_ = HsvClassifier(HsvBox::Make(h, s, HsvRange{floor, v.hi}));
    }
  }
  if (gray_) {
    fringe_gray_ = gray_->lo > 0 ? HsvRange{gray_->lo / 2, gray_->hi}
                                 : HsvRange{0, gray_->hi + (255 - gray_->hi) / 2};
  }
  if (gray_ && gray_->lo >= kDimMinFloor) {
    dim_gray_ = HsvRange{static_cast<int>(gray_->lo * kDimFloor), gray_->hi};
  }
  acquire_roi_ = params_.roi;
  opencv_in_windows_ = gray_ || params_.filter != ColourParams::Filter::kNone ||
                       (!kernel_.empty() && !morph_cross_ && !morph_square_);
}

void ColourTracker::check_frame(const cv::Mat& frame) const {
  if (frame.empty() || (frame.type() != CV_8UC3 && frame.type() != CV_8UC1)) {
    throw InputError("colour tracking needs 8-bit BGR or gray frames, got " +
                     (frame.empty() ? std::string("an empty frame")
                                    : cv::typeToString(frame.type()) + " frames"));
  }
  if (frame.type() == CV_8UC1 && params_.NeedsColour()) {
    throw InputError("the frames are gray, but this colour marker's range needs colour (a gray "
                     "level range `gray: [lo, hi]` or an HSV range of any hue from saturation 0 "
                     "tracks white, gray or black markers)");
  }
}

void ColourTracker::reset() {
  held_frames_ = 0;
  last_miss_px_.reset();
  last_px_.reset();
  velocity_px_ = cv::Point2d(0, 0);
  tracking_ = false;
  // The roi says where the marker is when tracking starts; once it has been found (a model is
  // learned), it may be anywhere the camera and the body have taken it since: a search after a
  // reset (a report found implausible, a jump of the camera) covers the whole frame, judged by
  // the model, as after any loss.
  if (!model_) acquire_roi_ = params_.roi;
}

bool ColourTracker::start(const Frame& frame) {
  // A roi picked at a later frame says nothing of where the marker is before it.
  if (frame.index < params_.roi_frame) return false;
  // Without a roi there is nothing to learn before the first update: it acquires on the whole
  // frame.
  if (params_.roi) init(frame.image, *params_.roi);
  return true;
}

void ColourTracker::init(const cv::Mat& frame_bgr, const cv::Rect& hint) {
  check_frame(frame_bgr);
  const cv::Rect frame_rect(cv::Point(0, 0), frame_bgr.size());
  if (hint.width <= 0 || hint.height <= 0) {
    throw InputError("colour marker rectangle [" + std::to_string(hint.x) + ", " +
                     std::to_string(hint.y) + ", " + std::to_string(hint.width) + ", " +
                     std::to_string(hint.height) + "] is empty");
  }
  if ((hint & frame_rect).empty()) {
    throw InputError("colour marker rectangle [" + std::to_string(hint.x) + ", " +
                     std::to_string(hint.y) + ", " + std::to_string(hint.width) + ", " +
                     std::to_string(hint.height) + "] lies outside the " +
                     std::to_string(frame_rect.width) + "x" + std::to_string(frame_rect.height) +
                     " frame");
  }
  // A new selection is a new calibration: learn the model again, inside the hint.
  params_.roi = hint & frame_rect;
  model_.reset();
  reset();
  frame_size_ = frame_bgr.size();
  report(acquire(frame_bgr));
}

Observation ColourTracker::update(const cv::Mat& frame_bgr) {
  check_frame(frame_bgr);
  if (frame_bgr.size() != frame_size_) {
    if (!frame_size_.empty()) reset();
    frame_size_ = frame_bgr.size();
  }
  saved_ = State{model_, acquire_roi_, last_px_, last_seen_px_, velocity_px_, tracking_,
                 held_frames_, lost_frames_};
  return search(frame_bgr);
}

std::optional<Observation> ColourTracker::adopt(size_t index) {
  if (index >= candidates_.size() || candidates_.size() != blobs_.size()) return std::nullopt;
  const CandidateVerdict verdict = candidates_[index].verdict;
  if (verdict != CandidateVerdict::kFits && verdict != CandidateVerdict::kChosen) {
    return std::nullopt;
  }
  // Back to before the last report, then report this candidate as the choice.
  model_ = saved_.model;
  acquire_roi_ = saved_.acquire_roi;
  last_px_ = saved_.last_px;
  last_seen_px_ = saved_.last_seen_px;
  velocity_px_ = saved_.velocity_px;
  tracking_ = saved_.tracking;
  held_frames_ = saved_.held_frames;
  lost_frames_ = saved_.lost_frames;
  if (!model_) return std::nullopt;  // Nothing learned to verify it against.
  for (MarkerCandidate& c : candidates_) {
    if (c.verdict == CandidateVerdict::kChosen) c.verdict = CandidateVerdict::kFits;
  }
  candidates_[index].verdict = CandidateVerdict::kChosen;
  last_miss_px_.reset();  // Not the window's choice: the next frame starts with the window.
  Choice choice;
  choice.blob = blobs_[index];
  choice.status = MarkerStatus::kFound;
  return report(choice);
}

Observation ColourTracker::search(const cv::Mat& frame_bgr) {
  candidates_.clear();
  // Set again by track_in_windows when its window chooses the marker.
  const std::optional<double> last_miss = std::exchange(last_miss_px_, std::nullopt);
  partly_seen_ = false;
  partly_out_ = false;
  Choice choice;
  if (tracking_ && params_.window_px > 0) {
    choice = track_in_windows(frame_bgr, last_miss);
  } else if (tracking_) {
    // Whole-frame tracking (window 0): the same choice as in a window, the nearest verified blob.
    const cv::Point2d predicted = *last_px_ + velocity_px_;
    find_blobs(frame_bgr, acquire_downsample(), &blobs_);
    last_search_px_ = cv::Rect(cv::Point(0, 0), frame_bgr.size());
    double best = std::numeric_limits<double>::infinity();
    size_t chosen = 0;
    for (const ColourBlob& b : blobs_) {
      const auto [verdict, misfit] = judge(b);
      candidates_.push_back(candidate(b, verdict, misfit));
      const double d = cv::norm(b.centroid_px - predicted);
      if (verdict == CandidateVerdict::kFits && d < best) {
        best = d;
        choice.blob = b;
        chosen = candidates_.size() - 1;
      }
    }
    if (choice.blob) candidates_[chosen].verdict = CandidateVerdict::kChosen;
  }
  if (!choice.blob && tracking_ && partly_seen_ && held_frames_ < kHoldCoveredFrames) {
    // What is left of the marker is where it should be (covered, or leaving the frame): it is
    // not measured, and not looked for elsewhere either, where a look-alike would be all there
    // is. The window stays on it.
    choice.status = partly_out_ ? MarkerStatus::kOutOfFrame : MarkerStatus::kCovered;
    choice.hold = true;
    return report(choice);
  }
  if (!choice.blob) {
    const bool was_tracking = tracking_;
    const cv::Point2d predicted = last_px_.value_or(cv::Point2d()) + velocity_px_;
    choice = acquire(frame_bgr);
    if (!choice.blob && was_tracking && choice.status == MarkerStatus::kLost) {
      if (partly_out_ ||
          !cv::Rect2d(-0.5, -0.5, frame_bgr.cols, frame_bgr.rows).contains(predicted)) {
        choice.status = MarkerStatus::kOutOfFrame;
      } else if (partly_seen_) {
        choice.status = MarkerStatus::kCovered;
      }
    }
    if (!choice.blob && choice.status != MarkerStatus::kAmbiguous && last_seen_px_ &&
        lost_frames_ + 1 >= kRelearnAfterFrames) {
      const Choice relearned = relearn(*last_seen_px_);
      if (relearned.blob || relearned.status == MarkerStatus::kAmbiguous) choice = relearned;
    }
  }
  return report(choice);
}

void ColourTracker::learn(const ColourBlob& blob, bool tracking) {
  if (!model_) {
    model_ = ColourModel{blob.area_px, blob.area_px, blob.circularity, blob.core_colour,
                         blob.asymmetry_px};
    return;
  }
  // Asymmetry follows only down: a marker learned while partly covered is learned whole later,
  // never the other way round.
  if (tracking && blob.asymmetry_px < model_->asymmetry_px) {
    model_->asymmetry_px += std::max(params_.adapt_rate, 0.1) *
                            (blob.asymmetry_px - model_->asymmetry_px);
  }
  if (!tracking || params_.adapt_rate <= 0) return;
  // Follow slow changes only: a marker growing in perspective, the light drifting. A sudden one
  // (a partial cover, a reflection) is not learned.
  ColourModel& m = *model_;
  if (blob.circularity < m.circularity - kAdaptShape) return;
  const double r = params_.adapt_rate;
  m.area_px = std::clamp(m.area_px + r * (blob.area_px - m.area_px),
                         kAdaptMinRange * m.first_area_px, kAdaptMaxRange * m.first_area_px);
  m.circularity += r * (blob.circularity - m.circularity);
  if (blob.measured && !blob.shaded) m.colour += r * (blob.core_colour - m.colour);
}

namespace {
BlobEvidence EvidenceOf(const ColourBlob& blob, const ColourModel& model) {
  BlobEvidence evidence;
  evidence.area_px = blob.area_px;
  if (blob.measured) {
    evidence.noise_levels = 0.5 * (blob.core_sigma + blob.ring_sigma);
    evidence.contrast_levels = cv::norm(blob.core_colour - blob.ring_colour);
    evidence.excess_asymmetry_px = blob.asymmetry_px - model.asymmetry_px;
    // (Not for a blob placed by its rim: the fitted circle's centre does not rest on symmetry.)
    if (!blob.rim_placed) evidence.own_asymmetry_px = blob.asymmetry_px;
  }
  evidence.rim_placed = blob.rim_placed;
  if (blob.rim_placed) {
    evidence.area_px = std::max(blob.area_px, model.area_px);
  } else {
    // The soft centroid's own disagreement: the fringe's step is the fringe's term.
    const cv::Point2d placed = blob.fringe_placed ? blob.fringe_pull_px : cv::Point2d();
    evidence.centroid_disagreement_px =
        cv::norm(blob.centroid_px - placed - blob.binary_centroid_px);
    evidence.fringe_shift_px = blob.fringe_shift_px;
  }
  return evidence;
}
}  // namespace

Observation ColourTracker::report(const Choice& choice) {
  if (!choice.blob && choice.hold) {
    ++held_frames_;
    ++lost_frames_;
    // The window follows where the marker goes meanwhile (behind the cover, out of the frame).
    if (last_px_) *last_px_ += velocity_px_;
    return Observation::NotFound(choice.status);
  }
  if (!choice.blob) {
    held_frames_ = 0;
    tracking_ = false;
    velocity_px_ = cv::Point2d(0, 0);
    ++lost_frames_;
    return Observation::NotFound(choice.status, choice.tied);
  }
  const ColourBlob& blob = *choice.blob;
  // What is left of it is not its looks, nor is a blob segmented with the lowered floor.
  if (!blob.rim_placed && !blob.dimmed) learn(blob, tracking_);
  lost_frames_ = 0;
  last_seen_px_ = blob.centroid_px;
  // After frames held covered, the step from the last position spans them: no velocity.
  velocity_px_ = tracking_ && held_frames_ == 0 ? blob.centroid_px - *last_px_ : cv::Point2d(0, 0);
  held_frames_ = 0;
  last_px_ = blob.centroid_px;
  tracking_ = true;
  acquire_roi_.reset();
  Observation obs;
  obs.position_px = blob.centroid_px;
  obs.score = blob.area_px / model_->area_px;
  obs.sigma_px = BlobCentroidSigmaPx(EvidenceOf(blob, *model_));
  return obs;
}

ColourTracker::Choice ColourTracker::track_in_windows(const cv::Mat& frame,
                                                      std::optional<double> last_miss) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  const cv::Point2d predicted = *last_px_ + velocity_px_;
  // The window must hold the whole marker with room to move: at least two diameters.
  const double ref_radius = std::sqrt(model_ ? model_->area_px / CV_PI : 0.0);
  const int base = std::max(params_.window_px, static_cast<int>(std::ceil(4.0 * ref_radius)));
  // Where the marker may be this frame: within its radius (plus a frame's motion) of the
  // prediction.
  const double reach = ref_radius + cv::norm(velocity_px_) + 1.0;
  // Where the last frame's prediction was good (the marker found within `miss` px of it), first a
  // window just large enough for the marker where this frame's prediction puts it, if it errs by
  // up to twice as much (with the ring around it), when that is at most three quarters of the
  // window's side (a try that fails costs its pixels too). Issue 45: on mire-2 a 30 px window
  // instead of 64 for the small dots, which share the default window with the card's bright edge
  // and the poster, and 56 instead of 80 for the large one. It is taken only when it settles the
  // first window would: a verified blob chosen, nothing partial or cut by its border nearer to
  // the prediction, and the chosen blob nearer to the prediction than the tight window's border,
  // so every blob the first window holds nearer than it lies in the tight one, whole (then the
  // same pixels, mask and measurement, bit for bit) or cut by its border (then it is not taken).
  // The chosen blob and the report are then the first window's; only the candidates farther
  // than the tight window are not listed. Anything else: the windows as before.
  int tight_side = 0;
  if (last_miss && tight_window_) {
    tight_side = 2 * static_cast<int>(std::ceil(ref_radius + 2.0 * std::max(*last_miss, 1.0) +
                                                kRingOuter + 2));
    if (4 * tight_side > 3 * base) tight_side = 0;
  }
  for (int step = tight_side > 0 ? -1 : 0; step <= params_.widen_steps; ++step) {
    const bool tight = step < 0;
    const int side = tight ? tight_side : base << step;
    const cv::Rect window =
        cv::Rect(cvRound(predicted.x) - side / 2, cvRound(predicted.y) - side / 2, side, side) &
        frame_rect;
    if (window.empty()) continue;  // Prediction far outside the frame: try wider.
    last_search_px_ = window;
    blobs_.clear();
    analyse(frame, window, &blobs_);
    std::sort(blobs_.begin(), blobs_.end(), CentroidBefore);
    candidates_.clear();
    const ColourBlob* best = nullptr;
    size_t best_index = 0;
    double best_dist = std::numeric_limits<double>::infinity();
    double nearest_partial = std::numeric_limits<double>::infinity();
    cv::Point2d sliver_px;  // The nearest partial blob's centroid.
    for (ColourBlob& b : blobs_) {
      auto [verdict, misfit] = judge(b);
      const double d = cv::norm(b.centroid_px - predicted);
      // In a shadow (a hand or a tool between the light and the marker, a dim side of the bench):
      // a blob where the marker should be that fits it in everything but brightness (its tint,
      // size, shape and contrast) is the marker darkened, not a darker look-alike that happens to
      // stand exactly there. Colour only: a gray marker has nothing but its brightness.
      if (verdict == CandidateVerdict::kColour && !gray_ && model_ && d <= reach) {
        const auto [shaded, shaded_misfit] = judge(b, true);
        if (shaded == CandidateVerdict::kFits) {
          verdict = shaded;
          misfit = shaded_misfit + kShadowMisfit;
          b.shaded = true;
        }
      }
      candidates_.push_back(candidate(b, verdict, misfit));
      // What is left of a covered marker: of its colour, smaller than it (often a sliver, so of
      // any shape), and within its own radius (plus one frame's motion) of where it should be.
      // So is a partial blob there (part of it covered, or beyond the frame's edge).
      const bool smaller = (verdict == CandidateVerdict::kSize ||
                            verdict == CandidateVerdict::kShape) &&
                           model_ && b.area_px < model_->area_px;
      const bool piece_where_expected =
          (smaller || verdict == CandidateVerdict::kPartial) && model_ && d <= reach;
      if (piece_where_expected) {
        partly_seen_ = true;
        if (b.at_frame_edge) partly_out_ = true;
      }
      // A sliver of it where it should be is the marker covered, as much as a partial blob
      // anywhere: a whole look-alike farther away is not it.
      if ((piece_where_expected || verdict == CandidateVerdict::kPartial) && d < nearest_partial) {
        nearest_partial = d;
        sliver_px = b.centroid_px;
      }
      if (verdict != CandidateVerdict::kFits) continue;
      if (d < best_dist) {
        best_dist = d;
        best = &b;
        best_index = candidates_.size() - 1;
      }
    }
    if (tight) {
      // Settled as the first window would settle it (see above), or the first window itself.
      // The border lies at least side / 2 - 0.5 px from the prediction (the window is centred
      // on it rounded): a blob whose centroid is nearer than the chosen one's lies in the window.
      bool settled = best != nullptr && !(nearest_partial < best_dist) &&
                     best_dist < side / 2 - 1.5;
      for (const ColourBlob& b : blobs_) {
        if (b.clipped && DistanceToRect(predicted, b.bbox_px) < best_dist) settled = false;
      }
      if (!settled) {
        partly_seen_ = false;  // As search() left them for the first window.
        partly_out_ = false;
        continue;
      }
    }
    // The marker partly hidden (covered, or leaving the frame) nearer than the best whole blob:
    // that is where the marker is, and what is left of it is not measured. A look-alike farther
    // away is not it. Unless what is left is only the brightest part of the marker, the rest
    // fallen below the range's floor: the dim pass measures it whole.
    if (nearest_partial < best_dist) {
      if (nearest_partial <= reach && !partly_out_) {
        return dim_search(frame, window, predicted, reach, sliver_px);
      }
      return Choice{};
    }
    // A blob cut by the window's border may be the marker extending outside, and nearer than
    // the best complete one: never report a clipped centroid, look wider instead.
    bool nearer_clipped = false;
    for (const ColourBlob& b : blobs_) {
      if (b.clipped && DistanceToRect(predicted, b.bbox_px) < best_dist) nearer_clipped = true;
    }
    if (best && !nearer_clipped) {
      last_miss_px_ = best_dist;
      candidates_[best_index].verdict = CandidateVerdict::kChosen;
      Choice choice;
      choice.blob = *best;
      choice.status = MarkerStatus::kFound;
      return choice;
    }
    if (window == frame_rect) break;
  }
  return Choice{};
}

ColourTracker::Choice ColourTracker::dim_search(const cv::Mat& frame, const cv::Rect& window,
                                                const cv::Point2d& predicted, double reach,
                                                const cv::Point2d& sliver) {
  if (!model_ || !(dim_hsv_ || dim_gray_)) return Choice{};
  dim_blobs_.clear();
  analyse(frame, window, &dim_blobs_, true);
  std::sort(dim_blobs_.begin(), dim_blobs_.end(), CentroidBefore);
  // The marker darkened is the one blob there that holds the sliver the range saw and fits the
  // marker in all but brightness: size, shape, symmetry (not itself partly hidden), contrast to
  // its surroundings and, for a coloured marker, chroma. Two such blobs: neither is taken.
  size_t only = 0;
  double only_misfit = 0;
  int fitting = 0;
  for (size_t i = 0; i < dim_blobs_.size(); ++i) {
    const ColourBlob& b = dim_blobs_[i];
    if (cv::norm(b.centroid_px - predicted) > reach) continue;
    const cv::Rect& box = b.bbox_px;
    if (!(sliver.x >= box.x && sliver.x <= box.x + box.width - 1 && sliver.y >= box.y &&
          sliver.y <= box.y + box.height - 1)) {
      continue;
    }
    const auto [verdict, misfit] = judge(b, true);
    if (verdict != CandidateVerdict::kFits) continue;
    ++fitting;
    only = i;
    only_misfit = misfit;
  }
  if (fitting != 1) return Choice{};
  // The dim pass's blobs are the candidates now; only the chosen one is judged without its
  // brightness (the others as any search judges them, so none is offered as the marker).
  std::swap(blobs_, dim_blobs_);
  blobs_[only].shaded = true;
  blobs_[only].dimmed = true;
  candidates_.clear();
  for (size_t i = 0; i < blobs_.size(); ++i) {
    if (i == only) {
      candidates_.push_back(
          candidate(blobs_[i], CandidateVerdict::kChosen, only_misfit + kShadowMisfit));
      continue;
    }
    const auto [verdict, misfit] = judge(blobs_[i]);
    candidates_.push_back(candidate(blobs_[i], verdict, misfit));
  }
  Choice choice;
  choice.blob = blobs_[only];
  choice.status = MarkerStatus::kFound;
  return choice;
}

ColourTracker::Choice ColourTracker::acquire(const cv::Mat& frame) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  cv::Rect region = frame_rect;
  if (acquire_roi_) {
    region = *acquire_roi_ & frame_rect;
    if (region.empty()) return Choice{std::nullopt, MarkerStatus::kOutOfFrame, 0};
  }
  last_search_px_ = region;
  blobs_.clear();
  const int factor = acquire_downsample();
  if (factor > 1 && region.area() >= kCoarseMinArea) {
    coarse_to_fine(frame, region, factor, &blobs_);
  } else {
    complete_blobs(frame, region, &blobs_);
  }
  std::sort(blobs_.begin(), blobs_.end(), CentroidBefore);

  // Every candidate is judged against the model (or, before one is learned, the configured
  // ranges and a compact, contrasted shape); among those that fit, the best fit wins, with a
  // preference for the neighbourhood of the last known position. A runner-up nearly as good
  // makes the marker ambiguous: a coin toss between look-alikes is not a measurement.
  const double diagonal = std::hypot(frame.cols, frame.rows);
  Ranking ranking = rank_candidates(diagonal);
  Choice choice;
  if (!std::isfinite(ranking.best_cost)) {
    // kLost: nothing whole fits; what fits is partly hidden.
    if (std::isfinite(ranking.partial_cost)) {
      choice.status = ranking.partial_at_edge ? MarkerStatus::kOutOfFrame : MarkerStatus::kCovered;
    }
    return choice;
  }
  ranking.second_cost = std::min(ranking.second_cost, ranking.partial_cost);
  // Before a model is learned, the misfit knows only the configured ranges and a compact,
  // contrasted shape: it cannot tell a marker from a look-alike (a glint, a dot of the bench), so
  // a whole-frame first acquisition needs the one candidate that fits at all.
  const double margin = !model_ && !acquire_roi_ ? std::numeric_limits<double>::infinity()
                                                 : params_.ambiguity_margin;
  const bool by_uniqueness = !model_ && !acquire_roi_;
  if (std::isfinite(ranking.second_cost) && ranking.second_cost - ranking.best_cost < margin) {
    return ambiguous_choice(ranking.best_cost, margin, diagonal, by_uniqueness);
  }
  // The first acquisition learns the marker's size and shape from the blob it takes: a piece of
  // a marker split by compression or noise (a round corner of it, 5 px off its centre) would
  // then be the model, and the whole marker too large to fit it ever after. A larger blob of the
  // same range (twice its area or more: not a neighbouring marker of about its size) right beside
  // the best one means the marker may be that blob, or the two of them:
  // not found until a frame shows it whole.
  if (!model_ && acquire_roi_ && a_larger_piece_beside(ranking.best)) {
    choice.status = MarkerStatus::kAmbiguous;
    choice.tied = 2;
    return choice;
  }
  if (by_uniqueness && !rivals_.empty()) {
    if (a_rival_may_be_it(blobs_[ranking.best])) {
      choice.status = MarkerStatus::kAmbiguous;
      choice.tied = 2;
      return choice;
    }
    rivals_.clear();
  }
  candidates_[ranking.best].verdict = CandidateVerdict::kChosen;
  choice.blob = blobs_[ranking.best];
  choice.status = MarkerStatus::kFound;
  return choice;
}

double ColourTracker::acquisition_cost(double misfit, const cv::Point2d& position_px,
                                       double diagonal) const {
  double cost = misfit;
  if (last_px_) cost += cv::norm(position_px - *last_px_) / diagonal;
  return cost;
}

ColourTracker::Ranking ColourTracker::rank_candidates(double diagonal) {
  const cv::Rect2d roi_area = acquire_roi_ ? cv::Rect2d(acquire_roi_->x - 0.5, acquire_roi_->y - 0.5,
                                                        acquire_roi_->width, acquire_roi_->height)
                                           : cv::Rect2d();
  candidates_.clear();
  Ranking ranking;
  for (const ColourBlob& b : blobs_) {
    auto [verdict, misfit] = judge(b);
    if (verdict == CandidateVerdict::kFits && acquire_roi_ && !roi_area.contains(b.centroid_px)) {
      verdict = CandidateVerdict::kOutsideRoi;
    }
    candidates_.push_back(candidate(b, verdict, misfit));
    const bool partial = verdict == CandidateVerdict::kPartial;
    if (verdict != CandidateVerdict::kFits && !partial) continue;
    const double cost = acquisition_cost(misfit, b.centroid_px, diagonal);
    if (partial) {
      // Partly hidden: never the one reported, but a rival (it may be the marker).
      if (cost < ranking.partial_cost) {
        ranking.partial_cost = cost;
        ranking.partial_at_edge = b.at_frame_edge;
      }
      continue;
    }
    const size_t index = candidates_.size() - 1;
    if (cost < ranking.best_cost) {
      ranking.second_cost = ranking.best_cost;
      ranking.best = index;
      ranking.best_cost = cost;
    } else if (cost < ranking.second_cost) {
      ranking.second_cost = cost;
    }
  }
  return ranking;
}

ColourTracker::Choice ColourTracker::ambiguous_choice(double best_cost, double margin,
                                                     double diagonal, bool by_uniqueness) {
  Choice choice;
  choice.status = MarkerStatus::kAmbiguous;
  if (by_uniqueness) rivals_.clear();
  for (size_t i = 0; i < candidates_.size(); ++i) {
    const bool partial = candidates_[i].verdict == CandidateVerdict::kPartial;
    if (candidates_[i].verdict != CandidateVerdict::kFits && !partial) continue;
    const double cost = acquisition_cost(candidates_[i].misfit, blobs_[i].centroid_px, diagonal);
    if (!partial && cost - best_cost < margin) ++choice.tied;
    if (by_uniqueness) {
      // A partial rival too: the marker leaving the frame is one.
      rivals_.push_back({blobs_[i].centroid_px, std::sqrt(blobs_[i].area_px / CV_PI)});
    }
  }
  return choice;
}

bool ColourTracker::a_larger_piece_beside(size_t chosen) const {
  const ColourBlob& best = blobs_[chosen];
  const cv::Rect& a = best.bbox_px;
  for (size_t i = 0; i < blobs_.size(); ++i) {
    const ColourBlob& other = blobs_[i];
    const cv::Rect& b = other.bbox_px;
    // A piece of the marker the person boxed lies in the box with it: a surface of the range
    // reaching out of the box (a bright board behind white dots) or the next marker is no piece.
    if (i == chosen || other.clipped || other.area_px < kPieceAreaRatio * best.area_px ||
        (b & *acquire_roi_) != b) {
      continue;
    }
    const int dx = std::max({0, a.x - (b.x + b.width), b.x - (a.x + a.width)});
    const int dy = std::max({0, a.y - (b.y + b.height), b.y - (a.y + a.height)});
    if (std::hypot(dx, dy) <= kPieceGapPx) return true;
  }
  return false;
}

bool ColourTracker::a_rival_may_be_it(const ColourBlob& only) const {
  // The one candidate left may be one of those that were tied before, still exactly in its
  // place (a look-alike of the background does not move; a marker on a bending body does).
  // If another of them is still there (a blob in its place that no longer fits: the checks told
  // them apart), the candidate is the marker. If another has vanished, it may have been the
  // marker (gone, or covered) and the one left a look-alike: as ambiguous as before. A
  // candidate that has moved, or is in none of their places, is the marker.
  const auto at = [](const cv::Point2d& p, const Rival& rival) {
    return cv::norm(p - rival.position_px) <= rival.radius_px + 2.0;
  };
  bool was_a_rival = false, a_rival_vanished = false;
  for (const Rival& rival : rivals_) {
    if (cv::norm(only.centroid_px - rival.position_px) <= kRivalStillPx) {
      was_a_rival = true;
      continue;
    }
    bool still_there = false;
    for (const ColourBlob& b : blobs_) still_there = still_there || at(b.centroid_px, rival);
    a_rival_vanished = a_rival_vanished || !still_there;
  }
  return was_a_rival && a_rival_vanished;
}

ColourTracker::Choice ColourTracker::relearn(const cv::Point2d& last_seen) {
  // Chroma is what tells the marker from a darker or brighter look-alike here, so a gray-level
  // marker (brightness is all it has) is never relearned.
  Choice choice;
  if (!model_ || gray_) return choice;
  // Anywhere in the searched region, every candidate that fits in all but brightness counts: the
  // one relearned must be the only one.
  std::optional<size_t> only;
  int fitting = 0;
  for (size_t i = 0; i < candidates_.size() && i < blobs_.size(); ++i) {
    const CandidateVerdict verdict = candidates_[i].verdict;
    if (verdict == CandidateVerdict::kFits ||
        (verdict == CandidateVerdict::kColour &&
         judge(blobs_[i], true).first == CandidateVerdict::kFits)) {
      ++fitting;
      only = i;
    }
  }
  if (fitting > 1) {
    choice.status = MarkerStatus::kAmbiguous;
    choice.tied = fitting;
    return choice;
  }
  // And near where the marker was last seen: a few of its radii, and one more for every frame it
  // has been lost (a marker moving a radius a frame is fast).
  const double reach =
      (kRelearnRadii + lost_frames_) * std::sqrt(model_->area_px / CV_PI);
  if (!only || cv::norm(blobs_[*only].centroid_px - last_seen) > reach) return choice;
  candidates_[*only].verdict = CandidateVerdict::kChosen;
  choice.blob = blobs_[*only];
  choice.status = MarkerStatus::kFound;
  model_->colour = choice.blob->core_colour;  // The new light's colour, learned afresh.
  return choice;
}

}  // namespace softsight
