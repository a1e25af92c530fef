// Finding, verifying and ordering the markers of one frame: see marker_finder.h.
#include "softsight/calib/marker_finder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {
namespace {

// Hue bands of the candidate search: centres every kHueStep, reaching kHueReach either side, so
// any marker whose hues spread over less than 2 * kHueReach - kHueStep lies wholly in one band.
constexpr int kHueStep = 10;
constexpr int kHueReach = 12;
// Gray-level bands of the candidate search on gray frames: bright dots at or above, dark dots at
// or below these levels.
constexpr int kBrightLevels[] = {230, 200, 170, 140, 110};
constexpr int kDarkLevels[] = {25, 50, 80};
// Candidates from different bands closer than this (in marker radii, at least 2 px) are one blob.
constexpr double kSameBlobRadii = 0.5;
// Rejected blobs smaller than this are not drawn or listed (texture specks are many).
constexpr double kListedRejectAreaPx = 20.0;
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
// The verifying tracker must find the candidate within this many radii (and 1 px) of where the
// search found it: the same blob, measured with the marker's own ranges.
constexpr double kVerifyRadii = 0.25;
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
// A marker's edge fades (80 % -> 20 %) within at most this many pixels, or this many radii for
// large markers (see EdgeWidthPx). A sharp rendered marker measures 0.75-1 px; a Gaussian blur
// adds 1.7 sigmas, so markers defocused up to sigma ~1 px (more for large ones) pass, while the
// stains of a textured bench (3.5-4 px measured on the renderer's bench) do not.
constexpr double kMaxEdgeWidthPx = 2.5;
constexpr double kMaxEdgeWidthRadii = 0.15;
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
// Paths through at most this many markers are searched exhaustively.
constexpr size_t kExactOrderMax = 8;

struct Candidate {
  cv::Point2d position_px;
  double area_px = 0;
  double circularity = 1;
  bool elongated = false;  // Refused by the whole-frame search for its shape alone.
  std::optional<HsvRange> band_gray;  // Gray-level band that found it (gray frames).
};

double RadiusOf(double area_px) { return std::sqrt(std::max(area_px, 0.0) / CV_PI); }

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

// One probe of the colour tracker's whole-frame first acquisition with `colour`: what it weighed.
std::vector<MarkerCandidate> Probe(const cv::Mat& frame, const ColourParams& colour) {
  MarkerSpec spec;
  spec.name = "probe";
  spec.params = colour;
  const auto tracker = CreateTracker(spec);
  Frame f;
  f.image = frame;
  tracker->start(f);
  tracker->update(frame);
  return tracker->candidates();
}

const char* RejectReason(CandidateVerdict verdict) {
  switch (verdict) {
    case CandidateVerdict::kSize:
      return "size";
    case CandidateVerdict::kShape:
      return "shape (not compact)";
    case CandidateVerdict::kColour:
      return "colour";
    case CandidateVerdict::kContrast:
      return "contrast (background)";
    default:
      return CandidateVerdictName(verdict);
  }
}

// Adds `c` to `list` unless a blob there already is the same one; keeps the larger.
void Merge(std::vector<Candidate>* list, const Candidate& c) {
  for (Candidate& other : *list) {
    const double near = std::max(2.0, kSameBlobRadii * RadiusOf(std::max(c.area_px, other.area_px)));
    if (cv::norm(other.position_px - c.position_px) < near) {
      if (c.area_px > other.area_px) other = c;
      return;
    }
  }
  list->push_back(c);
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

// Median HSV saturation and value of the disc of 0.6 radii around `centre`.
struct CoreLooks {
  double saturation = 0;
  double value = 0;
};
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


double PathLength(const std::vector<cv::Point2d>& points, const std::vector<size_t>& order) {
  double length = 0;
  for (size_t i = 1; i < order.size(); ++i) length += cv::norm(points[order[i]] - points[order[i - 1]]);
  return length;
}

double BorderDistance(const cv::Point2d& p, cv::Size size) {
  return std::min({p.x, p.y, size.width - 1 - p.x, size.height - 1 - p.y});
}

// The triple (and, beyond three, the chain) of markers in body order, as SceneMeasureOptions.
MeasureOptions BodyMeasure(const std::vector<FoundMarker>& markers) {
  MeasureOptions measure;
  const size_t n = markers.size();
  if (n < 3) return measure;
  measure.base = markers.front().spec.name;
  measure.middle = markers[n / 2].spec.name;
  measure.tip = markers.back().spec.name;
  if (n > 3) {
    for (const FoundMarker& m : markers) measure.chain.push_back(m.spec.name);
  }
  return measure;
}

}  // namespace

void ReverseBodyOrder(MarkerFinding* finding) {
  std::reverse(finding->markers.begin(), finding->markers.end());
  if (finding->intensity) {
    for (size_t k = 0; k < finding->markers.size(); ++k) {
      finding->markers[k].spec.name = "dot" + std::to_string(k);
    }
  }
  finding->measure = BodyMeasure(finding->markers);
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
  } else if (n <= kExactOrderMax) {
    std::vector<size_t> order = best;
    double best_length = std::numeric_limits<double>::infinity();
    double second_length = best_length;
    do {
      if (order.front() > order.back()) continue;  // Each path once, not also reversed.
      const double length = PathLength(points, order);
      if (length < best_length) {
        second_length = best_length;
        best_length = length;
        best = order;
      } else if (length < second_length) {
        second_length = length;
      }
    } while (std::next_permutation(order.begin(), order.end()));
    if (ambiguous != nullptr) {
      *ambiguous = second_length < (1 + kOrderAmbiguity) * best_length;
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
      const double length = PathLength(points, order);
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
                             : BorderDistance(last, image_size) < BorderDistance(first, image_size);
    if (reverse) std::reverse(best.begin(), best.end());
  }
  return best;
}

namespace {

// FindMarkers on a BGR frame, looking for saturated blobs or (`intensity`) white or black dots.
MarkerFinding FindMarkersAs(const cv::Mat& frame, const MarkerFinderOptions& options,
                            bool intensity);

}  // namespace

MarkerFinding FindMarkers(const cv::Mat& input, const MarkerFinderOptions& options) {
  options.Check();
  if (input.empty() || input.depth() != CV_8U || (input.channels() != 1 && input.channels() != 3)) {
    throw InputError("init needs an 8-bit BGR or gray frame");
  }
  cv::Mat frame = input;
  if (input.channels() == 1) cv::cvtColor(input, frame, cv::COLOR_GRAY2BGR);
  if (IsGrayFrame(frame)) return FindMarkersAs(frame, options, true);
  MarkerFinding colour = FindMarkersAs(frame, options, false);
  // No coloured blob that could be a marker at all (not look-alikes refused, which stay
  // refused): white or black dots, on footage stored in colour (hardly any colour: one dot is
  // enough) or on a colourful bench (white domes on a dark actuator before a pegboard). There a
  // lone bright blob is more likely a lamp or a glint than a set of markers: two at least, which
  // the dots' own checks judge as usual (many alike, a pegboard's holes, are refused).
  if (colour.markers.empty() && colour.problem.rfind("no markers", 0) == 0) {
    const bool nearly_gray = IsNearlyGrayFrame(frame);
    MarkerFinding dots = FindMarkersAs(frame, options, true);
    if (dots.markers.size() >= (nearly_gray ? 1u : 2u)) {
      dots.notes.push_back(nearly_gray ? "no coloured marker in a frame with hardly any colour: "
                                         "white or black dots, by gray level"
                                       : "no coloured marker: white or black dots, by gray level");
      return dots;
    }
  }
  return colour;
}

namespace {

// ---- 1. Candidates: the colour tracker's own verdicts, band by band -----------------------------
// Blobs that fitted a band (or, for colour, were refused for their shape alone: elongated), in
// `search`; the larger blobs every band refused go to finding->rejected with the reason.
std::vector<Candidate> FindCandidates(const cv::Mat& frame, const MarkerFinderOptions& options,
                                      const cv::Rect& search, MarkerFinding* finding_out) {
  MarkerFinding& finding = *finding_out;
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  const cv::Rect2d search_area(search.x - 0.5, search.y - 0.5, search.width, search.height);
  ColourParams probe;
  probe.min_area_px = options.min_area_px;
  probe.max_area_px = std::max(options.min_area_px + 1,
                               options.max_area_fraction * frame_rect.area());
  std::vector<ColourParams> bands;
  if (finding.intensity) {
    for (int level : kBrightLevels) {
      probe.gray = HsvRange{level, 255};
      bands.push_back(probe);
    }
    for (int level : kDarkLevels) {
      probe.gray = HsvRange{0, level};
      bands.push_back(probe);
    }
  } else {
    probe.s = {options.min_saturation, 255};
    probe.v = {options.min_value, 255};
    for (int centre = 0; centre < 180; centre += kHueStep) {
      probe.h = HsvRange::HueAround(centre, kHueReach);
      bands.push_back(probe);
    }
  }
  std::vector<Candidate> fitting;
  std::vector<std::pair<Candidate, std::string>> rejects;
  for (const ColourParams& band : bands) {
    for (const MarkerCandidate& c : Probe(frame, band)) {
      if (!search_area.contains(c.position_px)) continue;
      Candidate candidate{c.position_px, c.area_px, c.circularity, false, band.gray};
      if (c.verdict == CandidateVerdict::kFits || c.verdict == CandidateVerdict::kChosen) {
        Merge(&fitting, candidate);
      } else if (!finding.intensity && c.verdict == CandidateVerdict::kShape &&
                 c.circularity >= kMinCandidateCircularity && c.area_px >= options.min_area_px) {
        candidate.elongated = true;
        Merge(&fitting, candidate);
      } else if (c.area_px >= kListedRejectAreaPx) {
        rejects.emplace_back(candidate, RejectReason(c.verdict));
      }
    }
  }
  // A blob that fitted in one band is not also a reject from another (its partial hue there).
  std::vector<Candidate> listed;
  for (const auto& [candidate, why] : rejects) {
    bool known = false;
    for (const Candidate& f : fitting) {
      if (cv::norm(f.position_px - candidate.position_px) < std::max(2.0, RadiusOf(f.area_px))) {
        known = true;
      }
    }
    const size_t before = listed.size();
    if (!known) Merge(&listed, candidate);
    if (listed.size() > before) {
      finding.rejected.push_back({candidate.position_px, RadiusOf(candidate.area_px), why});
    }
  }
  return fitting;
}

// ---- 2 + 3. A candidate's own ranges, verified by a tracker built from them ------------------------
struct Verified {
  FoundMarker marker;
  int hue = 0;
  CoreLooks looks;     // Medians over its core (colour markers).
  bool twin = false;   // One of several alike blobs of its colour, told apart by its roi.
  bool elongated = false;
};
struct LookAlike {
  std::string colour;
  int hue = 0;
  double radius_px = 0;
  size_t rejected_index = 0;  // Its entry in finding.rejected.
};

// Candidate `i` of `fitting` as a marker, or nullopt with its reason in finding->rejected (and,
// when look-alikes of its colour made it ambiguous, in *ambiguous).
std::optional<Verified> VerifyCandidate(const cv::Mat& frame, const MarkerFinderOptions& options,
                                        const std::vector<Candidate>& fitting, size_t i,
                                        MarkerFinding* finding_out,
                                        std::vector<LookAlike>* ambiguous_out) {
  MarkerFinding& finding = *finding_out;
  std::vector<LookAlike>& ambiguous = *ambiguous_out;
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  const Candidate& c = fitting[i];
  const double radius = RadiusOf(c.area_px);
  auto reject = [&](const std::string& why) {
    finding.rejected.push_back({c.position_px, radius, why});
  };
  // The roi: the click box, at least four radii, excluding every other candidate's centre.
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t j = 0; j < fitting.size(); ++j) {
    if (j != i) nearest = std::min(nearest, cv::norm(fitting[j].position_px - c.position_px));
  }
  int side = std::max(options.roi_side_px, static_cast<int>(std::ceil(4 * radius)));
  if (std::isfinite(nearest)) side = std::min(side, static_cast<int>(std::floor(1.3 * nearest)));
  side = std::max(side, static_cast<int>(std::ceil(2 * radius)) + 3);

