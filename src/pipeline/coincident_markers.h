// Two markers cannot occupy one place. A tracker that re-acquires onto a look-alike of another
// marker (gray template matching cannot tell same-shape discs apart; a colour threshold may catch
// a neighbour's blob) would report its covered marker at the neighbour's position: a silent wrong
// number. This rule finds such reports so the session can drop them.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"

namespace softsight {

// Distinct markers on one body are at least a marker diameter apart; a false lock lands on the
// neighbour's centroid to within a pixel or two. 3 px separates the two cases for markers of any
// usable size (radius >= 2 px).
inline constexpr double kCoincidentMarkerPx = 3.0;

// Indices (ascending, unique) of observations to drop. Of two found markers closer than
// `min_separation_px`, the one that moved farther from its own previous position loses (a marker
// with no previous position counts as having jumped); when both lack a previous position, or moved
// equally far, neither can be trusted and both are dropped.
std::vector<size_t> FindCoincidentMarkers(
    const std::vector<MarkerObservation>& current,
    const std::vector<std::optional<cv::Point2d>>& previous_px,
    double min_separation_px = kCoincidentMarkerPx);

// Indices (ascending) of found markers within `min_separation_px` of where another marker was
// last believed (`recent_px`, present only for a position believed about a second ago at most)
// while that other marker is not found now. Two markers cannot swap places within a second:
// such a report is the other marker seen in this one's colour (a decoding error that shifted the
// colours of part of a frame, a look-alike at its place). A marker still at its own recent
// position is kept.
std::vector<size_t> FindMarkersOnAMissingMarkersPlace(
    const std::vector<MarkerObservation>& current,
    const std::vector<std::optional<cv::Point2d>>& recent_px,
    double min_separation_px = kCoincidentMarkerPx);

}  // namespace softsight
