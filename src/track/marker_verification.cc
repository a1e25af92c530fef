// Each candidate of `init`'s marker finder verified (marker_finder_parts.h, steps 2 and 3): its
// outline must be a marker's, its own ranges come from its pixels (the live window's click pick, or
// a gray dot's level), and a colour tracker built from them must find it again, alone.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "softsight/track/hsv_picker.h"
#include "track/marker_finder_parts.h"

namespace softsight::marker_finding {
namespace {

// The verifying tracker must find the candidate within this many radii (and 1 px) of where the
// search found it: the same blob, measured with the marker's own ranges.
constexpr double kVerifyRadii = 0.25;
// A marker's edge fades (80 % -> 20 %) within at most this many pixels, or this many radii for
// large markers (see EdgeWidthPx). A sharp rendered marker measures 0.75-1 px; a Gaussian blur
// adds 1.7 sigmas, so markers defocused up to sigma ~1 px (more for large ones) pass, while the
// stains of a textured bench (3.5-4 px measured on the renderer's bench) do not.
constexpr double kMaxEdgeWidthPx = 2.5;
constexpr double kMaxEdgeWidthRadii = 0.15;

// The pixels within `reach_px` of `centre` (a square), cut to the frame of `size`.
cv::Rect SquareAround(const cv::Point2d& centre, double reach_px, cv::Size size) {
  return cv::Rect(cvFloor(centre.x - reach_px), cvFloor(centre.y - reach_px),
                  cvCeil(2 * reach_px) + 2, cvCeil(2 * reach_px) + 2) &
         cv::Rect(0, 0, size.width, size.height);
}

// The pixels of `bgr` that a colour tracker with `colour` counts as its marker's (255), by the
// tracker's own classifier: hue ranges through red included.
void ColourMembership(const cv::Mat& bgr, const ColourParams& colour, cv::Mat& mask) {
  MarkerSpec spec;
  spec.name = "membership";
  spec.params = colour;
  CreateTracker(spec)->membership(bgr, mask);
}

std::string Point(const cv::Point2d& p) {
  char text[64];
  std::snprintf(text, sizeof(text), "(%.1f, %.1f)", p.x, p.y);
  return text;
}

double Median(std::vector<int> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// The gray range of a dot: from the level halfway between its core (the disc of 0.6 radii) and
// its surroundings (the ring 2..4 px outside it) to white (a bright dot) or black (a dark one).
std::optional<HsvRange> DotRange(const cv::Mat& gray, const cv::Point2d& centre, double radius) {
  std::vector<int> core, ring;
  const double core_r = std::max(1.0, 0.6 * radius);
  const double ring_in = radius + 2, ring_out = radius + 4;
  const int reach = static_cast<int>(std::ceil(ring_out));
  for (int y = cvRound(centre.y) - reach; y <= cvRound(centre.y) + reach; ++y) {
    if (y < 0 || y >= gray.rows) continue;
    for (int x = cvRound(centre.x) - reach; x <= cvRound(centre.x) + reach; ++x) {
      if (x < 0 || x >= gray.cols) continue;
      const double d = std::hypot(x - centre.x, y - centre.y);
      if (d <= core_r) core.push_back(gray.at<uchar>(y, x));
      if (d >= ring_in && d <= ring_out) ring.push_back(gray.at<uchar>(y, x));
    }
  }
  if (core.empty() || ring.empty()) return std::nullopt;
  const double c = Median(core), r = Median(ring);
  if (std::abs(c - r) < 20) return std::nullopt;  // Not a dot that stands out.
  const double middle = 0.5 * (c + r);
  if (c > r) return HsvRange{static_cast<int>(std::ceil(middle)), 255};
  return HsvRange{0, static_cast<int>(std::floor(middle))};
}

// How sharply a blob's colour gives way to its surroundings: along rays from its centre, the
// distance over which the colour goes from 80 % to 20 % of the way between its core (the disc of
// half its radius) and its surroundings (the ring 3..5 px outside it), in pixels. A printed or
// painted marker's edge takes 1-3 px (anti-aliasing, a little blur); a patch of stain or shading
// on a bench fades over many. The first quartile over the rays, not the median: a marker blurred
// by its motion fades along the motion only and stays sharp across it, while a stain fades all
// round. Absent when the core and the ring have the same colour.
std::optional<double> EdgeWidthPx(const cv::Mat& bgr, const cv::Point2d& centre, double radius) {
  constexpr int kRays = 16;
  auto sample = [&](double x, double y, cv::Vec3d* out) {
    if (x < 0 || y < 0 || x > bgr.cols - 1.001 || y > bgr.rows - 1.001) return false;
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    const double fx = x - x0, fy = y - y0;
    const cv::Vec3b& a = bgr.at<cv::Vec3b>(y0, x0);
    const cv::Vec3b& b = bgr.at<cv::Vec3b>(y0, x0 + 1);
    const cv::Vec3b& c = bgr.at<cv::Vec3b>(y0 + 1, x0);
    const cv::Vec3b& d = bgr.at<cv::Vec3b>(y0 + 1, x0 + 1);
    for (int k = 0; k < 3; ++k) {
      (*out)[k] = (1 - fy) * ((1 - fx) * a[k] + fx * b[k]) + fy * ((1 - fx) * c[k] + fx * d[k]);
    }
    return true;
  };
  const double inner = 0.5 * radius, ring_in = radius + 3, ring_out = radius + 5;
  std::vector<double> core_samples[3], ring_samples[3];  // Per channel (B, G, R).
  for (int k = 0; k < kRays; ++k) {
    const double a = 2 * CV_PI * k / kRays;
    const cv::Point2d dir(std::cos(a), std::sin(a));
    cv::Vec3d p;
    for (double d = 0; d <= inner; d += 0.5) {
      if (sample(centre.x + d * dir.x, centre.y + d * dir.y, &p)) {
        for (int ch = 0; ch < 3; ++ch) core_samples[ch].push_back(p[ch]);
      }
    }
    for (double d = ring_in; d <= ring_out; d += 0.5) {
      if (sample(centre.x + d * dir.x, centre.y + d * dir.y, &p)) {
        for (int ch = 0; ch < 3; ++ch) ring_samples[ch].push_back(p[ch]);
      }
    }
  }
  if (core_samples[0].empty() || ring_samples[0].empty()) return std::nullopt;
  // The core's median, not its mean: a glossy marker's highlight covers a good part of its core,
  // and the mean would put the marker's own colour part of the way to the ring's, as if its edge
  // began inside it. The ring's mean: a grainy bench's median follows its grain.
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  cv::Vec3d core, ring;
  for (int ch = 0; ch < 3; ++ch) {
    core[ch] = median(core_samples[ch]);
    ring[ch] = std::accumulate(ring_samples[ch].begin(), ring_samples[ch].end(), 0.0) /
              static_cast<double>(ring_samples[ch].size());
  }
  const cv::Vec3d span = core - ring;
  const double span2 = span.dot(span);
  if (span2 < 15.0 * 15.0) return std::nullopt;
  std::vector<double> widths;
  for (int k = 0; k < kRays; ++k) {
    const double a = 2 * CV_PI * k / kRays;
    const cv::Point2d dir(std::cos(a), std::sin(a));
    std::optional<double> d80, d20;
    cv::Vec3d p;
    for (double d = inner; d <= ring_out; d += 0.25) {
      if (!sample(centre.x + d * dir.x, centre.y + d * dir.y, &p)) break;
      const double m = (p - ring).dot(span) / span2;
      if (!d80 && m < 0.8) d80 = d;
      if (!d20 && m < 0.2) {
        d20 = d;
        break;
      }
    }
    if (d80 && d20) widths.push_back(*d20 - *d80);
    else widths.push_back(ring_out - inner);  // Never fades within reach: as wide as can be.
  }
  std::nth_element(widths.begin(), widths.begin() + widths.size() / 4, widths.end());
  return widths[widths.size() / 4];
}

// The CoreLooks of the disc of 0.6 radii around `centre`.
CoreLooks CoreLooksOf(const cv::Mat& bgr, const cv::Point2d& centre, double radius) {
  const double r = std::max(1.0, 0.6 * radius);
  const cv::Rect box = SquareAround(centre, r, bgr.size());
  if (box.empty()) return {};
  cv::Mat hsv;
  cv::cvtColor(bgr(box), hsv, cv::COLOR_BGR2HSV);
  std::vector<int> s, v;
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      if (std::hypot(box.x + x - centre.x, box.y + y - centre.y) <= r) {
        s.push_back(hsv.at<cv::Vec3b>(y, x)[1]);
        v.push_back(hsv.at<cv::Vec3b>(y, x)[2]);
      }
    }
  }
  return {Median(s), Median(v)};
}

// Blobs of `colour` other than `c` in the whole frame with 0.5-2x its area and at least the
// circularity its marker accepts: what the marker could be taken for once it is lost.
int ElongatedLookAlikes(const cv::Mat& frame, const ColourParams& colour, const Candidate& c) {
  ColourParams probe = colour;
  probe.roi.reset();
  int others = 0;
  for (const MarkerCandidate& o : Probe(frame, probe)) {
    const bool shaped = o.verdict == CandidateVerdict::kFits ||
                        o.verdict == CandidateVerdict::kChosen ||
                        (o.verdict == CandidateVerdict::kShape &&
                         o.circularity >= colour.min_circularity);
    if (shaped && o.area_px >= 0.5 * c.area_px && o.area_px <= 2 * c.area_px &&
        cv::norm(o.position_px - c.position_px) > RadiusOf(c.area_px)) {
      ++others;
    }
  }
  return others;
}

// The blob of `colour` at `centre` against its moment ellipse (the ellipse with its area's second
// moments): how fully it fills it (1 for an ellipse, 0.955 for a bar, less for ragged or hollow
// shapes) and the ellipse's minor semi-axis. Zeros when no blob of `colour` lies at `centre`.
// Looked at within `reach_px` of `centre`.
struct EllipseFit {
  double fill = 0;
  double minor_px = 0;
};
EllipseFit FitMomentEllipse(const cv::Mat& bgr, const ColourParams& colour,
                            const cv::Point2d& centre, double reach_px) {
  const cv::Rect box = SquareAround(centre, reach_px, bgr.size());
  if (box.empty()) return {};
  cv::Mat mask;
  ColourMembership(bgr(box), colour, mask);
  cv::Mat labels;
  cv::connectedComponents(mask, labels, 8, CV_32S);
  const cv::Point at(cvRound(centre.x) - box.x, cvRound(centre.y) - box.y);
  if (!cv::Rect(0, 0, labels.cols, labels.rows).contains(at)) return {};
  const int label = labels.at<int>(at);
  if (label == 0) return {};
  const cv::Moments m = cv::moments(labels == label, true);
  if (m.m00 < 1) return {};
  const double cxx = m.mu20 / m.m00, cyy = m.mu02 / m.m00, cxy = m.mu11 / m.m00;
  const double det = cxx * cyy - cxy * cxy;
  if (det <= 0) return {};
  const double smaller_variance =
      0.5 * (cxx + cyy) - std::sqrt(0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy);
  return {m.m00 / (4 * CV_PI * std::sqrt(det)), 2 * std::sqrt(std::max(0.0, smaller_variance))};
}

// A pale marker's picked range reaches down to the saturation of a tinted bench, and the blob
// it selects then merges with a patch of the bench of its hue whenever it passes one. Like a
// two-class threshold, the saturation bound is placed half way between the marker's core and the
// most saturated of its surroundings (the 99.5th percentile over the square of five radii, at
// least 32 px, each side of it, less the marker's own disc and 3 px around it; pixels outside the
// hue and value ranges count as grey); it is only ever raised, and never to the core's median.
void KeepSaturationAboveSurroundings(const cv::Mat& bgr, const cv::Point2d& centre, double radius,
                                     double core_saturation, ColourParams* colour) {
  const double ring_in = radius + 3, ring_out = std::max(5 * radius, 32.0);
  const cv::Rect box = SquareAround(centre, ring_out, bgr.size());
  if (box.empty()) return;
  // Within the hue and value ranges, whatever the saturation.
  ColourParams any_saturation = *colour;
  any_saturation.s = {0, 255};
  cv::Mat hsv, in_range;
  ColourMembership(bgr(box), any_saturation, in_range);
  cv::cvtColor(bgr(box), hsv, cv::COLOR_BGR2HSV);
  std::vector<int> ring;
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      const double d = std::hypot(box.x + x - centre.x, box.y + y - centre.y);
      if (d < ring_in) continue;
      ring.push_back(in_range.at<uchar>(y, x) ? hsv.at<cv::Vec3b>(y, x)[1] : 0);
    }
  }
  if (ring.size() < 20) return;
  const size_t k = ring.size() * 995 / 1000;
  std::nth_element(ring.begin(), ring.begin() + k, ring.end());
  const int bench = ring[k];
  if (bench < colour->s.lo) return;
  const int raised = static_cast<int>(std::ceil(0.5 * (bench + core_saturation)));
  if (raised > colour->s.lo && raised < core_saturation) colour->s.lo = raised;
}

