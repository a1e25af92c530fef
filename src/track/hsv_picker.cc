#include "softsight/track/hsv_picker.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <opencv2/imgproc.hpp>

namespace softsight {
namespace {

constexpr int kHueCount = HsvRange::kHueCycle;  // OpenCV's 8-bit hue: 0..179, two degrees per step.
// The least chroma (largest minus smallest of a pixel's B, G, R: saturation x value / 255) whose
// hue means something: 8-bit hue moves in steps of 60 / chroma degrees, and noise of 2-3 levels
// turns a pixel of chroma 10 through 30 degrees. A dim saturated marker under a side lamp (value
// 50, saturation 130) has 25.
constexpr int kMinHueChroma = 16;
// How far (hue steps, 2 degrees each) a sampled pixel's hue may lie from the most common one to
// count as the marker's: a dome's hue moves 5-15 steps between its lit and shaded sides (red
// under a warm lamp 165-10), the next colour a person would name lies 25-30 away.
constexpr int kHueClusterHalfWidth = 20;
// A click farther than this from the centre of the marker's blob through it is re-centred there
// (px), within this reach of the click (a marker up to about 80 px across).
constexpr double kRecentrePx = 2.0;
constexpr int kRecentreReachPx = 48;
// The near surroundings of a picked marker (SurroundingsPassing): from this far beyond its blob
// (past the blurred rim) to this far (px).
constexpr int kSurroundingsNearPx = 3;
constexpr int kSurroundingsFarPx = 10;
// A coloured pick whose range passes at least this much of the marker's near surroundings is
// weighed against the white or black dot's (PickHsvRange).
constexpr double kLeakyColourPick = 0.05;
// A pick whose range passes this much of the marker's near surroundings is refused.
constexpr double kInseparablePick = 0.5;

// Linear-interpolated percentile of sorted values, `percent` in [0, 100].
double Percentile(const std::vector<double>& sorted, double percent) {
  const double position = percent / 100.0 * (sorted.size() - 1);
  const size_t below = static_cast<size_t>(std::floor(position));
  const size_t above = std::min(below + 1, sorted.size() - 1);
  const double frac = position - below;
  return sorted[below] * (1 - frac) + sorted[above] * frac;
}

HsvRange LinearRange(std::vector<double> values, const HsvPickOptions& o, int margin,
                     int floor_at) {
  std::sort(values.begin(), values.end());
  const double lo = Percentile(values, o.low_percentile) - margin;
  const double hi = Percentile(values, o.high_percentile) + margin;
  return {std::clamp(static_cast<int>(std::floor(lo)), floor_at, 255),
          std::clamp(static_cast<int>(std::ceil(hi)), 0, 255)};
}


}  // namespace

bool HsvPickOptions::Check(std::string* error) const {
  auto fail = [&](const std::string& message) {
    *error = message;
    return false;
  };
  if (radius_px < 0 || radius_px > 100) {
    return fail("radius_px must be in 0..100, got " + std::to_string(radius_px));
  }
  if (!(low_percentile >= 0 && low_percentile < high_percentile && high_percentile <= 100)) {
    return fail("low_percentile and high_percentile must satisfy 0 <= low < high <= 100, got " +
                std::to_string(low_percentile) + " and " + std::to_string(high_percentile));
  }
  if (hue_margin < 0 || hue_margin > 89) {
    return fail("hue_margin must be in 0..89, got " + std::to_string(hue_margin));
  }
  if (saturation_margin < 0 || saturation_margin > 255) {
    return fail("saturation_margin must be in 0..255, got " + std::to_string(saturation_margin));
  }
  if (value_margin < 0 || value_margin > 255) {
    return fail("value_margin must be in 0..255, got " + std::to_string(value_margin));
  }
  if (!(darkest_light > 0 && darkest_light <= 1)) {
    return fail("darkest_light must be in (0, 1], got " + std::to_string(darkest_light));
  }
  if (min_saturation < 0 || min_saturation > 255) {
    return fail("min_saturation must be in 0..255, got " + std::to_string(min_saturation));
  }
  return true;
}

namespace {
// PickHsvFromSamples with the channels' least spread for a pixel to carry a hue (kMinHueChroma
// there) as a parameter.
std::optional<HsvPick> PickHsvFromSamplesWithChroma(const std::vector<cv::Vec3b>& hsv_samples,
                                                    const HsvPickOptions& options,
                                                    int min_chroma, std::string* why_not) {
  std::string error;
  CV_Assert(options.Check(&error));
  auto fail = [&](const std::string& message) -> std::optional<HsvPick> {
    if (why_not != nullptr) *why_not = message;
    return std::nullopt;
  };
  if (hsv_samples.empty()) return fail("no pixels to sample");

  // Only saturated pixels carry a hue; grey rim or background pixels would scatter it. And only
  // pixels whose channels differ by kMinHueChroma levels or more: a black dot's pixels (levels
  // 5-20, a few apart under tinted light) are "saturated" by noise, their hue the light's.
  std::vector<cv::Vec3b> coloured;
  coloured.reserve(hsv_samples.size());
  for (const cv::Vec3b& p : hsv_samples) {
    if (p[1] >= options.min_saturation && p[1] * p[2] >= min_chroma * 255) {
      coloured.push_back(p);
    }
  }
  if (coloured.size() * 2 < hsv_samples.size()) {
    return fail("not a coloured marker: only " + std::to_string(coloured.size()) + " of " +
                std::to_string(hsv_samples.size()) + " pixels have saturation >= " +
                std::to_string(options.min_saturation) + " and channels " +
                std::to_string(min_chroma) + " or more levels apart");
  }

  // The marker's hue is the most common one (a histogram smoothed over 7 steps, around the
  // circle), and only the pixels within kHueClusterHalfWidth of it are the marker's: a click off
  // its centre samples its surroundings too (orange wood beside a blue dome, a shaded rib, the
  // next marker), and their hues in the percentiles would stretch the range over other colours.
  std::array<int, kHueCount> histogram{};
  for (const cv::Vec3b& p : coloured) ++histogram[p[0] % kHueCount];
  int mode = 0, mode_count = -1;
  for (int h = 0; h < kHueCount; ++h) {
    int count = 0;
    for (int d = -3; d <= 3; ++d) count += histogram[(h + d + kHueCount) % kHueCount];
    if (count > mode_count) mode = h, mode_count = count;
  }
  const auto hue_distance = [](int a, int b) {
    const int d = std::abs(a - b) % kHueCount;
    return std::min(d, kHueCount - d);
  };
  coloured.erase(std::remove_if(coloured.begin(), coloured.end(),
                                [&](const cv::Vec3b& p) {
                                  return hue_distance(p[0], mode) > kHueClusterHalfWidth;
                                }),
                 coloured.end());

  // Circular mean of the hue, then every hue as a signed offset from it in [-90, 90): the
  // percentiles of the offsets are well defined whether or not the colour straddles 0.
  double sum_sin = 0, sum_cos = 0;
  for (const cv::Vec3b& p : coloured) {
    const double angle = p[0] * (2 * CV_PI / kHueCount);
    sum_sin += std::sin(angle);
    sum_cos += std::cos(angle);
  }
  double mean_hue = std::atan2(sum_sin, sum_cos) * (kHueCount / (2 * CV_PI));
  if (mean_hue < 0) mean_hue += kHueCount;
  std::vector<double> offsets, sat, val;
  offsets.reserve(coloured.size());
  sat.reserve(coloured.size());
  val.reserve(coloured.size());
  for (const cv::Vec3b& p : coloured) {
    double offset = std::fmod(p[0] - mean_hue + 1.5 * kHueCount, kHueCount) - 0.5 * kHueCount;
    offsets.push_back(offset);
    sat.push_back(p[1]);
    val.push_back(p[2]);
  }
  std::sort(offsets.begin(), offsets.end());
  const double lo_offset = Percentile(offsets, options.low_percentile);
  const double hi_offset = Percentile(offsets, options.high_percentile);

  HsvPick pick;
  pick.sample_count = static_cast<int>(hsv_samples.size());
  pick.hue_spread = hi_offset - lo_offset;
  const int lo = static_cast<int>(std::floor(mean_hue + lo_offset)) - options.hue_margin;
  const int hi = static_cast<int>(std::ceil(mean_hue + hi_offset)) + options.hue_margin;
  if (hi - lo + 1 >= kHueCount) {
    pick.h = {0, kHueCount - 1};  // Covers every hue: saturation and value do the separating.
  } else {
    pick.h = {HsvRange::WrapHue(lo), HsvRange::WrapHue(hi)};
  }
  // Saturation does not go below min_saturation here: below it the hue of a few sampled pixels
  // means little. (PickHsvRange lowers it for a pale marker on paler surroundings.)
  pick.s = LinearRange(std::move(sat), options, options.saturation_margin, options.min_saturation);
  std::sort(val.begin(), val.end());  // Once, for the margin's range and the darkest light's.
  const int darkest =
      static_cast<int>(std::floor(options.darkest_light * Percentile(val, options.low_percentile)));
  pick.v = {std::min(LinearRange(std::move(val), options, options.value_margin, 0).lo, darkest), 255};
  return pick;
}
}  // namespace

std::optional<HsvPick> PickHsvFromSamples(const std::vector<cv::Vec3b>& hsv_samples,
                                          const HsvPickOptions& options, std::string* why_not) {
  return PickHsvFromSamplesWithChroma(hsv_samples, options, kMinHueChroma, why_not);
}

namespace {

// How far a white or black dot's gray levels must stand from its surroundings'.
constexpr int kMinDotContrast = 20;

// A white or black dot at the click: the disc's gray levels against a ring around it. The dot
// may be larger than the sampled disc, so rings 3 px wide at growing distances are tried and the
// one that stands farthest from the disc is its surroundings.
std::optional<HsvPick> PickGrayDot(const cv::Mat& bgr, cv::Point2d click_px, int radius,
                                   std::string* why) {
  constexpr int kRingStarts[] = {3, 6, 9, 12, 16, 20, 25, 30};
  constexpr int kRingWidth = 3;
  const int outer = radius + kRingStarts[std::size(kRingStarts) - 1] + kRingWidth;
  const cv::Point centre(cvRound(click_px.x), cvRound(click_px.y));
  const cv::Rect box = cv::Rect(centre.x - outer, centre.y - outer, 2 * outer + 1, 2 * outer + 1) &
                       cv::Rect(0, 0, bgr.cols, bgr.rows);
  const std::string plain = *why + ", nor a white or black dot (its gray levels do not stand " +
                            std::to_string(kMinDotContrast) + " above or below its surroundings')";
  if (box.empty()) {
    *why = plain;
    return std::nullopt;
  }
  cv::Mat gray;
  cv::cvtColor(bgr(box), gray, cv::COLOR_BGR2GRAY);
  std::vector<double> disc;
  std::vector<std::vector<double>> rings(std::size(kRingStarts));
  for (int y = 0; y < gray.rows; ++y) {
    for (int x = 0; x < gray.cols; ++x) {
      const double d = std::hypot(box.x + x - click_px.x, box.y + y - click_px.y);
      const double level = gray.at<uchar>(y, x);
      if (d <= radius + 0.5) disc.push_back(level);
      for (size_t k = 0; k < rings.size(); ++k) {
        if (d >= radius + kRingStarts[k] && d < radius + kRingStarts[k] + kRingWidth) {
          rings[k].push_back(level);
        }
      }
    }
  }
  if (disc.empty()) {
    *why = plain;
    return std::nullopt;
  }
  std::sort(disc.begin(), disc.end());
  const double disc_lo = Percentile(disc, 10), disc_hi = Percentile(disc, 90);
  double best_white = -1e9, best_black = -1e9, white_level = 0, black_level = 0;
  for (std::vector<double>& ring : rings) {
    if (ring.size() < 8) continue;
    std::sort(ring.begin(), ring.end());
    const double ring_lo = Percentile(ring, 10), ring_hi = Percentile(ring, 90);
    if (disc_lo - ring_hi > best_white) {
      best_white = disc_lo - ring_hi;
      white_level = 0.5 * (disc_lo + ring_hi);
    }
    if (ring_lo - disc_hi > best_black) {
      best_black = ring_lo - disc_hi;
      black_level = 0.5 * (disc_hi + ring_lo);
    }
  }
  HsvPick pick;
  pick.h = {0, kHueCount - 1};
  pick.s = {0, 255};
  pick.v = {0, 255};
  pick.sample_count = static_cast<int>(disc.size());
  if (best_white >= kMinDotContrast) {
    pick.gray = HsvRange{static_cast<int>(std::floor(white_level)), 255};
  } else if (best_black >= kMinDotContrast) {
    pick.gray = HsvRange{0, static_cast<int>(std::ceil(black_level))};
  } else {
    *why = plain;
    return std::nullopt;
  }
  return pick;
}

// The lowest saturation floor a pale marker's range may get: below it the hue of an 8-bit pixel
// (steps of 60 / S degrees) is noise, and white or gray surfaces pass any hue range.
constexpr int kLowestSaturationFloor = 16;
// How far the marker's saturation must stand above its surroundings' for the floor to drop.
constexpr int kMinSaturationContrast = 20;
// How far the lower floor must move the centre of the blob at the click for it to be taken: a
// part of the marker on one side was cut off. A rim that only widens all round (the blur at a
// saturated marker's edge) moves it less, and widening the range for it only lets in more of
// the surroundings.
constexpr double kMinCentreShiftPx = 1.0 / 3.0;

// The HSV pixels of the disc of radius `r` around `at` (pixel-centre convention) inside `bgr`.
std::vector<cv::Vec3b> SampleDisc(const cv::Mat& bgr, cv::Point2d at, int r) {
  const cv::Point centre(cvRound(at.x), cvRound(at.y));
  const cv::Rect box = cv::Rect(centre.x - r, centre.y - r, 2 * r + 1, 2 * r + 1) &
                       cv::Rect(0, 0, bgr.cols, bgr.rows);
  std::vector<cv::Vec3b> samples;
  if (box.empty()) return samples;
  cv::Mat hsv;
  cv::cvtColor(bgr(box), hsv, cv::COLOR_BGR2HSV);
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      const double dx = box.x + x - at.x, dy = box.y + y - at.y;
      if (dx * dx + dy * dy <= (r + 0.5) * (r + 0.5)) samples.push_back(hsv.at<cv::Vec3b>(y, x));
    }
  }
  return samples;
}

