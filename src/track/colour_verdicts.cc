// ColourTracker, part 3 of 3: verification. Each candidate's verdict and misfit against the
// marker's model (or, before one is learned, the configured ranges), and where a partly hidden
// round marker's centre is.
#include "softsight/track/colour_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "track/colour_tracker_impl.h"
#include "track/colour_tracker_parts.h"
#include "track/track_options.h"

namespace softsight {

using namespace colour_internal;  // NOLINT: the tracker's own constants and helpers.

MarkerCandidate ColourTracker::candidate(const ColourBlob& b, CandidateVerdict verdict,
                                         double misfit) const {
  MarkerCandidate c;
  c.position_px = b.clipped ? cv::Point2d(b.bbox_px.x + (b.bbox_px.width - 1) / 2.0,
                                          b.bbox_px.y + (b.bbox_px.height - 1) / 2.0)
                            : b.centroid_px;
  c.area_px = b.area_px;
  c.circularity = b.circularity;
  c.misfit = misfit;
  c.verdict = verdict;
  return c;
}

std::pair<CandidateVerdict, double> ColourTracker::judge(const ColourBlob& b,
                                                         bool any_brightness) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (b.clipped) return {CandidateVerdict::kClipped, kInf};
  if (b.area_px < params_.min_area_px || (params_.max_area_px > 0 && b.area_px > params_.max_area_px)) {
    return {CandidateVerdict::kSize, kInf};
  }
  // Without a model and a roi the first acquisition takes the one compact candidate; in a roi a
  // person showed the marker, and the configured limit holds (an elongated sticker).
  const double min_circularity =
      model_ || acquire_roi_ ? params_.min_circularity
                             : std::max(params_.min_circularity, kMinCircularityWithoutModel);
  if (b.circularity < min_circularity || !b.measured) return {CandidateVerdict::kShape, kInf};
  // Part of it hidden: beyond the frame's edge, or covered (more asymmetric than the marker).
  // Judged on for its misfit: a partial blob that would fit is a rival of the others (it may be
  // the marker) and is never reported itself.
  // A blob placed at the centre of its visible rim is partial no more: its position is the
  // marker's.
  bool partial = b.at_frame_edge && !b.rim_placed;
  if (model_ && !b.rim_placed) {
    // The asymmetry is measured against the smallest enclosing circle, whose centre an elongated
    // marker's two ends place: its wobble grows with that circle, not with the area (a 2:1
    // sticker's is 1.4 times a disc's of the same area). What is left of a covered marker has a
    // smaller circle than the marker: the learned area's radius bounds it from below.
    const double radius = std::max(std::sqrt(model_->area_px / CV_PI), b.enclosing_radius_px);
    const double tolerance = std::max(kPartialMinPx, kPartialRadii * radius);
    // Both the blob and its hull: a notch (a highlight, a speck) leaves the hull whole.
    const double limit = model_->asymmetry_px + tolerance;
    partial = partial || (b.asymmetry_px > limit && b.hull_asymmetry_px > limit);
  }
  if (!model_ && !acquire_roi_ && b.core_px < kMinCorePxWithoutModel) {
    return {CandidateVerdict::kSize, kInf};
  }
  double misfit = 0;
  // Shape: 0 as round as the model (a disc without one), 1 at the limit.
  // Before a model, in a roi, any shape down to the configured limit may be the marker (the
  // person showed it): the span reaches that limit.
  const double ref_circularity = model_ ? model_->circularity : 1.0;
  const double shape_span =
      model_ || !acquire_roi_
          ? std::max(0.05, std::min(kShapeTolerance, ref_circularity - min_circularity))
          : std::max(0.05, ref_circularity - min_circularity);
  const double shape = std::max(0.0, ref_circularity - b.circularity) / shape_span;
  if (shape > 1) return {CandidateVerdict::kShape, kInf};
  misfit += shape;
  // Size against the learned area: the configured fraction and factor are the limits.
  if (model_) {
    const double ratio = b.area_px / model_->area_px;
    double size = 0;
    if (ratio < 1 && params_.min_area_fraction > 0) {
      if (ratio < params_.min_area_fraction) return {CandidateVerdict::kSize, kInf};
      size = std::log(ratio) / std::log(params_.min_area_fraction);
    } else if (ratio > 1 && params_.max_area_factor > 0) {
      if (ratio > params_.max_area_factor) return {CandidateVerdict::kSize, kInf};
      size = std::log(ratio) / std::log(params_.max_area_factor);
    }
    misfit += size;
    // Little more than half its learned area at once (the area follows slow changes only): a
    // disc cut beyond its centre, whose centroid is more than 0.4 radii off. The asymmetry cannot
    // tell: the smallest circle around less than half a disc is no longer the disc's.
    partial = partial || (ratio < kWholeAreaFraction && !b.rim_placed);
  }
  // Contrast to its own surroundings.
  if (!(b.contrast >= kMinContrast)) return {CandidateVerdict::kContrast, kInf};
  if (!model_ && !acquire_roi_ && !(b.whole_ring_contrast >= kMinContrast)) {
    return {CandidateVerdict::kContrast, kInf};
  }
  misfit += kMinContrast / b.contrast;
  // Colour against the learned core colour, or the nominal one.
  const std::optional<cv::Vec3d> reference =
      model_ ? std::optional<cv::Vec3d>(model_->colour) : nominal_;
  if (reference) {
    const int channels = gray_ ? 1 : 3;
    const double ref_bright = Norm(*reference, channels);
    const double bright = Norm(b.core_colour, channels);
    double colour = 0;
    if (ref_bright > 1 && bright > 1) {
      if (!any_brightness) {
        colour = std::abs(std::log(bright / ref_bright)) / std::log(kBrightnessTolerance);
      }
      if (channels == 3) {
        const double cosine = std::clamp(b.core_colour.dot(*reference) / (bright * ref_bright),
                                         -1.0, 1.0);
        colour = std::max(colour, std::acos(cosine) / kChromaTolerance);
      }
    } else if (std::abs(bright - ref_bright) > 8) {
      colour = kInf;  // One of them black: compare levels directly.
    }
    if (colour > 1) return {CandidateVerdict::kColour, kInf};
    misfit += colour;
  }
  return {partial ? CandidateVerdict::kPartial : CandidateVerdict::kFits, misfit};
}