// The side of candidate `i`'s roi: the click box, at least four radii, excluding every other
// candidate's centre.
int RoiSide(const MarkerFinderOptions& options, const std::vector<Candidate>& fitting, size_t i,
            double radius) {
  const Candidate& c = fitting[i];
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t j = 0; j < fitting.size(); ++j) {
    if (j != i) nearest = std::min(nearest, cv::norm(fitting[j].position_px - c.position_px));
  }
  int side = std::max(options.roi_side_px, static_cast<int>(std::ceil(4 * radius)));
  if (std::isfinite(nearest)) side = std::min(side, static_cast<int>(std::floor(1.3 * nearest)));
  return std::max(side, static_cast<int>(std::ceil(2 * radius)) + 3);
}

// Why the candidate's outline is not a marker's (cut by the frame border; an edge that fades
// slowly, a stain or a shadow; no edge at all), or nullopt when it is.
std::optional<std::string> OutlineProblem(const cv::Mat& frame, const Candidate& c, double radius) {
  if (BorderDistance(c.position_px, frame.size()) < radius + 2) return "cut by the frame border";
  const std::optional<double> edge = EdgeWidthPx(frame, c.position_px, radius);
  if (!edge) return "no edge (same colour around it)";
  if (*edge > std::max(kMaxEdgeWidthPx, kMaxEdgeWidthRadii * radius)) {
    char why[96];
    std::snprintf(why, sizeof(why), "soft edge (fades over %.1f px: a stain or shadow)", *edge);
    return why;
  }
  return std::nullopt;
}