// The area a blob at `centre` is looked for in (BlobIn): kRecentreReachPx around it.
cv::Rect SearchedArea(cv::Point centre) {
  const int reach = kRecentreReachPx;
  return cv::Rect(centre.x - reach, centre.y - reach, 2 * reach + 1, 2 * reach + 1);
}

// The blob of the pixels that pass `pick`'s ranges and are joined (8 ways) to the one at `at`,
// within kRecentreReachPx of it, with the pixels around it that pass too.
struct BlobAtClick {
  cv::Rect box;        // The searched area (within the image), in image pixels.
  cv::Mat passes;      // CV_8U over `box`: 255 where a pixel passes the ranges.
  cv::Mat blob;        // CV_8U over `box`: 255 on the blob.
};

// Nothing when the pixel at `at` fails (and every one within `seed_reach` px of it: the blob is
// then the one through the nearest that passes), or the blob reaches the edge of the searched
// area (not a marker-sized blob: a surface of the marker's colour, or the range let the
// surroundings in). `converted_image`: the image's pixels over `converted_box` in the pick's
// colour space (gray for a white or black dot's pick, else HSV), a box inside the image that
// holds the searched area as far as the image does (a caller that has converted a larger box
// already passes it: no pixel is converted twice).
std::optional<BlobAtClick> BlobIn(const cv::Mat& converted_image, const cv::Rect& converted_box,
                                  cv::Point2d at, const HsvPick& pick, int seed_reach = 0) {
  const cv::Point centre(cvRound(at.x), cvRound(at.y));
  const cv::Rect area = SearchedArea(centre);
  BlobAtClick found;
  found.box = area & converted_box;
  if (!found.box.contains(centre)) return std::nullopt;
  // The pixels that pass: a white or black dot's by their gray level, a coloured marker's by
  // hue, saturation and value.
  const cv::Mat converted = converted_image(found.box - converted_box.tl());
  found.passes = cv::Mat(converted.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < converted.rows; ++y) {
    for (int x = 0; x < converted.cols; ++x) {
      const bool passes = pick.gray ? pick.gray->contains(converted.at<uchar>(y, x))
                                    : HsvInRange(converted.at<cv::Vec3b>(y, x), pick.h, pick.s,
                                                 pick.v);
      if (passes) found.passes.at<uchar>(y, x) = 255;
    }
  }
  cv::Point seed = centre - found.box.tl();
  if (!found.passes.at<uchar>(seed)) {
    // A highlight or a speck at the click: the nearest pixel that passes.
    int best = seed_reach * seed_reach + 1;
    const cv::Point click = seed;
    for (int dy = -seed_reach; dy <= seed_reach; ++dy) {
      for (int dx = -seed_reach; dx <= seed_reach; ++dx) {
        const cv::Point p = click + cv::Point(dx, dy);
        if (dx * dx + dy * dy < best && p.inside(cv::Rect(cv::Point(), converted.size())) &&
            found.passes.at<uchar>(p)) {
          best = dx * dx + dy * dy;
          seed = p;
        }
      }
    }
    if (seed == click) return std::nullopt;
  }
  // floodFill's mask is one pixel larger on every side; 0 fills.
  cv::Mat mask(converted.rows + 2, converted.cols + 2, CV_8U, cv::Scalar(1));
  mask(cv::Rect(1, 1, converted.cols, converted.rows)).setTo(0, found.passes);
  // A flat canvas: only the mask bounds the fill.
  cv::Mat canvas(converted.size(), CV_8U, cv::Scalar(0));
  cv::Rect filled;
  cv::floodFill(canvas, mask, seed, cv::Scalar(255), &filled, cv::Scalar(), cv::Scalar(),
                8 | cv::FLOODFILL_MASK_ONLY | (255 << 8));
  if (filled.x == 0 || filled.y == 0 || filled.br().x == converted.cols ||
      filled.br().y == converted.rows) {
    return std::nullopt;
  }
  found.blob = mask(cv::Rect(1, 1, converted.cols, converted.rows)) == 255;
  return found;
}