std::optional<double> ColourTracker::rim_radius_px() const {
  if (!params_.rim_fit || !model_ || model_->circularity < kMinRimCircularity ||
      model_->area_px < kMinRimArea) {
    return std::nullopt;
  }
  // The centres of a disc's edge pixels lie half a pixel inside its outline.
  return std::sqrt(model_->area_px / CV_PI) - 0.5;
}

std::optional<cv::Point2d> ColourTracker::RimCentre(const ColourBlob& blob) const {
  const std::optional<double> radius = rim_radius_px();
  if (!blob.rim || !radius) return std::nullopt;
  const RimFit& fit = *blob.rim;
  // Half of the rim or more, densely on the circle (a disc's edge has about 1.1 pixels per
  // pixel of its length), within half a pixel of it.
  const double expected = 2 * CV_PI * *radius * fit.arc_deg / 360.0;
  if (fit.arc_deg < kMinRimArcDeg || fit.rms_px > kMaxRimRmsPx || fit.rim_points < 0.8 * expected) {
    return std::nullopt;
  }
  // What is left of the marker lies inside its circle: a blob reaching outside it is not this
  // marker partly hidden (a look-alike touching it, another shape).
  const double reach = *radius + 1.0;
  const cv::Point2d c = fit.centre_px;
  const cv::Rect2d circle_box(c.x - reach, c.y - reach, 2 * reach, 2 * reach);
  if (blob.bbox_px.x < circle_box.x || blob.bbox_px.y < circle_box.y ||
      blob.bbox_px.x + blob.bbox_px.width - 1 > circle_box.x + circle_box.width ||
      blob.bbox_px.y + blob.bbox_px.height - 1 > circle_box.y + circle_box.height) {
    return std::nullopt;
  }
  return c;
}

double ColourTracker::min_blob_radius_px() const {
  const double min_area = std::max(params_.min_area_px,
                                   params_.min_area_fraction * (model_ ? model_->area_px : 0.0));
  return std::sqrt(min_area / CV_PI);
}

int ColourTracker::acquire_downsample() const {
  if (params_.acquire_downsample > 0) return params_.acquire_downsample;
  // The smallest blob that can count as the marker must hold sample points of the coarse grid
  // (spacing f): a disc of radius r >= f / sqrt(2) holds one, r >= f holds at least three.
  const double radius = min_blob_radius_px();
  int factor = 1;
  while (factor < 8 && radius >= 2.0 * factor) factor *= 2;
  return factor;
}

}  // namespace softsight