  if (BorderDistance(c.position_px, frame.size()) < radius + 2) {
    reject("cut by the frame border");
    return std::nullopt;
  }
  const std::optional<double> edge = EdgeWidthPx(frame, c.position_px, radius);
  if (!edge || *edge > std::max(kMaxEdgeWidthPx, kMaxEdgeWidthRadii * radius)) {
    char why[96];
    std::snprintf(why, sizeof(why), "soft edge (fades over %.1f px: a stain or shadow)",
                  edge.value_or(0.0));
    reject(edge ? why : "no edge (same colour around it)");
    return std::nullopt;
  }
  MarkerSpec spec;
  ColourParams& colour = spec.params.emplace<ColourParams>();
  int hue = 0;
  if (finding.intensity) {
    cv::Mat gray;
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
    const auto range = DotRange(gray, c.position_px, radius);
    if (!range) {
      reject("contrast (no clear level between the dot and its surroundings)");
      return std::nullopt;
    }
    colour.gray = *range;
    colour.roi = cv::Rect(cvRound(c.position_px.x) - side / 2,
                          cvRound(c.position_px.y) - side / 2, side, side) & frame_rect;
  } else {
    HsvPickOptions picker = options.picker;
    picker.radius_px = std::clamp(static_cast<int>(std::floor(0.6 * radius)), 1,
                                  options.picker.radius_px);
    std::string why;
    const auto pick = PickMarkerColourAt(frame, c.position_px, picker, side, &why);
    if (!pick) {
      reject("colour pick: " + why);
      return std::nullopt;
    }
    ApplyColourPick(*pick, &colour);
    hue = pick->ranges.h.hue_centre();
    if (c.elongated) {
      const EllipseFit fit = FitMomentEllipse(frame, colour, c.position_px, 4 * radius + 4);
      if (fit.fill < kMinEllipseFill || fit.minor_px < kMinStickerHalfWidthPx) {
        char why[112];
        std::snprintf(why, sizeof(why),
                      "shape (not compact, nor an ellipse or a bar: fills %.2f of its ellipse, "
                      "%.1f px wide)", fit.fill, 2 * fit.minor_px);
        reject(why);
        return std::nullopt;
      }
      colour.min_circularity = std::floor(100 * kStickerCircularity * c.circularity) / 100;
    }
  }
  const double tolerance = std::max(1.0, kVerifyRadii * radius);
  auto verify = [&](bool with_roi, Observation* observation) {
    MarkerSpec probe_spec = spec;
    probe_spec.name = "verify";
    if (!with_roi) probe_spec.params.get<ColourParams>().roi.reset();
    const auto tracker = CreateTracker(probe_spec);
    Frame f;
    f.image = frame;
    tracker->start(f);
    *observation = tracker->update(frame);
    return observation->found() && cv::norm(*observation->position_px - c.position_px) <= tolerance;
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
    const int others = ElongatedLookAlikes(frame, colour, c);
    if (others > 0) {
      reject("ambiguous: " + std::to_string(others + 1) + " look-alikes of its colour and shape");
      return std::nullopt;
    }
  }
  if (!ok && (finding.intensity || options.search_px) &&
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
      ambiguous.push_back({finding.intensity ? "dot" : HueName(hue), hue, radius,
                           finding.rejected.size()});
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
  CoreLooks looks;
  if (!finding.intensity) {
    looks = CoreLooksOf(frame, c.position_px, radius);
    // Tightened only once verified with the picked ranges, and kept only when the marker is
    // still found with them: it steadies the tracking of a marker, never makes a blob one.
    const MarkerSpec picked = spec;
    const int picked_lo = colour.s.lo;
    KeepSaturationAboveSurroundings(frame, c.position_px, radius, looks.saturation, &colour);
    Observation tightened;
    if (colour.s.lo != picked_lo && !verify(needs_roi, &tightened)) spec = picked;
  }
  Verified v;
  v.marker.spec = spec;
  v.marker.position_px = *alone.position_px;
  v.marker.radius_px = radius;
  v.marker.needs_roi = needs_roi;
  v.hue = hue;
  v.looks = looks;
  v.twin = twin;
  v.elongated = c.elongated;
  return v;
}

MarkerFinding FindMarkersAs(const cv::Mat& frame, const MarkerFinderOptions& options,
                            bool intensity) {
  MarkerFinding finding;
  finding.intensity = intensity;
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  const cv::Rect search = options.search_px ? (*options.search_px & frame_rect) : frame_rect;
  if (search.empty()) throw InputError("the search region lies outside the frame");
  const cv::Rect2d search_area(search.x - 0.5, search.y - 0.5, search.width, search.height);

  std::vector<Candidate> fitting = FindCandidates(frame, options, search, &finding);

  // ---- 2 + 3. Each candidate's own ranges, verified by a tracker built from them ---------------------
  std::vector<Verified> verified;
  std::vector<LookAlike> ambiguous;
  for (size_t i = 0; i < fitting.size(); ++i) {
    if (std::optional<Verified> v = VerifyCandidate(frame, options, fitting, i, &finding, &ambiguous)) {
      verified.push_back(std::move(*v));
    }
  }
  // The markers of one body are of one kind: beside round markers, an elongated blob is a patch
  // of the scene, not a sticker of theirs.
  if (std::any_of(verified.begin(), verified.end(), [](const Verified& v) { return !v.elongated; })) {
    for (const Verified& v : verified) {
      if (v.elongated) {
        finding.rejected.push_back({v.marker.position_px, v.marker.radius_px,
                                    "elongated, unlike the round markers"});
      }
    }
    verified.erase(std::remove_if(verified.begin(), verified.end(),
                                  [](const Verified& v) { return v.elongated; }),
                   verified.end());
  }
  // Twins of one colour are markers only when they are alike in everything a tracker can see
  // (size, saturation, brightness) and no look-alike of theirs stayed unresolved: then each is
  // followed in its own roi. Otherwise (a larger, a darker, a half-sized patch of a marker's
  // colour) init cannot tell which of them is the marker and will not guess.
  // A refused group's twins become look-alikes of their colour, which may refuse another group
  // near that colour: refused groups are taken out until every group left is alike.
  const auto hues_apart = [](int a, int b) { return std::min(std::abs(a - b), 180 - std::abs(a - b)); };
  const auto twin_group = [&](size_t i) {
    std::vector<size_t> group;
    for (size_t j = 0; j < verified.size(); ++j) {
      if (verified[j].twin && hues_apart(verified[j].hue, verified[i].hue) <= kTwinHueApart) {
        group.push_back(j);
      }
    }
    return group;
  };
  const auto group_alike = [&](const std::vector<size_t>& group) {
    double r_lo = 1e9, r_hi = 0, s_lo = 1e9, s_hi = 0, v_lo = 1e9, v_hi = 0;
    for (size_t j : group) {
      const Verified& t = verified[j];
      r_lo = std::min(r_lo, t.marker.radius_px), r_hi = std::max(r_hi, t.marker.radius_px);
      s_lo = std::min(s_lo, t.looks.saturation), s_hi = std::max(s_hi, t.looks.saturation);
      v_lo = std::min(v_lo, t.looks.value), v_hi = std::max(v_hi, t.looks.value);
    }
    const int hue = verified[group.front()].hue;
    const bool unresolved = std::any_of(ambiguous.begin(), ambiguous.end(), [&](const LookAlike& a) {
      return hues_apart(a.hue, hue) <= kHueReach;
    });
    return group.size() >= 2 && !unresolved && r_hi <= kTwinSizeRatio * r_lo &&
           s_lo >= kTwinLooksRatio * s_hi && v_lo >= kTwinLooksRatio * v_hi;
  };
  for (bool refused = true; refused;) {
    refused = false;
    for (size_t i = 0; i < verified.size() && !refused; ++i) {
      if (!verified[i].twin) continue;
      const std::vector<size_t> group = twin_group(i);
      if (group_alike(group)) continue;
      for (size_t j : group) {
        const Verified& t = verified[j];
        ambiguous.push_back({HueName(t.hue), t.hue, t.marker.radius_px, finding.rejected.size()});
        finding.rejected.push_back({t.marker.position_px, t.marker.radius_px,
                                    "ambiguous: look-alikes of its colour that differ from it"});
      }
      for (size_t k = group.size(); k-- > 0;) verified.erase(verified.begin() + group[k]);
      refused = true;
    }
  }
  for (size_t i = 0; i < verified.size(); ++i) {
    if (!verified[i].twin) continue;
    const std::vector<size_t> group = twin_group(i);
    for (size_t j : group) verified[j].twin = false;  // Settled: markers, a roi each.
    finding.notes.push_back(std::to_string(group.size()) + " alike " +
                            HueName(verified[i].hue) +
                            " blobs are taken as identical markers, each told apart by its roi "
                            "(restrict the search with --roi X,Y,W,H if some are not markers)");
  }
  // Look-alikes that could be markers of this body make the finding unusable: init will not
  // guess between them. Once markers are verified, the body's markers have about their size, so
  // a pair of look-alikes of another size (a patch of the bench, twice as large) is only a reject.
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
      finding.rejected[a.rejected_index].why += ", unlike the markers' size";
    } else if (std::find(look_alikes.begin(), look_alikes.end(), a.colour) == look_alikes.end()) {
      look_alikes.push_back(a.colour);
    }
  }
  // Only blobs of about a marker's size are worth showing: texture specks are many.
  if (!verified.empty()) {
    double smallest = std::numeric_limits<double>::infinity();
    for (const Verified& v : verified) smallest = std::min(smallest, v.marker.radius_px);
    finding.rejected.erase(std::remove_if(finding.rejected.begin(), finding.rejected.end(),
                                          [&](const RejectedCandidate& r) {
                                            return r.radius_px < 0.5 * smallest;
                                          }),
                           finding.rejected.end());
  }
  std::sort(finding.rejected.begin(), finding.rejected.end(),
            [](const RejectedCandidate& a, const RejectedCandidate& b) {
              return a.radius_px > b.radius_px;
            });
  if (finding.rejected.size() > kMaxListedRejects) finding.rejected.resize(kMaxListedRejects);