// BlobIn, converting just the area it looks in.
std::optional<BlobAtClick> BlobAt(const cv::Mat& bgr, cv::Point2d at, const HsvPick& pick,
                                  int seed_reach = 0) {
  const cv::Rect box =
      SearchedArea(cv::Point(cvRound(at.x), cvRound(at.y))) & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (box.empty()) return std::nullopt;
  cv::Mat converted;
  cv::cvtColor(bgr(box), converted, pick.gray ? cv::COLOR_BGR2GRAY : cv::COLOR_BGR2HSV);
  return BlobIn(converted, box, at, pick, seed_reach);
}

// The centroid of a blob BlobIn or BlobAt found.
std::optional<cv::Point2d> CentroidOf(const std::optional<BlobAtClick>& found) {
  if (!found) return std::nullopt;
  const cv::Moments m = cv::moments(found->blob, true);
  if (!(m.m00 > 0)) return std::nullopt;
  return cv::Point2d(found->box.x + m.m10 / m.m00, found->box.y + m.m01 / m.m00);
}

std::optional<cv::Point2d> BlobCentroidAt(const cv::Mat& bgr, cv::Point2d at, const HsvPick& pick) {
  return CentroidOf(BlobAt(bgr, at, pick));
}

// How well `pick`'s ranges tell the marker at `at` from what is around it: the fraction of its
// near surroundings (the pixels 3 to 10 px beyond the blob at `at`, or at the pixel nearest to
// it within the sampled disc that passes) that pass them, 1 when there is no marker-sized blob
// there. A range that passes its surroundings joins the marker to them as soon as it moves or
// the light changes.
double SurroundingsPassing(const cv::Mat& bgr, cv::Point2d at, const HsvPick& pick,
                           int sample_radius) {
  const std::optional<BlobAtClick> found = BlobAt(bgr, at, pick, sample_radius);
  if (!found) return 1.0;
  const auto grown = [&](int r) {
    cv::Mat out;
    cv::dilate(found->blob, out,
               cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
    return out;
  };
  const cv::Mat ring = grown(kSurroundingsFarPx) & ~grown(kSurroundingsNearPx - 1);
  const int total = cv::countNonZero(ring);
  if (total == 0) return 1.0;
  return static_cast<double>(cv::countNonZero(ring & found->passes)) / total;
}

// A pale marker (a light pigment, or a lit dome whose top the light whitens) has a part less
// saturated than the pick's floor of min_saturation, and a range that cuts it off moves the
// marker's centre towards its saturated part. When the surroundings are paler still, the floor
// drops to a third of the way from them to the marker's sampled pixels (their 10th percentile):
// - where the marker ends: the first 3 px ring around the click of which less than a quarter
//   passes the pick's range; the surroundings start one ring further (that ring holds the
//   blurred rim) and reach 30 px out;
// - the surroundings' saturation: the 99th percentile, over their pixels, of the saturation a
//   pixel needs to pass the range (none where its hue or value fails it), so a surface of the
//   marker's hue nearby keeps the floor where it was and other hues do not matter.
// The lower floor is taken only when it moves the centre of the blob at the click (the marker
// had a part cut off on one side), by kMinCentreShiftPx or more.
void LowerSaturationFloorToSurroundings(const cv::Mat& bgr, cv::Point2d click_px,
                                        const std::vector<cv::Vec3b>& disc, int radius,
                                        HsvPick* pick) {
  if (pick->s.lo <= kLowestSaturationFloor) return;
  std::vector<double> disc_sat;
  for (const cv::Vec3b& p : disc) {
    if (HsvInRange(p, pick->h, pick->s, pick->v)) disc_sat.push_back(p[1]);
  }
  if (disc_sat.size() < 8) return;
  std::sort(disc_sat.begin(), disc_sat.end());
  const double disc_lo = Percentile(disc_sat, 10);

  constexpr int kRingWidth = 3, kFarthest = 30;
  const int outer = radius + kFarthest + kRingWidth;
  const cv::Point centre(cvRound(click_px.x), cvRound(click_px.y));
  // The box holds the rings and the area the blob at the click is looked for in below, which is
  // larger for a radius under 15 px: it is converted once for both (the pixels beyond the rings
  // are passed over).
  const int half = std::max(outer, kRecentreReachPx);
  const cv::Rect box = cv::Rect(centre.x - half, centre.y - half, 2 * half + 1, 2 * half + 1) &
                       cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (box.empty()) return;
  cv::Mat hsv;
  cv::cvtColor(bgr(box), hsv, cv::COLOR_BGR2HSV);
  const int ring_count = (kFarthest - 3) / kRingWidth + 1;
  std::vector<int> ring_total(ring_count, 0), ring_passing(ring_count, 0);
  std::vector<std::vector<double>> ring_needs(ring_count);
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      const double d = std::hypot(box.x + x - click_px.x, box.y + y - click_px.y) - radius - 3;
      if (d < 0) continue;
      const int k = static_cast<int>(d) / kRingWidth;
      if (k >= ring_count) continue;
      const cv::Vec3b& p = hsv.at<cv::Vec3b>(y, x);
      ++ring_total[k];
      ring_passing[k] += HsvInRange(p, pick->h, pick->s, pick->v);
      // The saturation the pixel needs to pass the range: none (0) when its hue or value fails.
      ring_needs[k].push_back(pick->h.contains_hue(p[0]) && pick->v.contains(p[2]) ? p[1] : 0);
    }
  }
  int edge = 0;
  while (edge < ring_count && 4 * ring_passing[edge] >= ring_total[edge]) ++edge;
  if (edge + 1 >= ring_count) return;  // The marker fills the rings: nothing to compare with.
  std::vector<double> beyond;
  // The ring where the marker ends still holds its blurred rim: the surroundings start beyond.
  for (int k = edge + 1; k < ring_count; ++k) {
    beyond.insert(beyond.end(), ring_needs[k].begin(), ring_needs[k].end());
  }
  if (beyond.size() < 24) return;
  std::sort(beyond.begin(), beyond.end());
  const double surroundings = Percentile(beyond, 99);
  if (disc_lo - surroundings < kMinSaturationContrast) return;
  const int floor = std::max(
      kLowestSaturationFloor,
      static_cast<int>(std::ceil(surroundings + (disc_lo - surroundings) / 3)));
  if (floor >= pick->s.lo) return;
  HsvPick lower = *pick;
  lower.s.lo = floor;
  const auto before = CentroidOf(BlobIn(hsv, box, click_px, *pick));
  const auto after = CentroidOf(BlobIn(hsv, box, click_px, lower));
  if (!before || !after) return;
  if (cv::norm(*after - *before) < kMinCentreShiftPx) return;
  pick->s.lo = floor;
}

