// Finding, verifying and ordering the markers of one frame: see marker_finder.h. The candidates
// and their verification are marker_candidates.cc and marker_verification.cc
// (marker_finder_parts.h); here the set of verified blobs is judged as the markers of one body.
#include "softsight/track/marker_finder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/hsv_picker.h"
#include "track/marker_finder_parts.h"

namespace softsight {
namespace marker_finding {
namespace {

// Rejected blobs listed (and drawn) at most, the largest first.
constexpr size_t kMaxListedRejects = 40;
// Markers of one body have about one size: a blob this many times another's area is not one of them.
constexpr double kMaxAreaRatio = 6.0;
// The markers of one body are made alike: their radii lie within this factor of their median
// (perspective across one body changes them far less). A verified blob outside it, among a
// majority inside, is not a marker (a stain of the bench with a clean edge); look-alikes outside
// it do not stop init.
constexpr double kBodySizeRatio = 1.4;
// ... and as saturated: a verified blob below this fraction of their median saturation, among a
// majority above it, is a pale stain rather than one of them.
constexpr double kMinSaturationRatio = 0.6;
// Neighbouring markers along a body are spaced within this factor of each other. Markers are put
// on an actuator at even steps, and a constant-curvature bend keeps the chords between evenly
// spaced markers equal (perspective changes them gradually): a blob off the body at an end of
// the path breaks it. With the count given (--markers) the spacing is the user's business.
constexpr double kMaxSpacingRatio = 1.6;
// Blobs of one colour that the colour alone cannot tell apart are identical markers (a dot on
// each of two carts, a row of pucks) when their radii lie within this factor of each other and
// their core saturation and brightness within this fraction: printed or cut from one sheet, they
// differ far less (perspective, a highlight), while patches of the bench differ more. Their
// hues (the centres of their picked ranges) lie within kTwinHueApart.
constexpr double kTwinSizeRatio = 1.25;
constexpr int kTwinHueApart = 5;  // OpenCV hue units (0..180); red and orange are 10 apart.
constexpr double kTwinLooksRatio = 0.8;
// A second body order within this fraction of the shortest path's length makes the order ambiguous.
constexpr double kOrderAmbiguity = 0.10;
// Paths through at most this many markers are searched exhaustively.
constexpr size_t kExactOrderMax = 8;

// A frame whose channels are equal everywhere: gray video stored as colour.
bool IsGrayFrame(const cv::Mat& frame) {
  if (frame.channels() == 1) return true;
  for (int y = 0; y < frame.rows; ++y) {
    const cv::Vec3b* row = frame.ptr<cv::Vec3b>(y);
    for (int x = 0; x < frame.cols; ++x) {
      if (row[x][0] != row[x][1] || row[x][1] != row[x][2]) return false;
    }
  }
  return true;
}

// A frame with hardly any colour: gray footage after a codec's chroma and a sensor's noise (each
// channel a few levels apart), or a gray bench with white dots. Fewer than 1 % of the pixels (one
// in four of every fourth row sampled) have channels more than 16 levels apart.
bool IsNearlyGrayFrame(const cv::Mat& frame) {
  constexpr int kMaxChannelSpread = 16;
  int64_t sampled = 0, coloured = 0;
  for (int y = 0; y < frame.rows; y += 4) {
    const cv::Vec3b* row = frame.ptr<cv::Vec3b>(y);
    for (int x = 0; x < frame.cols; x += 4) {
      const int lo = std::min({row[x][0], row[x][1], row[x][2]});
      const int hi = std::max({row[x][0], row[x][1], row[x][2]});
      ++sampled;
      if (hi - lo > kMaxChannelSpread) ++coloured;
    }
  }
  return coloured * 100 < sampled;
}

double PathLength(const std::vector<cv::Point2d>& points, const std::vector<size_t>& order) {
  double length = 0;
  for (size_t i = 1; i < order.size(); ++i) length += cv::norm(points[order[i]] - points[order[i - 1]]);
  return length;
}

// The triple (and, beyond three, the chain) of markers in body order (MeasureOptions::AlongBody).
MeasureOptions BodyMeasure(const std::vector<FoundMarker>& markers) {
  std::vector<std::string> names;
  for (const FoundMarker& m : markers) names.push_back(m.spec.name);
  return MeasureOptions::AlongBody(names);
}

// ---- 2 + 3, over all candidates ------------------------------------------------------------
// Every candidate verified; the markers of one body are of one kind: beside round markers, an
// elongated blob is a patch of the scene, not a sticker of theirs.
std::vector<Verified> VerifyAll(const cv::Mat& frame, const MarkerFinderOptions& options,
                                const std::vector<Candidate>& fitting, MarkerFinding* finding,
                                std::vector<LookAlike>* ambiguous) {
  std::vector<Verified> verified;
  for (size_t i = 0; i < fitting.size(); ++i) {
    if (std::optional<Verified> v = VerifyCandidate(frame, options, fitting, i, finding, ambiguous)) {
      verified.push_back(std::move(*v));
    }
  }
  if (std::any_of(verified.begin(), verified.end(), [](const Verified& v) { return !v.elongated; })) {
    for (const Verified& v : verified) {
      if (v.elongated) {
        finding->rejected.push_back({v.marker.position_px, v.marker.radius_px,
                                     "elongated, unlike the round markers"});
      }
    }
    verified.erase(std::remove_if(verified.begin(), verified.end(),
                                  [](const Verified& v) { return v.elongated; }),
                   verified.end());
  }
  return verified;
}

// ---- Twins: blobs of one colour that only their rois tell apart --------------------------------
int HuesApart(int a, int b) { return std::min(std::abs(a - b), 180 - std::abs(a - b)); }

// The twins whose hue lies within kTwinHueApart of verified[i]'s (indices into `verified`).
std::vector<size_t> TwinGroup(const std::vector<Verified>& verified, size_t i) {
  std::vector<size_t> group;
  for (size_t j = 0; j < verified.size(); ++j) {
    if (verified[j].twin && HuesApart(verified[j].hue, verified[i].hue) <= kTwinHueApart) {
      group.push_back(j);
    }
  }
  return group;
}

// Whether the twins of `group` are alike in everything a tracker can see (size, saturation,
// brightness) and no look-alike near their hue stayed unresolved.
bool GroupAlike(const std::vector<Verified>& verified, const std::vector<size_t>& group,
                const std::vector<LookAlike>& ambiguous) {
  double r_lo = 1e9, r_hi = 0, s_lo = 1e9, s_hi = 0, v_lo = 1e9, v_hi = 0;
  for (size_t j : group) {
    const Verified& t = verified[j];
    r_lo = std::min(r_lo, t.marker.radius_px), r_hi = std::max(r_hi, t.marker.radius_px);
    s_lo = std::min(s_lo, t.looks.saturation), s_hi = std::max(s_hi, t.looks.saturation);
    v_lo = std::min(v_lo, t.looks.value), v_hi = std::max(v_hi, t.looks.value);
  }
  const int hue = verified[group.front()].hue;
  const bool unresolved = std::any_of(ambiguous.begin(), ambiguous.end(), [&](const LookAlike& a) {
    return HuesApart(a.hue, hue) <= kHueReach;
  });
  return group.size() >= 2 && !unresolved && r_hi <= kTwinSizeRatio * r_lo &&
         s_lo >= kTwinLooksRatio * s_hi && v_lo >= kTwinLooksRatio * v_hi;
}

// Twins of one colour are markers only when they are alike (GroupAlike): then each is followed
// in its own roi. Otherwise (a larger, a darker, a half-sized patch of a marker's colour) init
// cannot tell which of them is the marker and will not guess.
// A refused group's twins become look-alikes of their colour, which may refuse another group
// near that colour: refused groups are taken out until every group left is alike.
void SettleTwins(std::vector<Verified>* verified_io, std::vector<LookAlike>* ambiguous,
                 MarkerFinding* finding) {
  std::vector<Verified>& verified = *verified_io;
  for (bool refused = true; refused;) {
    refused = false;
    for (size_t i = 0; i < verified.size() && !refused; ++i) {
      if (!verified[i].twin) continue;
      const std::vector<size_t> group = TwinGroup(verified, i);
      if (GroupAlike(verified, group, *ambiguous)) continue;
      for (size_t j : group) {
        const Verified& t = verified[j];
        ambiguous->push_back({HueName(t.hue), t.hue, t.marker.radius_px, finding->rejected.size()});
        finding->rejected.push_back({t.marker.position_px, t.marker.radius_px,
                                     "ambiguous: look-alikes of its colour that differ from it"});
      }
      for (size_t k = group.size(); k-- > 0;) verified.erase(verified.begin() + group[k]);
      refused = true;
    }
  }
  for (size_t i = 0; i < verified.size(); ++i) {
    if (!verified[i].twin) continue;
    const std::vector<size_t> group = TwinGroup(verified, i);
    for (size_t j : group) verified[j].twin = false;  // Settled: markers, a roi each.
    finding->notes.push_back(std::to_string(group.size()) + " alike " +
                             HueName(verified[i].hue) +
                             " blobs are taken as identical markers, each told apart by its roi "
                             "(restrict the search with --roi X,Y,W,H if some are not markers)");
  }
}

// ---- Look-alikes, the rejects listed, markers unlike the others ------------------------------
// The colours whose look-alikes could be markers of this body: they make the finding unusable
// (init will not guess between them). Once markers are verified, the body's markers have about
// their size, so a pair of look-alikes of another size (a patch of the bench, twice as large) is
// only a reject.
std::vector<std::string> BodySizedLookAlikes(const std::vector<Verified>& verified,
                                             const std::vector<LookAlike>& ambiguous,
                                             MarkerFinding* finding) {
  std::vector<std::string> look_alikes;
  double median_radius = 0;
  if (!verified.empty()) {
    std::vector<double> radii;
    for (const Verified& v : verified) radii.push_back(v.marker.radius_px);
    std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
    median_radius = radii[radii.size() / 2];
  }
  for (const LookAlike& a : ambiguous) {
    const bool body_sized = verified.empty() || (a.radius_px >= median_radius / kBodySizeRatio &&
                                                 a.radius_px <= median_radius * kBodySizeRatio);
    if (!body_sized) {
      finding->rejected[a.rejected_index].why += ", unlike the markers' size";
    } else if (std::find(look_alikes.begin(), look_alikes.end(), a.colour) == look_alikes.end()) {
      look_alikes.push_back(a.colour);
    }
  }
  return look_alikes;
}

// The rejects worth showing, largest first: only blobs of about a marker's size (texture specks
// are many), at most kMaxListedRejects.
void TrimRejected(const std::vector<Verified>& verified, MarkerFinding* finding) {
  if (!verified.empty()) {
    double smallest = std::numeric_limits<double>::infinity();
    for (const Verified& v : verified) smallest = std::min(smallest, v.marker.radius_px);
    finding->rejected.erase(std::remove_if(finding->rejected.begin(), finding->rejected.end(),
                                           [&](const RejectedCandidate& r) {
                                             return r.radius_px < 0.5 * smallest;
                                           }),
                            finding->rejected.end());
  }
  std::sort(finding->rejected.begin(), finding->rejected.end(),
            [](const RejectedCandidate& a, const RejectedCandidate& b) {
              return a.radius_px > b.radius_px;
            });
  if (finding->rejected.size() > kMaxListedRejects) finding->rejected.resize(kMaxListedRejects);
}

// With most of at least three markers agreeing on `value`, drops those whose value is
// `unlike_median` (to finding->rejected); without such a majority it leaves them all.
void DropMinority(const std::function<double(const Verified&)>& value,
                  const std::function<bool(double, double)>& unlike_median,
                  std::vector<Verified>* verified, MarkerFinding* finding) {
  if (verified->size() < 3) return;
  std::vector<double> values;
  for (const Verified& v : *verified) values.push_back(value(v));
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  const double median = values[values.size() / 2];
  const auto unlike = [&](const Verified& v) { return unlike_median(value(v), median); };
  const size_t outliers =
      static_cast<size_t>(std::count_if(verified->begin(), verified->end(), unlike));
  if (outliers * 2 >= verified->size()) return;
  for (const Verified& v : *verified) {
    if (unlike(v)) {
      finding->rejected.push_back({v.marker.position_px, v.marker.radius_px,
                                   "unlike the other markers (size or paleness)"});
    }
  }
  verified->erase(std::remove_if(verified->begin(), verified->end(), unlike), verified->end());
}

// Markers of one body are made alike: with most of them agreeing, a blob of another size (a
// patch of the bench with a clean edge), then a pale one among vivid markers (a stain), is not
// one of them. Without such a majority the finding is refused later (sizes too different).
void DropUnlikeMarkers(std::vector<Verified>* verified, MarkerFinding* finding) {
  DropMinority([](const Verified& v) { return v.marker.radius_px; },
               [](double r, double median) {
                 return r < median / kBodySizeRatio || r > median * kBodySizeRatio;
               },
               verified, finding);
  if (!finding->intensity) {
    DropMinority([](const Verified& v) { return v.looks.saturation; },
                 [](double s, double median) { return s < kMinSaturationRatio * median; },
                 verified, finding);
  }
}

// ---- 4. Body order, names, measurement -----------------------------------------------------
// The verified markers, named, into finding->markers in body order, with their measurement and a
// note on which end is the base. Returns whether the order is ambiguous.
bool PutInBodyOrder(std::vector<Verified>* verified, const MarkerFinderOptions& options,
                    cv::Size frame_size, MarkerFinding* finding) {
  std::vector<cv::Point2d> positions;
  for (const Verified& v : *verified) positions.push_back(v.marker.position_px);
  bool order_ambiguous = false;
  const std::vector<size_t> order =
      OrderAlongBody(positions, frame_size, options.base_near_px, &order_ambiguous);
  for (size_t k = 0; k < order.size(); ++k) {
    Verified& v = (*verified)[order[k]];
    std::string name = finding->intensity ? "dot" + std::to_string(k) : HueName(v.hue);
    if (!finding->intensity) {
      int same = 0;
      for (const FoundMarker& m : finding->markers) {
        if (m.spec.name == name || m.spec.name.rfind(name + "_", 0) == 0) ++same;
      }
      if (same > 0) name += "_" + std::to_string(same + 1);
    }
    v.marker.spec.name = name;
    ColourParams& colour = v.marker.spec.params.get<ColourParams>();
    if (colour.roi) colour.roi_frame = static_cast<int>(options.frame_index);
    finding->markers.push_back(v.marker);
  }
  finding->measure = BodyMeasure(finding->markers);
  if (finding->markers.size() >= 2) {
    finding->notes.push_back(
        "base: " + finding->markers.front().spec.name +
        (options.base_near_px ? " (the end nearest the given point)"
                              : " (the end nearer the image border; --base X,Y chooses)"));
  }
  return order_ambiguous;
}

// ---- The verdict on the whole set ----------------------------------------------------------
// Why nothing was found, the reasons most frequent first: what a person needs to change (light,
// focus, markers).
std::string NoMarkersProblem(const MarkerFinding& finding) {
  std::vector<std::pair<std::string, int>> reasons;
  for (const RejectedCandidate& r : finding.rejected) {
    const std::string reason = r.why.substr(0, r.why.find(" ("));
    auto it = std::find_if(reasons.begin(), reasons.end(),
                           [&](const auto& entry) { return entry.first == reason; });
    if (it == reasons.end()) {
      reasons.emplace_back(reason, 1);
    } else {
      ++it->second;
    }
  }
  std::stable_sort(reasons.begin(), reasons.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string why;
  for (const auto& [reason, count] : reasons) {
    why += (why.empty() ? ": " : ", ") + std::to_string(count) + " " + reason;
  }
  return std::string("no markers: no compact ") +
         (finding.intensity ? "white or black dot" : "saturated blob") +
         " stands out from its surroundings (" + std::to_string(finding.rejected.size()) +
         " blobs of some size rejected" + why + "; see the picture)";
}

// Sets finding->problem when the markers found cannot be used (look-alikes, none, a wrong count,
// sizes or spacings no body has); markers in no clear order are kept without a body to measure.
void JudgeFinding(const MarkerFinderOptions& options, const std::vector<std::string>& look_alikes,
                  bool order_ambiguous, MarkerFinding* finding_out) {
  MarkerFinding& finding = *finding_out;
  const size_t n = finding.markers.size();
  double min_radius = std::numeric_limits<double>::infinity(), max_radius = 0;
  for (const FoundMarker& m : finding.markers) {
    min_radius = std::min(min_radius, m.radius_px);
    max_radius = std::max(max_radius, m.radius_px);
  }
  double min_segment = std::numeric_limits<double>::infinity(), max_segment = 0;
  for (size_t i = 1; i < n; ++i) {
    const double d = cv::norm(finding.markers[i].position_px - finding.markers[i - 1].position_px);
    min_segment = std::min(min_segment, d);
    max_segment = std::max(max_segment, d);
  }
  if (!look_alikes.empty()) {
    std::string text;
    for (const std::string& l : look_alikes) text += (text.empty() ? "" : "; ") + l;
    finding.problem = "several blobs fit each of these colours alike, and init will not guess "
                      "which is the marker: " + text + " (restrict the search to the actuator with --roi X,Y,W,H, or pick the "
                      "markers with `softsight pick`)";
  } else if (n == 0) {
    finding.problem = NoMarkersProblem(finding);
  } else if (options.expected_count && static_cast<int>(n) != *options.expected_count) {
    finding.problem = "found " + std::to_string(n) + " markers, expected " +
                      std::to_string(*options.expected_count) + " (see the picture)";
  } else if (n >= 2 && max_radius * max_radius > kMaxAreaRatio * min_radius * min_radius) {
    char text[200];
    std::snprintf(text, sizeof(text),
                  "the blobs found differ too much in size to be the markers of one body (radius "
                  "%.1f to %.1f px): restrict the search with --roi X,Y,W,H",
                  min_radius, max_radius);
    finding.problem = text;
  } else if (n >= 3 && !options.expected_count && max_segment > kMaxSpacingRatio * min_segment) {
    char text[220];
    std::snprintf(text, sizeof(text),
                  "the markers are unevenly spaced along the body (neighbours %.0f to %.0f px "
                  "apart): one of them may not be a marker (--roi X,Y,W,H); if they are all markers, "
                  "say how many with --markers N",
                  min_segment, max_segment);
    finding.problem = text;
  } else if (order_ambiguous) {
    // Markers in no clear order (a plate of dots, markers on several bodies) are still the
    // markers: written to track their positions, with no body to measure, rather than refused.
    finding.measure = MeasureOptions();
    finding.notes.push_back("the order along a body is ambiguous (two paths through the markers "
                            "are about as short): the markers are written without a body "
                            "(positions only); name base, middle and tip under `measure:` for "
                            "angles, or choose a frame where the actuator is less bent (--frame)");
  }
}

// FindMarkers on a BGR frame, looking for saturated blobs or (`intensity`) white or black dots.
MarkerFinding FindMarkersAs(const cv::Mat& frame, const MarkerFinderOptions& options,
                            bool intensity) {
  MarkerFinding finding;
  finding.intensity = intensity;
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  const cv::Rect search = options.search_px ? (*options.search_px & frame_rect) : frame_rect;
  if (search.empty()) throw InputError("the search region lies outside the frame");
  const std::vector<Candidate> fitting = FindCandidates(frame, options, search, &finding);
  std::vector<LookAlike> ambiguous;
  std::vector<Verified> verified = VerifyAll(frame, options, fitting, &finding, &ambiguous);
  SettleTwins(&verified, &ambiguous, &finding);
  const std::vector<std::string> look_alikes = BodySizedLookAlikes(verified, ambiguous, &finding);
  TrimRejected(verified, &finding);
  DropUnlikeMarkers(&verified, &finding);
  const bool order_ambiguous = PutInBodyOrder(&verified, options, frame.size(), &finding);
  JudgeFinding(options, look_alikes, order_ambiguous, &finding);
  return finding;
}

}  // namespace
}  // namespace marker_finding

void ReverseBodyOrder(MarkerFinding* finding) {
  std::reverse(finding->markers.begin(), finding->markers.end());
  if (finding->intensity) {
    for (size_t k = 0; k < finding->markers.size(); ++k) {
      finding->markers[k].spec.name = "dot" + std::to_string(k);
    }
  }
  finding->measure = marker_finding::BodyMeasure(finding->markers);
}

void MarkerFinderOptions::Check() const {
  if (search_px && (search_px->width <= 0 || search_px->height <= 0)) {
    throw InputError("search region: width and height must be positive");
  }
  if (expected_count && (*expected_count < 1 || *expected_count > 64)) {
    throw InputError("marker count must be in 1..64, got " + std::to_string(*expected_count));
  }
  if (frame_index < 0 || frame_index > 1000000000) {
    throw InputError("frame " + std::to_string(frame_index) + ": must be in 0..1000000000");
  }
  if (min_saturation < 1 || min_saturation > 255) {
    throw InputError("min_saturation must be in 1..255, got " + std::to_string(min_saturation));
  }
  if (min_value < 0 || min_value > 255) {
    throw InputError("min_value must be in 0..255, got " + std::to_string(min_value));
  }
  if (!(min_area_px >= 1)) throw InputError("min_area_px must be at least 1");
  if (!(max_area_fraction > 0 && max_area_fraction <= 1)) {
    throw InputError("max_area_fraction must be in (0, 1]");
  }
  if (roi_side_px < 3) throw InputError("roi side must be at least 3 px");
  std::string error;
  if (!picker.Check(&error)) throw InputError("picker: " + error);
}

std::vector<size_t> OrderAlongBody(const std::vector<cv::Point2d>& points, cv::Size image_size,
                                   const std::optional<cv::Point2d>& base_near_px,
                                   bool* ambiguous) {
  const size_t n = points.size();
  std::vector<size_t> best(n);
  std::iota(best.begin(), best.end(), 0);
  if (ambiguous != nullptr) *ambiguous = false;
  if (n <= 2) {
    // Nothing to order but the direction.
  } else if (n <= marker_finding::kExactOrderMax) {
    std::vector<size_t> order = best;
    double best_length = std::numeric_limits<double>::infinity();
    double second_length = best_length;
    do {
      if (order.front() > order.back()) continue;  // Each path once, not also reversed.
      const double length = marker_finding::PathLength(points, order);
      if (length < best_length) {
        second_length = best_length;
        best_length = length;
        best = order;
      } else if (length < second_length) {
        second_length = length;
      }
    } while (std::next_permutation(order.begin(), order.end()));
    if (ambiguous != nullptr) {
      *ambiguous = second_length < (1 + marker_finding::kOrderAmbiguity) * best_length;
    }
  } else {
    double best_length = std::numeric_limits<double>::infinity();
    for (size_t start = 0; start < n; ++start) {
      std::vector<size_t> order{start};
      std::vector<bool> used(n, false);
      used[start] = true;
      while (order.size() < n) {
        size_t next = 0;
        double nearest = std::numeric_limits<double>::infinity();
        for (size_t j = 0; j < n; ++j) {
          const double d = cv::norm(points[j] - points[order.back()]);
          if (!used[j] && d < nearest) {
            nearest = d;
            next = j;
          }
        }
        used[next] = true;
        order.push_back(next);
      }
      const double length = marker_finding::PathLength(points, order);
      if (length < best_length) {
        best_length = length;
        best = order;
      }
    }
  }
  if (n >= 2) {
    const cv::Point2d& first = points[best.front()];
    const cv::Point2d& last = points[best.back()];
    const bool reverse = base_near_px
                             ? cv::norm(last - *base_near_px) < cv::norm(first - *base_near_px)
                             : marker_finding::BorderDistance(last, image_size) < marker_finding::BorderDistance(first, image_size);
    if (reverse) std::reverse(best.begin(), best.end());
  }
  return best;
}

MarkerFinding FindMarkers(const cv::Mat& input, const MarkerFinderOptions& options) {
  options.Check();
  if (input.empty() || input.depth() != CV_8U || (input.channels() != 1 && input.channels() != 3)) {
    throw InputError("init needs an 8-bit BGR or gray frame");
  }
  cv::Mat frame = input;
  if (input.channels() == 1) cv::cvtColor(input, frame, cv::COLOR_GRAY2BGR);
  if (marker_finding::IsGrayFrame(frame)) return marker_finding::FindMarkersAs(frame, options, true);
  MarkerFinding colour = marker_finding::FindMarkersAs(frame, options, false);
  // No coloured blob that could be a marker at all (not look-alikes refused, which stay
  // refused): white or black dots, on footage stored in colour (hardly any colour: one dot is
  // enough) or on a colourful bench (white domes on a dark actuator before a pegboard). There a
  // lone bright blob is more likely a lamp or a glint than a set of markers: two at least, which
  // the dots' own checks judge as usual (many alike, a pegboard's holes, are refused).
  if (colour.markers.empty() && colour.problem.rfind("no markers", 0) == 0) {
    const bool nearly_gray = marker_finding::IsNearlyGrayFrame(frame);
    MarkerFinding dots = marker_finding::FindMarkersAs(frame, options, true);
    if (dots.markers.size() >= (nearly_gray ? 1u : 2u)) {
      dots.notes.push_back(nearly_gray ? "no coloured marker in a frame with hardly any colour: "
                                         "white or black dots, by gray level"
                                       : "no coloured marker: white or black dots, by gray level");
      return dots;
    }
  }
  return colour;
}

cv::Mat DrawMarkerFinding(const cv::Mat& input, const MarkerFinding& finding) {
  cv::Mat image;
  if (input.channels() == 1) {
    cv::cvtColor(input, image, cv::COLOR_GRAY2BGR);
  } else {
    image = input.clone();
  }
  const cv::Scalar ok_colour(60, 230, 60), reject_colour(40, 40, 255), roi_colour(0, 220, 255);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  for (const RejectedCandidate& r : finding.rejected) {
    const cv::Point p(cvRound(r.position_px.x), cvRound(r.position_px.y));
    const int s = std::max(3, cvRound(r.radius_px * 0.7));
    cv::line(image, p + cv::Point(-s, -s), p + cv::Point(s, s), reject_colour, 1, cv::LINE_AA);
    cv::line(image, p + cv::Point(-s, s), p + cv::Point(s, -s), reject_colour, 1, cv::LINE_AA);
    cv::putText(image, r.why, p + cv::Point(s + 2, 4), font, 0.33, reject_colour, 1, cv::LINE_AA);
  }
  for (size_t i = 1; i < finding.markers.size(); ++i) {
    cv::line(image, finding.markers[i - 1].position_px, finding.markers[i].position_px, ok_colour,
             1, cv::LINE_AA);
  }
  for (size_t i = 0; i < finding.markers.size(); ++i) {
    const FoundMarker& m = finding.markers[i];
    const ColourParams& colour = m.spec.params.get<ColourParams>();
    if (colour.roi) cv::rectangle(image, *colour.roi, roi_colour, 1);
    const cv::Point p(cvRound(m.position_px.x), cvRound(m.position_px.y));
    cv::circle(image, p, cvRound(m.radius_px) + 3, ok_colour, 2, cv::LINE_AA);
    cv::putText(image, std::to_string(i + 1) + " " + m.spec.name,
                p + cv::Point(cvRound(m.radius_px) + 6, -4), font, 0.45, ok_colour, 1,
                cv::LINE_AA);
  }
  std::string headline = finding.ok() ? std::to_string(finding.markers.size()) +
                                            " markers, base to tip in order"
                                      : finding.problem;
  if (headline.size() > 110) headline = headline.substr(0, 107) + "...";
  cv::putText(image, headline, cv::Point(8, 18), font, 0.45, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(image, headline, cv::Point(8, 18), font, 0.45,
              finding.ok() ? ok_colour : reject_colour, 1, cv::LINE_AA);
  return image;
}

}  // namespace softsight
