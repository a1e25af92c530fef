// Finding the markers in one frame without a person: what `softsight init` does before it writes
// a config.
//
// 1. Candidates: every compact blob that stands out from its surroundings, found by the colour
//    tracker itself (its whole-frame first acquisition and its verdicts: size, shape, contrast,
//    core of its own colour) in overlapping hue bands of saturated pixels, or, on gray frames, in
//    bright and dark gray-level bands (white or black dots).
// 2. Each candidate's ranges come from its own pixels: the live window's click pick at its centre
//    (PickMarkerColourAt), or for a gray dot the level halfway between its core and its
//    surroundings.
// 3. "Found means verified": a candidate becomes a marker only when a colour tracker built from
//    its config, with no roi, finds exactly that blob on the frame, alone. Two look-alikes of one
//    colour make both ambiguous and the finding unusable (never a guess between them). Identical
//    dots (gray) are told apart by a roi each, verified the same way inside it.
// 4. The markers are ordered along the body: the shortest path through them (a body is a curve;
//    a second path nearly as short means the order is ambiguous), base at the end that is nearer
//    the image border (a fixture clamps the actuator there) unless `base_near_px` says otherwise.
//    Three markers give the paper's triple, more a chain (as sim/scene.h's SceneMeasureOptions).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/geometry/measurement.h"
#include "softsight/track/hsv_picker.h"
#include "softsight/track/tracker.h"

namespace softsight {

struct MarkerFinderOptions {
  // Only candidates whose centre lies in this rectangle (frame pixels) count; absent: the whole
  // frame. Restricting the search to the actuator removes look-alikes elsewhere; each marker then
  // gets a roi, which `track` applies from the analysed frame on (frame_index).
  std::optional<cv::Rect> search_px{};
  // How many markers the body carries; absent: as many as are verified. A different count is a
  // problem (the finding is not usable), never a silent choice.
  std::optional<int> expected_count{};
  // The end of the body nearest this point is the base; absent: the end nearer the image border.
  std::optional<cv::Point2d> base_near_px{};
  // Weakest colour a marker may have (8-bit HSV saturation and value). Default 70 / 40: printed
  // or painted markers are far above; wood, skin and shadows mostly below. Each hue is searched
  // from min_value and again from half of it (a blue dome under warm light is dim in value).
  int min_saturation = 70;
  int min_value = 40;
  // Marker size limits: area in pixels, and the largest as a fraction of the frame area.
  // Defaults 12 px (a disc of radius 2) and 2 % (radius 44 at VGA, 77 at 720p: close-ups).
  double min_area_px = 12.0;
  double max_area_fraction = 0.02;
  // The live window's click pick, used at each candidate's centre (its radius is shrunk to stay
  // inside small markers).
  HsvPickOptions picker{};
  // Side of each marker's roi (as live's click box, `LiveOptions::select_box_px`), px; at least
  // four marker radii, and smaller than the distance to the nearest other candidate.
  int roi_side_px = 32;
  // Index (Frame::index) of the analysed frame in its input. Rois are where the markers are in
  // that frame, so each applies from it on (ColourParams::roi_frame; not started before).
  int64_t frame_index = 0;

  // Throws InputError naming the field when an option is unusable.
  void Check() const;
};

// A candidate that did not become a marker, and why ("shape", "contrast", "ambiguous: ...").
struct RejectedCandidate {
  cv::Point2d position_px{};
  double radius_px = 0;
  std::string why{};
};

struct FoundMarker {
  MarkerSpec spec{};            // Name, method colour, ranges (and roi) ready for a config.
  cv::Point2d position_px{};    // Where the verifying tracker found it in the frame.
  double radius_px = 0;         // Of a disc of the blob's area.
  // Its colour alone does not tell it from other blobs of the frame (identical markers, or
  // look-alikes outside the search region): only its roi does, so the roi must stay.
  bool needs_roi = false;
};

struct MarkerFinding {
  std::vector<FoundMarker> markers{};  // In body order, base first.
  std::vector<RejectedCandidate> rejected{};
  MeasureOptions measure{};          // Triple (3 markers) or triple + chain (more); none below 3.
  bool intensity = false;            // Gray-level dots (the frame is gray).
  // Empty when the markers can be used; otherwise why not, in one line (no markers, look-alikes,
  // a wrong count, an ambiguous order). The markers found so far are kept for the picture.
  std::string problem{};
  // What the finding decided without being sure of it, for the user to check ("base: the end
  // nearer the image border").
  std::vector<std::string> notes{};

  bool ok() const { return problem.empty(); }
};

// Finds, verifies and orders the markers of `frame` (8-bit BGR, or gray). Throws InputError on
// unusable options or an empty frame; a frame without usable markers is a finding with a problem.
MarkerFinding FindMarkers(const cv::Mat& frame, const MarkerFinderOptions& options = {});

// Turns the body order round (the base becomes the tip): dots are renamed dot0.. in the new
// order, the triple and chain follow. For when a video shows which end is fixed.
void ReverseBodyOrder(MarkerFinding* finding);

// The frame with what was found (rings, names, body order, the roi boxes) and what was rejected
// (crosses with the reason): `softsight init`'s picture.
cv::Mat DrawMarkerFinding(const cv::Mat& frame, const MarkerFinding& finding);

// Orders `points` along a body: the open path through all of them of least total length (exact
// up to 8 points, nearest-neighbour paths beyond), reversed so that it starts at the end nearer
// `base_near_px` (absent: nearer the border of an image of `image_size`). Returns the indices in
// body order; sets `ambiguous` when a different path (not the reverse) is within 10 % of it.
std::vector<size_t> OrderAlongBody(const std::vector<cv::Point2d>& points, cv::Size image_size,
                                   const std::optional<cv::Point2d>& base_near_px,
                                   bool* ambiguous = nullptr);

}  // namespace softsight