// Whether the sampled disc (HSV) could be a white or black dot that tinted light or sensor noise
// gives a hue, so that its gray range may be the marker's kind: a white dot takes no more than
// the light's tint (median saturation 55-71 under a warm or cold cast without white balance,
// where a 2700 K lamp reaches about 120), a black dot's channels stay close whatever their hue
// (median chroma 13-19 with noise of sigma 8). A pigment is more saturated than either: an
// orange dome on a dark actuator under the warm lamp has 247 and chroma 101, and its gray range
// (anything lit) took it for a white dot, 2-2.8 px off.
constexpr int kMaxTintedWhiteSaturation = 140;
constexpr int kMaxNoisyBlackChroma = 2 * kMinHueChroma;

bool CouldBeTintedGrayDot(const std::vector<cv::Vec3b>& hsv_samples) {
  if (hsv_samples.empty()) return false;
  std::vector<int> saturation, chroma;
  saturation.reserve(hsv_samples.size());
  chroma.reserve(hsv_samples.size());
  for (const cv::Vec3b& p : hsv_samples) {
    saturation.push_back(p[1]);
    chroma.push_back(p[1] * p[2] / 255);  // max - min of the channels.
  }
  const auto median = [](std::vector<int>& v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  return median(saturation) < kMaxTintedWhiteSaturation || median(chroma) < kMaxNoisyBlackChroma;
}

}  // namespace