// The candidate's own ranges, from its pixels: a gray dot's level halfway to its surroundings
// (with a roi of `side`), or the colour the live window's click would pick at its centre (an
// elongated blob only when it fills its moment ellipse as a sticker or a bar does, and its marker
// then accepts about its circularity). Sets *hue (colour markers); nullopt with *why.
std::optional<MarkerSpec> OwnRanges(const cv::Mat& frame, const MarkerFinderOptions& options,
                                    bool intensity, const Candidate& c, double radius, int side,
                                    int* hue, std::string* why) {
  MarkerSpec spec;
  ColourParams& colour = spec.params.emplace<ColourParams>();
  if (intensity) {
    cv::Mat gray;
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
    const auto range = DotRange(gray, c.position_px, radius);
    if (!range) {
      *why = "contrast (no clear level between the dot and its surroundings)";
      return std::nullopt;
    }
    colour.gray = *range;
    colour.roi = cv::Rect(cvRound(c.position_px.x) - side / 2,
                          cvRound(c.position_px.y) - side / 2, side, side) &
                 cv::Rect(0, 0, frame.cols, frame.rows);
    return spec;
  }
  HsvPickOptions picker = options.picker;
  picker.radius_px = std::clamp(static_cast<int>(std::floor(0.6 * radius)), 1,
                                options.picker.radius_px);
  std::string pick_problem;
  const auto pick = PickMarkerColourAt(frame, c.position_px, picker, side, &pick_problem);
  if (!pick) {
    *why = "colour pick: " + pick_problem;
    return std::nullopt;
  }
  ApplyColourPick(*pick, &colour);
  *hue = pick->ranges.h.hue_centre();
  if (c.elongated) {
    const EllipseFit fit = FitMomentEllipse(frame, colour, c.position_px, 4 * radius + 4);
    if (fit.fill < kMinEllipseFill || fit.minor_px < kMinStickerHalfWidthPx) {
      char text[112];
      std::snprintf(text, sizeof(text),
                    "shape (not compact, nor an ellipse or a bar: fills %.2f of its ellipse, "
                    "%.1f px wide)", fit.fill, 2 * fit.minor_px);
      *why = text;
      return std::nullopt;
    }
    colour.min_circularity = std::floor(100 * kStickerCircularity * c.circularity) / 100;
  }
  return spec;
}