  // Markers of one body are made alike: with most of them agreeing, a blob of another size (a
  // patch of the bench with a clean edge), then a pale one among vivid markers (a stain), is not
  // one of them. Without such a majority the finding is refused below (sizes too different).
  const auto drop_minority = [&](const std::function<double(const Verified&)>& value,
                                 const std::function<bool(double, double)>& unlike_median) {
    if (verified.size() < 3) return;
    std::vector<double> values;
    for (const Verified& v : verified) values.push_back(value(v));
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    const double median = values[values.size() / 2];
    const auto unlike = [&](const Verified& v) { return unlike_median(value(v), median); };
    const size_t outliers =
        static_cast<size_t>(std::count_if(verified.begin(), verified.end(), unlike));
    if (outliers * 2 >= verified.size()) return;
    for (const Verified& v : verified) {
      if (unlike(v)) {
        finding.rejected.push_back({v.marker.position_px, v.marker.radius_px,
                                    "unlike the other markers (size or paleness)"});
      }
    }
    verified.erase(std::remove_if(verified.begin(), verified.end(), unlike), verified.end());
  };
  drop_minority([](const Verified& v) { return v.marker.radius_px; },
                [](double r, double median) {
                  return r < median / kBodySizeRatio || r > median * kBodySizeRatio;
                });
  if (!finding.intensity) {
    drop_minority([](const Verified& v) { return v.looks.saturation; },
                  [](double s, double median) { return s < kMinSaturationRatio * median; });
  }