std::optional<HsvPick> PickHsvRange(const cv::Mat& bgr, cv::Point2d click_px,
                                    const HsvPickOptions& options, std::string* why_not) {
  CV_Assert(bgr.type() == CV_8UC3);
  const int r = options.radius_px;
  std::vector<cv::Vec3b> samples = SampleDisc(bgr, click_px, r);
  if (samples.empty()) {
    if (why_not != nullptr) *why_not = "the click is outside the image";
    return std::nullopt;
  }
  std::string why;
  std::optional<HsvPick> pick = PickHsvFromSamples(samples, options, &why);
  cv::Point2d sampled_at = click_px;
  bool gray = false;
  // How much of its surroundings the pick passes at the click, where already measured.
  std::optional<double> passing_at_click;
  if (!pick && why.rfind("not a coloured marker", 0) == 0) {
    pick = PickGrayDot(bgr, click_px, r, &why);
    gray = true;
    // A dim coloured dome (blue under a warm lamp, its channels 8-15 levels apart) is no colour
    // by the channels' spread a hue needs, and dark as a black dot; but the dark range takes in
    // its shadow and the grooves beside it, where its hue does not. Its colour, read from the
    // pixels with half that spread, is taken if it tells the marker from its near surroundings
    // better than the gray range does.
    if (pick && r > 1) {
      if (std::optional<HsvPick> dim =
              PickHsvFromSamplesWithChroma(samples, options, kMinHueChroma / 2, nullptr)) {
        const double dim_passing = SurroundingsPassing(bgr, click_px, *dim, r);
        const double gray_passing = SurroundingsPassing(bgr, click_px, *pick, r);
        passing_at_click = gray_passing;
        if (dim_passing < kLeakyColourPick && dim_passing <= gray_passing) {
          pick = dim;
          gray = false;
          passing_at_click = dim_passing;
        }
      }
    }
  }
  // The pick of the same kind (a white or black dot's, or a coloured marker's) from the whole
  // disc at `at`, the marker's centre; a coloured marker's samples go to `disc`.
  const auto pick_at = [&](cv::Point2d at, std::vector<cv::Vec3b>* disc) {
    std::string unused = why;
    if (gray) return PickGrayDot(bgr, at, r, &unused);
    *disc = SampleDisc(bgr, at, r);
    return PickHsvFromSamples(*disc, options, nullptr);
  };
  // Takes the pick at the centre of the blob `first` gives through `from`, if there is one and
  // it is farther than `beyond` px, and the pick there succeeds: true when it took it.
  const auto recentre = [&](const HsvPick& first, cv::Point2d from, double beyond) {
    const std::optional<cv::Point2d> centre = BlobCentroidAt(bgr, from, first);
    if (!centre || cv::norm(*centre - from) <= beyond) return false;
    std::vector<cv::Vec3b> resampled;
    std::optional<HsvPick> repick = pick_at(*centre, &resampled);
    if (!repick) return false;
    pick = repick;
    if (!gray) samples = std::move(resampled);
    sampled_at = *centre;
    return true;
  };
  // A click near a marker's rim: the disc holds as much of the surroundings as of the marker.
  // The half disc at the click holds less of them.
  const auto half_disc_colour_pick = [&] {
    return PickHsvFromSamples(SampleDisc(bgr, click_px, r / 2), options, nullptr);
  };
  if (!pick && r > 1) {
    // The half disc may show the marker; it is then sampled at the centre of its blob.
    std::optional<HsvPick> small = half_disc_colour_pick();
    gray = !small;
    std::string unused;
    if (!small) small = PickGrayDot(bgr, click_px, r / 2, &unused);
    if (small) recentre(*small, click_px, -1.0);
  }
  if (pick) {
    // A click off the marker's centre samples its rim and what is around it (a shaded flank, its
    // shadow, the bench; a white or black dot's rings measured from the wrong point): ranges
    // wide enough to take those in. The marker's centre is the centre of the blob those ranges
    // give through the click; the ranges are picked again there.
    const bool recentred = recentre(*pick, sampled_at, kRecentrePx);
    // How much of the marker's near surroundings the pick's range passes, for the pick as it
    // stands (measured again whenever the pick or where it was sampled changes).
    double passing = !recentred && passing_at_click
                         ? *passing_at_click
                         : SurroundingsPassing(bgr, sampled_at, *pick, r);
    if (!gray && r > 1 && passing >= kInseparablePick) {
      // A click near a coloured marker's rim may give ranges wide enough for its shadow and the
      // bench beside it, which then join it. The half disc's ranges, sampled again at the centre
      // of the blob they give, are taken if they tell the marker from its surroundings.
      if (std::optional<HsvPick> small = half_disc_colour_pick()) {
        const std::optional<HsvPick> wide = pick;
        const cv::Point2d wide_at = sampled_at;
        std::vector<cv::Vec3b> wide_samples = samples;
        pick.reset();
        recentre(*small, click_px, -1.0);
        const double narrow = pick ? SurroundingsPassing(bgr, sampled_at, *pick, r) : 1.0;
        if (narrow >= kInseparablePick) {
          pick = wide;
          sampled_at = wide_at;
          samples = std::move(wide_samples);
        } else {
          passing = narrow;
        }
      }
    }
    if (!gray && pick->s.lo == options.min_saturation) {
      // The sampled saturations reach the floor: the marker may be paler in places than the disc.
      LowerSaturationFloorToSurroundings(bgr, sampled_at, samples, r, &*pick);
      if (pick->s.lo != options.min_saturation) {
        passing = SurroundingsPassing(bgr, sampled_at, *pick, r);
      }
    }
    if (!gray && passing >= kLeakyColourPick && CouldBeTintedGrayDot(samples)) {
      // A white dot under tinted light (a warm lamp, a camera without white balance) takes the
      // light's colour, and so do the surfaces around it; sensor noise gives a black dot's
      // pixels hues. Such a colour range passes the marker's surroundings too (or not the
      // marker: noise), while the dot stands out from them by its gray level. The pick that
      // tells the marker from its near surroundings better is the marker's kind; a colour range
      // that passes little of them stays (a red dome is also darker than white silicone).
      std::string unused = why;
      if (std::optional<HsvPick> dot = PickGrayDot(bgr, sampled_at, r, &unused)) {
        const double dot_passing = SurroundingsPassing(bgr, sampled_at, *dot, r);
        if (dot_passing < passing) {
          pick = dot;
          gray = true;
          passing = recentre(*pick, sampled_at, kRecentrePx)
                        ? SurroundingsPassing(bgr, sampled_at, *pick, r)
                        : dot_passing;
        }
      }
    }
    // Found means verified, from the pick on: a range that passes most of what surrounds the
    // marker (a pale dome's colour under a lamp of its tint, which the white silicone takes
    // too) tracks the surroundings, not the marker.
    if (passing >= kInseparablePick) {
      why = "the " + PickName(*pick) + " range picked here passes " +
            (passing >= 1.0 ? std::string("the surroundings too (its blob is not marker-sized)")
                            : std::to_string(static_cast<int>(std::lround(100 * passing))) +
                                  " % of the pixels around the marker") +
            ": it would not tell the marker from them (drag a template box around it instead)";
      pick.reset();
    }
  }
  if (!pick && why_not != nullptr) *why_not = why;
  if (pick) pick->sampled_at_px = sampled_at;
  return pick;
}