// How far from where the search found it the verifying tracker may find a candidate: the same
// blob, measured with the marker's own ranges.
double VerifyTolerance(double radius) { return std::max(1.0, kVerifyRadii * radius); }

// Whether a colour tracker built from `spec` (with its roi, or on the whole frame) finds the blob
// at `at` on `frame`, within VerifyTolerance(radius); what it reported in *observation.
bool FoundAgain(const cv::Mat& frame, const MarkerSpec& spec, bool with_roi, const cv::Point2d& at,
                double radius, Observation* observation) {
  MarkerSpec probe_spec = spec;
  probe_spec.name = "verify";
  if (!with_roi) probe_spec.params.get<ColourParams>().roi.reset();
  const auto tracker = CreateTracker(probe_spec);
  Frame f;
  f.image = frame;
  tracker->start(f);
  *observation = tracker->update(frame);
  return observation->found() && cv::norm(*observation->position_px - at) <= VerifyTolerance(radius);
}

// How a verified candidate is followed.
struct Confirmation {
  Observation seen;        // What the verifying tracker reported.
  bool twin = false;       // See Verified::twin.
  bool needs_roi = false;  // See FoundMarker::needs_roi.
};

// "Found means verified": a tracker built from the candidate's own ranges (`spec`) must find it on
// the frame, alone; identical dots (and look-alikes outside the search region) are told apart by
// a roi each, elongated stickers are verified in their roi only, and a blob of a colour several
// blobs share is a twin until the whole set is seen. Otherwise nullopt, with the reason in
// finding->rejected (and ambiguous colours in *ambiguous).
std::optional<Confirmation> Confirm(const cv::Mat& frame, const MarkerFinderOptions& options,
                                    const Candidate& c, const MarkerSpec& spec, int hue,
                                    double radius, MarkerFinding* finding,
                                    std::vector<LookAlike>* ambiguous) {
  auto reject = [&](const std::string& why) {
    finding->rejected.push_back({c.position_px, radius, why});
  };
  auto verify = [&](bool with_roi, Observation* observation) {
    return FoundAgain(frame, spec, with_roi, c.position_px, radius, observation);
  };
  Observation alone;
  bool twin = false, needs_roi = c.elongated;
  bool ok = verify(needs_roi, &alone);
  if (!ok && c.elongated) {
    reject(std::string("not verified in its roi (") + MarkerStatusName(alone.status()) + ")");
    return std::nullopt;
  }
  if (ok && c.elongated) {
    // Verified in its roi only, so it must be alone in the frame in another way: no other
    // blob of its colour, of about its area, as elongated or rounder.
    const int others = ElongatedLookAlikes(frame, spec.params.get<ColourParams>(), c);
    if (others > 0) {
      reject("ambiguous: " + std::to_string(others + 1) + " look-alikes of its colour and shape");
      return std::nullopt;
    }
  }
  if (!ok && (finding->intensity || options.search_px) &&
      (alone.status() == MarkerStatus::kAmbiguous || alone.found())) {
    // Identical dots, or look-alikes outside the search region: told apart by a roi each.
    Observation inside;
    ok = verify(true, &inside);
    if (!ok) {
      reject(std::string("not verified in its roi (") + MarkerStatusName(inside.status()) + ")");
      return std::nullopt;
    }
    alone = inside;
    needs_roi = true;
  } else if (!ok && alone.status() == MarkerStatus::kAmbiguous) {
    // Several blobs of its colour: identical markers (a dot on each of two carts, a row of
    // pucks) when they are all alike, which is decided once all are seen; a roi tells them
    // apart. Found in its roi, it is a twin until then.
    Observation inside;
    if (verify(true, &inside)) {
      ok = twin = needs_roi = true;
      alone = inside;
    }
  }
  if (!ok) {
    if (alone.status() == MarkerStatus::kAmbiguous) {
      ambiguous->push_back({finding->intensity ? "dot" : HueName(hue), hue, radius,
                            finding->rejected.size()});
      reject("ambiguous: " + std::to_string(std::max(2, alone.candidates)) +
             " look-alikes of its colour");
    } else if (alone.found()) {
      reject("its own ranges find another blob first, at " + Point(*alone.position_px));
    } else {
      reject(std::string("not found again with its own ranges (") +
             MarkerStatusName(alone.status()) + ")");
    }
    return std::nullopt;
  }
  return Confirmation{alone, twin, needs_roi};
}

}  // namespace

