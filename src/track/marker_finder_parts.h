// What the three parts of `init`'s marker finder (softsight/track/marker_finder.h) share: the
// candidate search (marker_candidates.cc: the colour tracker's whole-frame acquisition, band by
// band), each candidate's verification (marker_verification.cc: its own ranges, found again by a
// tracker built from them) and the judgement of the whole set (marker_finder.cc: twins, look-alikes,
// body order, the problem). Internal to the track library.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/hsv_range.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/marker_finder.h"
#include "softsight/track/tracker.h"

namespace softsight::marker_finding {

// Hue bands of the candidate search: centres every kHueStep, reaching kHueReach either side, so
// any marker whose hues spread over less than 2 * kHueReach - kHueStep lies wholly in one band.
constexpr int kHueStep = 10;
constexpr int kHueReach = 12;
// Elongated stickers and bars: a whole-frame search takes only compact blobs (the colour tracker's
// rule without a model: elongated patches of a colour are common), so coloured blobs it refused
// for their shape alone, down to this circularity, are candidates too: one is a marker only when
// it fills its moment ellipse (the ellipse of its area's second moments) to at least
// kMinEllipseFill (an ellipse fills it exactly, a bar 0.955, a ragged stain or an object's rim far
// less) and is verified in its own roi, where the configured shape limit holds. Its marker takes
// kStickerCircularity of its own circularity as its min_circularity (a turning bar's pixel
// outline varies).
constexpr double kMinCandidateCircularity = 0.3;
constexpr double kMinEllipseFill = 0.9;
constexpr double kStickerCircularity = 0.6;
// ... and is at least twice this wide (its ellipse's minor semi-axis): a narrower elongated blob
// is a streak, a thread or a fragment of an edge as often as a sticker.
constexpr double kMinStickerHalfWidthPx = 3.0;
// ... and is at least twice this wide (its ellipse's minor semi-axis): a narrower elongated blob
// is a streak, a thread or a fragment of an edge as often as a sticker.

struct Candidate {
  cv::Point2d position_px;
  double area_px = 0;
  double circularity = 1;
  bool elongated = false;  // Refused by the whole-frame search for its shape alone.
  std::optional<HsvRange> band_gray;  // Gray-level band that found it (gray frames).
};

// Median HSV saturation and value of the disc of 0.6 radii around `centre`.
struct CoreLooks {
  double saturation = 0;
  double value = 0;
};

// A candidate verified as a marker, with what the judgement of the whole set weighs.
struct Verified {
  FoundMarker marker;
  int hue = 0;
  CoreLooks looks;     // Medians over its core (colour markers).
  bool twin = false;   // One of several alike blobs of its colour, told apart by its roi.
  bool elongated = false;
};
// A candidate refused as ambiguous: blobs of its colour that its ranges cannot tell apart.
struct LookAlike {
  std::string colour;
  int hue = 0;
  double radius_px = 0;
  size_t rejected_index = 0;  // Its entry in finding.rejected.
};

// The radius of a disc of `area_px`.
inline double RadiusOf(double area_px) { return std::sqrt(std::max(area_px, 0.0) / CV_PI); }

// How far `p` lies inside an image of `size` (negative: outside).
inline double BorderDistance(const cv::Point2d& p, cv::Size size) {
  return std::min({p.x, p.y, size.width - 1 - p.x, size.height - 1 - p.y});
}

// One probe of the colour tracker's whole-frame first acquisition with `colour`: what it weighed.
std::vector<MarkerCandidate> Probe(const cv::Mat& frame, const ColourParams& colour);

// ---- 1. Candidates: the colour tracker's own verdicts, band by band (marker_candidates.cc) ----
// Blobs that fitted a band (or, for colour, were refused for their shape alone: elongated), in
// `search`; the larger blobs every band refused go to finding->rejected with the reason.
std::vector<Candidate> FindCandidates(const cv::Mat& frame, const MarkerFinderOptions& options,
                                      const cv::Rect& search, MarkerFinding* finding);

// ---- 2 + 3. A candidate's own ranges, verified by a tracker built from them ------------------
// (marker_verification.cc) Candidate `i` of `fitting` as a marker, or nullopt with its reason in
// finding->rejected (and, when look-alikes of its colour made it ambiguous, in *ambiguous).
std::optional<Verified> VerifyCandidate(const cv::Mat& frame, const MarkerFinderOptions& options,
                                        const std::vector<Candidate>& fitting, size_t i,
                                        MarkerFinding* finding, std::vector<LookAlike>* ambiguous);

}  // namespace softsight::marker_finding