std::optional<MarkerColourPick> PickMarkerColourAt(const cv::Mat& bgr, cv::Point2d click_px,
                                                   const HsvPickOptions& options,
                                                   int box_side_px, std::string* why_not) {
  const auto ranges = PickHsvRange(bgr, click_px, options, why_not);
  if (!ranges) return std::nullopt;
  MarkerColourPick pick;
  pick.ranges = *ranges;
  const int side = std::max(1, box_side_px);
  const cv::Point2d at = ranges->sampled_at_px;
  pick.roi = cv::Rect(cvRound(at.x) - side / 2, cvRound(at.y) - side / 2, side, side) &
             cv::Rect(0, 0, bgr.cols, bgr.rows);
  return pick;
}

void ApplyColourPick(const MarkerColourPick& pick, ColourParams* colour) {
  colour->h = pick.ranges.h;
  colour->s = pick.ranges.s;
  colour->v = pick.ranges.v;
  colour->auto_bgr.reset();
  colour->gray = pick.ranges.gray;
  colour->roi = pick.roi;
}

std::string PickName(const HsvPick& pick) {
  if (pick.gray) return pick.gray->hi == 255 ? "white" : "black";
  const HsvRange& h = pick.h;
  return HueName(h.hue_centre());
}

const char* HueName(int hue) {
  hue = HsvRange::WrapHue(hue);
  if (hue < 9 || hue >= 170) return "red";
  if (hue < 20) return "orange";
  if (hue < 35) return "yellow";
  if (hue < 78) return "green";
  if (hue < 96) return "cyan";
  if (hue < 131) return "blue";
  if (hue < 151) return "purple";
  return "magenta";
}

bool HsvInRange(const cv::Vec3b& hsv, const HsvRange& h, const HsvRange& s, const HsvRange& v) {
  return h.contains_hue(hsv[0]) && s.contains(hsv[1]) && v.contains(hsv[2]);
}

}  // namespace softsight