std::optional<Verified> VerifyCandidate(const cv::Mat& frame, const MarkerFinderOptions& options,
                                        const std::vector<Candidate>& fitting, size_t i,
                                        MarkerFinding* finding, std::vector<LookAlike>* ambiguous) {
  const Candidate& c = fitting[i];
  const double radius = RadiusOf(c.area_px);
  auto reject = [&](const std::string& why) {
    finding->rejected.push_back({c.position_px, radius, why});
  };
  const int side = RoiSide(options, fitting, i, radius);
  if (const std::optional<std::string> problem = OutlineProblem(frame, c, radius)) {
    reject(*problem);
    return std::nullopt;
  }
  int hue = 0;
  std::string why;
  std::optional<MarkerSpec> spec =
      OwnRanges(frame, options, finding->intensity, c, radius, side, &hue, &why);
  if (!spec) {
    reject(why);
    return std::nullopt;
  }
  const std::optional<Confirmation> confirmed =
      Confirm(frame, options, c, *spec, hue, radius, finding, ambiguous);
  if (!confirmed) return std::nullopt;
  CoreLooks looks;
  if (!finding->intensity) {
    looks = CoreLooksOf(frame, c.position_px, radius);
    // Tightened only once verified with the picked ranges, and kept only when the marker is
    // still found with them: it steadies the tracking of a marker, never makes a blob one.
    const MarkerSpec picked = *spec;
    ColourParams& colour = spec->params.get<ColourParams>();
    const int picked_lo = colour.s.lo;
    KeepSaturationAboveSurroundings(frame, c.position_px, radius, looks.saturation, &colour);
    Observation tightened;
    if (colour.s.lo != picked_lo &&
        !FoundAgain(frame, *spec, confirmed->needs_roi, c.position_px, radius, &tightened)) {
      spec = picked;
    }
  }
  Verified v;
  v.marker.spec = *spec;
  v.marker.position_px = *confirmed->seen.position_px;
  v.marker.radius_px = radius;
  v.marker.needs_roi = confirmed->needs_roi;
  v.hue = hue;
  v.looks = looks;
  v.twin = confirmed->twin;
  v.elongated = c.elongated;
  return v;
}

}  // namespace softsight::marker_finding