  // ---- 4. Body order, names, measurement ---------------------------------------------------------
  std::vector<cv::Point2d> positions;
  for (const Verified& v : verified) positions.push_back(v.marker.position_px);
  bool order_ambiguous = false;
  const std::vector<size_t> order =
      OrderAlongBody(positions, frame.size(), options.base_near_px, &order_ambiguous);
  for (size_t k = 0; k < order.size(); ++k) {
    Verified& v = verified[order[k]];
    std::string name = finding.intensity ? "dot" + std::to_string(k) : HueName(v.hue);
    if (!finding.intensity) {
      int same = 0;
      for (const FoundMarker& m : finding.markers) {
        if (m.spec.name == name || m.spec.name.rfind(name + "_", 0) == 0) ++same;
      }
      if (same > 0) name += "_" + std::to_string(same + 1);
    }
    v.marker.spec.name = name;
    ColourParams& colour = v.marker.spec.params.get<ColourParams>();
    if (colour.roi) colour.roi_frame = static_cast<int>(options.frame_index);
    finding.markers.push_back(v.marker);
  }
  const size_t n = finding.markers.size();
  finding.measure = BodyMeasure(finding.markers);
  if (n >= 2) {
    finding.notes.push_back(
        "base: " + finding.markers.front().spec.name +
        (options.base_near_px ? " (the end nearest the given point)"
                              : " (the end nearer the image border; --base X,Y chooses)"));
  }

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
  const std::string rejected_count = std::to_string(finding.rejected.size());
  if (!look_alikes.empty()) {
    std::string text;
    for (const std::string& l : look_alikes) text += (text.empty() ? "" : "; ") + l;
    finding.problem = "several blobs fit each of these colours alike, and init will not guess "
                      "which is the marker: " + text + " (restrict the search to the actuator with --roi X,Y,W,H, or pick the "
                      "markers with `softsight pick`)";
  } else if (n == 0) {
    // The reasons, most frequent first: what a person needs to change (light, focus, markers).
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
    finding.problem = std::string("no markers: no compact ") +
                      (finding.intensity ? "white or black dot" : "saturated blob") +
                      " stands out from its surroundings (" + rejected_count +
                      " blobs of some size rejected" + why + "; see the picture)";
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
  return finding;
}

}  // namespace

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
