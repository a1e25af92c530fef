#include "softsight/track/template_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "softsight/track/tracker.h"
#include "track/match_kernels.h"
#include "track/repeated_frames.h"
#include "track/soft_centroid.h"
#include "track/track_options.h"

namespace softsight {

const char* TemplateReportName(TemplateReport report) {
  switch (report) {
    case TemplateReport::kCentre: return "centre";
    case TemplateReport::kSymmetry: return "symmetry";
    case TemplateReport::kRectCentre: return "rect_centre";
  }
  return "?";
}

namespace {

constexpr int kMinTemplatePx = 3;           // Smaller templates have no sub-pixel neighbourhood.
constexpr int kMinRungPx = 5;               // Smallest side of a scaled first template.
constexpr int kMaxTemplateRowBytes = 2048;  // The SAD kernel's 16-bit accumulator limit.
constexpr int kMinCoarseTemplatePx = 8;     // Coarsest pyramid template side.
constexpr int kRefineMarginPx = 2;          // Search margin per pyramid level while refining.
constexpr int kCandidates = 3;              // Coarse peaks refined to full resolution.
constexpr int kMaxRecentre = 4;             // Re-centrings of the final window onto its peak.
constexpr int kFineMarginPx = 3;            // First-template search around the working match.
constexpr double kScaleStep = 1.05;         // Ratio between neighbouring rungs of the ladder.
constexpr int kRungsBelow = 19;             // 1.05^-19 = 0.40.
constexpr int kRungsAbove = 28;             // 1.05^28 = 3.92.
// A neighbouring rung replaces the current one only when its ZNCC is higher by this much, so
// noise does not make the scale flicker between two rungs that fit equally.
constexpr double kScaleHysteresis = 0.003;
// Below this self-match of the turned template there is no centre of symmetry worth reporting.
constexpr double kMinSymmetry = 0.5;

constexpr double kNoRival = -std::numeric_limits<double>::infinity();

std::string RectText(const cv::Rect& r) {
  return cv::format("[%d, %d, %d, %d]", r.x, r.y, r.width, r.height);
}

// Centre-of-template coordinates <-> top-left placement.
cv::Point2d HalfSize(const cv::Size& size) {
  return {(size.width - 1) / 2.0, (size.height - 1) / 2.0};
}

// Peak offset in [-0.5, 0.5] from three samples of a similarity (higher is better) around its
// integer maximum `c`. A parabola suits quadratic peaks (SSD, ZNCC); the equiangular fit suits
// V-shaped ones (SAD), where a parabola would halve the offset.
double PeakOffset(double l, double c, double r, bool v_shaped) {
  if (!std::isfinite(l) || !std::isfinite(r)) return 0.0;
  double d = 0.0;
  if (v_shaped) {
    const double slope = c - std::min(l, r);
    if (slope > 0) d = (r - l) / (2.0 * slope);
  } else {
    const double curvature = 2.0 * c - l - r;
    if (curvature > 0) d = (r - l) / (2.0 * curvature);
  }
  return std::clamp(d, -0.5, 0.5);
}

// Sub-pixel offset of the peak at `best` of a similarity map, per axis.
cv::Point2d SubPixel(const cv::Mat& sim, cv::Point best, bool v_shaped) {
  cv::Point2d offset(0, 0);
  const float* row = sim.ptr<float>(best.y);
  if (best.x > 0 && best.x < sim.cols - 1) {
    offset.x = PeakOffset(row[best.x - 1], row[best.x], row[best.x + 1], v_shaped);
  }
  if (best.y > 0 && best.y < sim.rows - 1) {
    offset.y = PeakOffset(sim.at<float>(best.y - 1, best.x), row[best.x],
                          sim.at<float>(best.y + 1, best.x), v_shaped);
  }
  return offset;
}

// The highest non-NaN value of a CV_32F map; false when every value is NaN.
bool BestIn(const cv::Mat& sim, cv::Point* at) {
  float best = -std::numeric_limits<float>::infinity();
  bool any = false;
  for (int y = 0; y < sim.rows; ++y) {
    const float* s = sim.ptr<float>(y);
    for (int x = 0; x < sim.cols; ++x) {
      if (s[x] > best || (!any && !std::isnan(s[x]))) {
        best = s[x];
        *at = {x, y};
        any = true;
      }
    }
  }
  return any;
}

// The highest local maximum of `sim` farther than `radius` (per axis) from `best`: a distinct
// second place the template fits. A value on the map's edge counts when it is not below its
// neighbours inside (it may be the slope of a peak just outside). False when there is none.
bool RivalIn(const cv::Mat& sim, cv::Point best, int radius, cv::Point* at) {
  float top = -std::numeric_limits<float>::infinity();
  bool any = false;
  for (int y = 0; y < sim.rows; ++y) {
    const float* s = sim.ptr<float>(y);
    for (int x = 0; x < sim.cols; ++x) {
      if (std::abs(x - best.x) <= radius && std::abs(y - best.y) <= radius) continue;
      const float v = s[x];
      if (std::isnan(v) || (any && v <= top)) continue;
      bool peak = true;
      for (int dy = -1; dy <= 1 && peak; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int yy = y + dy, xx = x + dx;
          if ((dx == 0 && dy == 0) || yy < 0 || xx < 0 || yy >= sim.rows || xx >= sim.cols) continue;
          if (sim.at<float>(yy, xx) > v) {
            peak = false;
            break;
          }
        }
      }
      if (!peak) continue;
      top = v;
      *at = {x, y};
      any = true;
    }
  }
  return any;
}

// The ellipse inscribed in a template of `size` (pixel centres within it count).
cv::Mat RoundMask(const cv::Size& size) {
  cv::Mat mask(size, CV_8UC1);
  const cv::Point2d centre = HalfSize(size);
  const double rx = size.width / 2.0, ry = size.height / 2.0;
  for (int i = 0; i < size.height; ++i) {
    for (int j = 0; j < size.width; ++j) {
      const double u = (j - centre.x) / rx, v = (i - centre.y) / ry;
      mask.at<uint8_t>(i, j) = u * u + v * v <= 1.0 ? 255 : 0;
    }
  }
  return mask;
}

// ZNCC of `templ` placed at `top_left` of `image` (one placement, by the vector kernel: the
// scalar reference here was a tenth of the tracker's time).
double ZnccAt(const cv::Mat& image, cv::Point top_left, const PreparedTemplate& templ,
              cv::Mat& result, ZnccScratch& scratch) {
  MatchZncc(image(cv::Rect(top_left, templ.size())), templ, result, scratch);
  return result.at<float>(0, 0);  // NaN on a flat window: fails every comparison.
}

// The point about which `templ` is most nearly point-symmetric, in template coordinates: the
// template is matched (ZNCC) against its inner part turned by 180 degrees about a guess c; a
// shift d between the two puts the centre of symmetry at c + d / 2. The guess starts at the
// geometric centre and is refined by turning about the last estimate (sub-pixel, bilinear), so
// the final shift is near zero, where the parabola fit of the peak has no pixel-locking bias.
// `strength` gets the ZNCC of the self-match (1: perfectly symmetric). Falls back to the
// geometric centre.
cv::Point2d SymmetryCentre(const cv::Mat& templ, double* strength) {
  *strength = 0.0;
  const cv::Point2d geometric = HalfSize(templ.size());
  const int m = std::min({3, (templ.cols - 3) / 2, (templ.rows - 3) / 2});
  if (m < 1) return geometric;
  const cv::Rect inner_rect(m, m, templ.cols - 2 * m, templ.rows - 2 * m);
  cv::Point2d c = geometric;
  cv::Mat turned, zncc;
  ZnccScratch scratch;
  PreparedTemplate inner;
  for (int iteration = 0; iteration < 3; ++iteration) {
    const cv::Matx23d turn(-1, 0, 2 * c.x, 0, -1, 2 * c.y);  // Its own inverse.
    cv::warpAffine(templ, turned, turn, templ.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    if (!inner.Prepare(turned(inner_rect))) return geometric;
    MatchZncc(templ, inner, zncc, scratch);
    cv::Point best;
    if (!BestIn(zncc, &best)) return geometric;
    *strength = zncc.at<float>(best);
    const cv::Point2d shift = cv::Point2d(best.x - m, best.y - m) + SubPixel(zncc, best, false);
    c += 0.5 * shift;
    if (std::abs(c.x - geometric.x) > m || std::abs(c.y - geometric.y) > m) return geometric;
    if (cv::norm(shift) < 1e-3) break;
  }
  return c;
}

// ---- Re-centring on the marker's blob ---------------------------------------------------------
// A marker that is a blob (a dot, a disc: one compact region brighter or darker than what is
// around it) is measured by its soft centroid in every frame: each pixel weighs by how much of it
// is marker, (v - background) / (marker - background) clamped to [0, 1], with the two levels
// split by Otsu's criterion in the patch at the match. Its centroid is the marker's centroid
// whatever its shape, so it follows perspective, scale and rotation exactly, where a template's
// fixed anchor carries the band's texture turning with the body.

// Otsu split of the (masked) values of a one-channel patch: the two class means. False when the
// patch has too little contrast to split.
bool SplitLevels(const cv::Mat& gray, const cv::Mat& mask, double* low, double* high) {
  int hist[256] = {0};
  int n = 0;
  for (int y = 0; y < gray.rows; ++y) {
    const uint8_t* g = gray.ptr<uint8_t>(y);
    const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(y);
    for (int x = 0; x < gray.cols; ++x) {
      if (m && !m[x]) continue;
      ++hist[g[x]];
      ++n;
    }
  }
  if (n < 2) return false;
  double total = 0;
  for (int v = 0; v < 256; ++v) total += double{1.0} * v * hist[v];
  double best = -1, sum0 = 0;
  int n0 = 0;
  for (int t = 0; t < 255; ++t) {
    n0 += hist[t];
    sum0 += double{1.0} * t * hist[t];
    const int n1 = n - n0;
    if (n0 == 0 || n1 == 0) continue;
    const double m0 = sum0 / n0, m1 = (total - sum0) / n1;
    const double between = double{1.0} * n0 * n1 * (m1 - m0) * (m1 - m0);
    if (between > best) {
      best = between;
      *low = m0;
      *high = m1;
    }
  }
  return best > 0;
}

constexpr double kMinBlobContrast = 12.0;  // Grey levels between marker and background.
// The blob at a match has at least this fraction of the learned blob's area (at the current
// scale), and at most its inverse: a tilt to 60 degrees halves a disc's area.
constexpr double kMinBlobAreaRatio = 0.4;
// A match may move onto its blob by at least this much (px; more for larger templates).
constexpr double kMinBlobShiftPx = 2.0;
// A blob this close to where the match puts it agrees with the match (px).
constexpr double kBlobAgreePx = 1.0;

// The one channel a template's blob is measured in: native gray, or colour projected on its
// axis (`projection`, see ContrastProjection; empty: luma).
void BlobChannelOf(const cv::Mat& native, const cv::Mat& projection, cv::Mat& out) {
  if (native.channels() == 1) {
    out = native;
  } else if (!projection.empty()) {
    cv::transform(native, out, projection);
  } else {
    cv::cvtColor(native, out, cv::COLOR_BGR2GRAY);
  }
}

class BlobMeter {
 public:
  // Learns the marker's polarity from the selected template (one channel): true when its centre
  // is a blob that lies wholly inside the template (mask), with `centroid` its soft centroid.
  bool Learn(const cv::Mat& gray, const cv::Mat& mask, cv::Point2d* centroid) {
    double low = 0, high = 0;
    if (!SplitLevels(gray, mask, &low, &high) || high - low < kMinBlobContrast) return false;
    const cv::Point centre(gray.cols / 2, gray.rows / 2);
    bright_ = gray.at<uint8_t>(centre) > (low + high) / 2;
    double area = 0;
    if (!Measure(gray, mask, HalfSize(gray.size()), centroid, &area)) return false;
    area_ = area;
    return true;
  }

  // The soft centroid of the marker-side component nearest `guess` (patch coordinates), and its
  // area in px (sum of weights). False when there is no such component within 2 px of the guess,
  // when it touches the patch or mask border (not separated from its surroundings), or when the
  // patch has too little contrast.
  bool Measure(const cv::Mat& gray, const cv::Mat& mask, const cv::Point2d& guess,
               cv::Point2d* centroid, double* area) {
    double low = 0, high = 0;
    if (!Segment(gray, mask, guess, &low, &high)) return false;
    const cv::Rect box = box_;
    // The levels right at the blob: the marker's from its interior (pixels whose 4 neighbours are
    // all in the component), the background's from a ring 3-4 px outside it. Otsu's class means
    // would take them from the whole patch, where shading and texture of the surroundings differ
    // from what is at the rim.
    const cv::Rect grown = cv::Rect(box.x - 4, box.y - 4, box.width + 8, box.height + 8) &
                           cv::Rect(0, 0, gray.cols, gray.rows);
    auto distance = [&](int x, int y) {  // Chebyshev distance to the component, capped at 5.
      int best = 5;
      for (int dy = -4; dy <= 4; ++dy) {
        for (int dx = -4; dx <= 4; ++dx) {
          const int yy = y + dy, xx = x + dx;
          if (yy < 0 || xx < 0 || yy >= gray.rows || xx >= gray.cols || !label_.at<uint8_t>(yy, xx)) {
            continue;
          }
          best = std::min(best, std::max(std::abs(dx), std::abs(dy)));
        }
      }
      return best;
    };
    double fg_sum = 0, bg_sum = 0;
    int fg_n = 0, bg_n = 0;
    dist_.create(gray.size(), CV_8UC1);
    for (int y = grown.y; y < grown.br().y; ++y) {
      for (int x = grown.x; x < grown.br().x; ++x) {
        const int d = label_.at<uint8_t>(y, x) ? 0 : distance(x, y);
        dist_.at<uint8_t>(y, x) = static_cast<uint8_t>(d);
        if (!IsInside(gray, mask, x, y)) continue;
        if (d == 0 && label_.at<uint8_t>(y - 1, x) && label_.at<uint8_t>(y + 1, x) &&
            label_.at<uint8_t>(y, x - 1) && label_.at<uint8_t>(y, x + 1)) {
          fg_sum += gray.at<uint8_t>(y, x);
          ++fg_n;
        } else if (d == 3 || d == 4) {
          bg_sum += gray.at<uint8_t>(y, x);
          ++bg_n;
        }
      }
    }
    const double fg = fg_n > 0 ? fg_sum / fg_n : (bright_ ? high : low);
    const double bg = bg_n > 0 ? bg_sum / bg_n : (bright_ ? low : high);
    if (!(std::abs(fg - bg) >= kMinBlobContrast)) return false;
    // Soft centroid over the component grown by 2 px (its anti-aliased rim), inside the mask.
    double sw = 0, sx = 0, sy = 0;
    for (int y = grown.y; y < grown.br().y; ++y) {
      for (int x = grown.x; x < grown.br().x; ++x) {
        if (!IsInside(gray, mask, x, y) || dist_.at<uint8_t>(y, x) > 2) continue;
        const double w = track_internal::Membership(&gray.at<uint8_t>(y, x), 1, &bg, &fg, 0.0, false);
        sw += w;
        sx += w * x;
        sy += w * y;
      }
    }
    if (!(sw > 0)) return false;
    *centroid = {sx / sw, sy / sw};
    *area = sw;
    return true;
  }

  // The marker-side component nearest `guess`, as Measure finds it, with its binary centroid and
  // pixel count: a quick check that the blob is there (a fraction of Measure's cost).
  bool Locate(const cv::Mat& gray, const cv::Mat& mask, const cv::Point2d& guess,
              cv::Point2d* centroid, double* area) {
    double low = 0, high = 0;
    if (!Segment(gray, mask, guess, &low, &high)) return false;
    const cv::Moments m = cv::moments(label_(box_), true);
    if (!(m.m00 > 0)) return false;
    *centroid = cv::Point2d(box_.tl()) + cv::Point2d(m.m10 / m.m00, m.m01 / m.m00);
    *area = m.m00;
    return true;
  }

  double area() const { return area_; }  // At selection, px.

 private:
  // Splits the patch into its two classes (low, high: their levels) and fills the marker-side
  // component nearest `guess` into label_ (box_). False without contrast, without such a
  // component within 2 px, or when it reaches the patch's or mask's edge.
  bool Segment(const cv::Mat& gray, const cv::Mat& mask, const cv::Point2d& guess, double* low,
               double* high) {
    if (!SplitLevels(gray, mask, low, high) || *high - *low < kMinBlobContrast) return false;
    const double threshold = (*low + *high) / 2;
    const std::optional<cv::Point> seed = SeedNear(gray, mask, guess, threshold);
    return seed && Fill(gray, mask, *seed, threshold);
  }
  bool IsInside(const cv::Mat& gray, const cv::Mat& mask, int x, int y) const {
    return x >= 0 && y >= 0 && x < gray.cols && y < gray.rows &&
           (mask.empty() || mask.at<uint8_t>(y, x));
  }
  bool IsMarker(const cv::Mat& gray, int x, int y, double threshold) const {
    const double v = gray.at<uint8_t>(y, x);
    return bright_ ? v > threshold : v < threshold;
  }
  // The marker-side pixel nearest `guess` at `threshold`, within 2 px (and a bit).
  std::optional<cv::Point> SeedNear(const cv::Mat& gray, const cv::Mat& mask,
                                    const cv::Point2d& guess, double threshold) const {
    std::optional<cv::Point> seed;
    double nearest = 8.0;  // Squared distance.
    const int gx = static_cast<int>(std::lround(guess.x)), gy = static_cast<int>(std::lround(guess.y));
    for (int y = gy - 2; y <= gy + 2; ++y) {
      for (int x = gx - 2; x <= gx + 2; ++x) {
        if (!IsInside(gray, mask, x, y) || !IsMarker(gray, x, y, threshold)) continue;
        const double d = (x - guess.x) * (x - guess.x) + (y - guess.y) * (y - guess.y);
        if (d <= nearest) {
          nearest = d;
          seed = cv::Point(x, y);
        }
      }
    }
    return seed;
  }
  // 4-connected flood fill of the marker side from `seed` into label_ (its bounding box in
  // box_). False when it reaches the patch's or the mask's edge: not separated there.
  bool Fill(const cv::Mat& gray, const cv::Mat& mask, cv::Point seed, double threshold) {
    label_.create(gray.size(), CV_8UC1);
    label_.setTo(0);
    stack_.clear();
    stack_.push_back(seed);
    label_.at<uint8_t>(seed) = 1;
    box_ = cv::Rect(seed, cv::Size(1, 1));
    while (!stack_.empty()) {
      const cv::Point p = stack_.back();
      stack_.pop_back();
      if (p.x == 0 || p.y == 0 || p.x == gray.cols - 1 || p.y == gray.rows - 1) return false;
      box_ |= cv::Rect(p, cv::Size(1, 1));
      const cv::Point next[4] = {{p.x + 1, p.y}, {p.x - 1, p.y}, {p.x, p.y + 1}, {p.x, p.y - 1}};
      for (const cv::Point& q : next) {
        if (!IsInside(gray, mask, q.x, q.y)) return false;  // Reaches the mask's edge.
        if (label_.at<uint8_t>(q) || !IsMarker(gray, q.x, q.y, threshold)) continue;
        label_.at<uint8_t>(q) = 1;
        stack_.push_back(q);
      }
    }
    return true;
  }

  bool bright_ = true;
  double area_ = 0;
  cv::Mat label_, dist_;
  cv::Rect box_;
  std::vector<cv::Point> stack_;
};

// One match of a template in a searched region.
struct Hit {
  cv::Point top_left;          // Integer best placement in frame coordinates.
  cv::Point2d offset{0, 0};    // Sub-pixel offset from it.
  double similarity = 0;       // Map value at the integer best (higher is better), for ranking.
  double score = 0;            // The reported score (see the header).
  double zncc = 1;             // ZNCC at the same placement (= score for ZNCC).
  double rival_zncc = kNoRival;  // ZNCC of the best distinct second peak in the region.
  bool on_inner_edge = false;  // Best on a window edge that is not the frame's: may lie outside.
};

// The first template at one scale: a rung of the scale ladder.
struct Rung {
  bool tried = false;      // Preparation attempted (templ empty: this scale is impossible).
  PreparedTemplate templ;  // Masked like the working template.
  cv::Point2d anchor;      // The reported point, in this rung's template coordinates.
};

// The first template's measurement of the marker, in frame coordinates.
struct Fix {
  cv::Point2d centre;    // The matched rung's geometric centre (where the next search looks).
  cv::Point2d reported;  // The rung's anchor: the position reported.
  double zncc = 0;       // ZNCC with the first template at that scale.
  double score = 0;      // The measure's score against it (see the header).
};

class TemplateTracker final : public Tracker {
 public:
  explicit TemplateTracker(const TemplateParams& params) : params_(params) {
    params_.image = params.image.clone();  // Own the pixels; the spec may change later.
  }

  void init(const cv::Mat& frame_bgr, const cv::Rect& hint) override;
  bool start(const Frame& frame) override;
  Observation update(const cv::Mat& frame_bgr) override;
  void reset() override {
    tracking_ = false;
    last_centre_.reset();
    velocity_px_ = {0, 0};
    repeats_ = 0;
    lost_frames_ = 0;
  }

 private:
  bool adapts() const { return params_.update_rate > 0; }
  // The template searched with: the updated one, or the first template at the current scale.
  const PreparedTemplate& search_template() const {
    return adapts() ? working_ : rungs_[rung_].templ;
  }
  void ToNative(const cv::Mat& frame, cv::Mat& out) const;
  void ConvertAround(const cv::Mat& frame, const cv::Rect& rect);
  void Native(const cv::Mat& frame, const cv::Rect& rect, cv::Mat& out);
  // The one channel the blob is measured in: native gray, or colour projected on its axis.
  void BlobChannel(const cv::Mat& native, cv::Mat& out) const {
    BlobChannelOf(native, blob_projection_, out);
  }
  std::optional<cv::Point2d> BlobShift(const cv::Mat& frame, const Fix& fix);
  // Whether `templ` (native) would show its marker's blob, as SetTemplate learns it; changes
  // nothing.
  bool ShowsAMarker(const cv::Mat& templ) const;
  // A point of the selected template in a rung of `size`. Template coordinates scale about the
  // pixel edges: u' + 0.5 = (u + 0.5) * size'/size.
  cv::Point2d ToRung(const cv::Point2d& p, const cv::Size& size) const {
    return {(p.x + 0.5) * size.width / original_.cols - 0.5,
            (p.y + 0.5) * size.height / original_.rows - 0.5};
  }
  cv::Mat MaskFor(const cv::Size& size) const {
    return params_.round_mask ? RoundMask(size) : cv::Mat();
  }
  void SetTemplate(const cv::Mat& templ, const std::string& where);
  const Rung* RungAt(int index);
  void Similarity(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& sim);
  double ScoreOf(double similarity) const;
  bool Accept(const Hit& m) const;
  cv::Rect WindowAround(const cv::Point2d& centre_px, const cv::Size& size, int margin_px) const;
  std::optional<Hit> Search(const cv::Mat& frame, cv::Rect region, const PreparedTemplate& templ,
                            bool find_rival);
  std::optional<Hit> Refine(const cv::Mat& frame, cv::Point top_left);
  std::optional<Hit> Acquire(const cv::Mat& frame);
  std::optional<Fix> Measure(const cv::Mat& frame, const cv::Point2d& centre_px);
  double RungZncc(const cv::Mat& frame, int index, const cv::Point2d& centre_px);
  void UpdateScale(const cv::Mat& frame, const Fix& fix);
  void UpdateTemplate(const cv::Mat& frame, const cv::Point2d& centre_px);
  void RestoreWorkingTemplate();
  void ScanForLookAlikes(const cv::Mat& frame, const cv::Point2d& centre_px);
  double rung_scale() const { return std::pow(kScaleStep, rung_ - kRungsBelow); }
  Observation Lose(MarkerStatus why, int candidates = 0) {
    tracking_ = false;  // Keep last_centre_: the next acquisition looks around it.
    velocity_px_ = {0, 0};
    repeats_ = 0;
    ++lost_frames_;
    return Observation::NotFound(why, candidates);
  }

  TemplateParams params_;
  cv::Mat original_;                    // The selected template, native (gray or BGR).
  cv::Point2d anchor_px_{0, 0};         // The reported point, in the selected template.
  std::vector<Rung> rungs_;             // The scale ladder; [kRungsBelow] is the selection.
  int rung_ = 0;                        // The current scale.
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
  double look_alike_px_ = std::numeric_limits<double>::infinity();
  bool scan_pending_ = false;           // Scan for look-alikes at the first match after a hint.

  // Buffers reused from frame to frame.
  cv::Mat region_, fine_, raw_, sim_, fine_sim_, rung_sim_, patch_, resized_, candidate_, shape_;
  // The frame around the marker in the matched channel(s), converted once per update: the
  // search, the measurement, the scale search and the template update each look at a window of
  // it (they overlap; converting each on its own was a seventh of the tracker's time).
  cv::Mat native_;
  cv::Rect native_rect_;  // Where native_ lies in the frame; empty when not converted.
  std::vector<cv::Mat> levels_;
  std::vector<cv::Point> candidates_;
  cv::Mat level_sim_;
  cv::Mat projection_;  // Gray only: 1x4 BGR weights + offset, or empty for plain luma.
  ZnccScratch zncc_;
  // The marker's blob in the template: every match is verified against it (BlobShift).
  BlobMeter blob_;
  bool blob_ok_ = false;                // The template shows a blob (its foreground).
  cv::Point2d blob_anchor_px_{0, 0};    // Its soft centroid, in the selected template.
  cv::Mat blob_projection_;  // Colour: BGR weights giving the blob channel; else empty.
  cv::Mat blob_native_, blob_gray_;
};

// Converts the part `rect` of the frame (clipped to it) for the windows of this update.
void TemplateTracker::ConvertAround(const cv::Mat& frame, const cv::Rect& rect) {
  native_rect_ = rect & cv::Rect(0, 0, frame.cols, frame.rows);
  if (native_rect_.empty()) return;
  ToNative(frame(native_rect_), native_);
}

// The window `rect` of the frame in the matched channel(s): a view of the part converted this
// update when it covers the window (the conversion is per pixel, so the values are the same),
// else converted on its own.
void TemplateTracker::Native(const cv::Mat& frame, const cv::Rect& rect, cv::Mat& out) {
  if (!native_rect_.empty() && (rect & native_rect_) == rect) {
    out = native_(rect - native_rect_.tl());
    return;
  }
  // `out` may still be a view of native_: converting into it would overwrite that.
  if (!out.empty() && out.datastart == native_.datastart) out.release();
  ToNative(frame(rect), out);
}

void TemplateTracker::ToNative(const cv::Mat& frame, cv::Mat& out) const {
  if (frame.channels() == 1) {
    if (params_.colour) {
      cv::cvtColor(frame, out, cv::COLOR_GRAY2BGR);
    } else {
      out = frame;  // A mono camera: the gray is the image (a header only).
    }
  } else if (params_.colour) {
    out = frame;  // A header only: the kernels read strided regions.
  } else if (!projection_.empty()) {
    cv::transform(frame, out, projection_);
  } else {
    cv::cvtColor(frame, out, cv::COLOR_BGR2GRAY);
  }
}

// The single channel that shows the template best: BGR projected on the template's principal
// colour axis (the direction of largest colour variance, i.e. marker against band), with weights
// of L1 norm 1 and an offset that keeps every value in 0..255. On a gray template (B = G = R, a
// mono camera) the axis is (1, 1, 1) / 3: the channel mean, which is luma there.
cv::Mat ContrastProjection(const cv::Mat& bgr) {
  const cv::Mat samples = bgr.clone().reshape(1, static_cast<int>(bgr.total()));
  cv::Mat covariance, mean;
  cv::calcCovarMatrix(samples, covariance, mean,
                      cv::COVAR_NORMAL | cv::COVAR_ROWS | cv::COVAR_SCALE, CV_64F);
  cv::Mat values, vectors;
  cv::eigen(covariance, values, vectors);
  cv::Vec3d axis(vectors.at<double>(0, 0), vectors.at<double>(0, 1), vectors.at<double>(0, 2));
  const double l1 = std::abs(axis[0]) + std::abs(axis[1]) + std::abs(axis[2]);
  if (!(l1 > 0)) return {};
  if (axis[0] + axis[1] + axis[2] < 0) axis = -axis;  // Mostly positive: light stays light.
  axis /= l1;
  double offset = 0;
  for (int c = 0; c < 3; ++c) offset -= 255.0 * std::min(0.0, axis[c]);
  cv::Mat m = (cv::Mat_<float>(1, 4) << axis[0], axis[1], axis[2], offset);
  return m;
}

// The marker's blob in a selected template (its foreground): the channel it shows best
// (`projection`: ContrastProjection on colour, else empty) and the blob learned in it. False
// when the template shows none.
bool LearnTemplateBlob(const cv::Mat& templ, const cv::Mat& mask, cv::Mat* projection,
                       BlobMeter* meter, cv::Point2d* anchor) {
  *projection = templ.channels() == 3 ? ContrastProjection(templ) : cv::Mat();
  cv::Mat gray;
  BlobChannelOf(templ, *projection, gray);
  return meter->Learn(gray, mask, anchor);
}

void TemplateTracker::SetTemplate(const cv::Mat& templ, const std::string& where) {
  if (templ.cols < kMinTemplatePx || templ.rows < kMinTemplatePx) {
    throw InputError(where + ": template is " + std::to_string(templ.cols) + "x" +
                     std::to_string(templ.rows) + " px, at least 3x3 is needed");
  }
  if (static_cast<int>(templ.total()) * templ.channels() > kMaxTemplateValues ||
      templ.cols * templ.channels() > kMaxTemplateRowBytes) {
    throw InputError(where + ": template " + std::to_string(templ.cols) + "x" +
                     std::to_string(templ.rows) + " is too large (at most " +
                     std::to_string(kMaxTemplateValues) + " pixels x channels)");
  }
  PreparedTemplate first;
  if (!first.Prepare(templ, MaskFor(templ.size()))) {
    throw InputError(where +
                     ": template has no contrast (all pixels equal); select the marker "
                     "with some background around it");
  }
  original_ = templ.clone();
  anchor_px_ = HalfSize(templ.size());
  // The marker's blob in the template (its foreground), whatever point is reported: every
  // match must contain it (see BlobShift).
  blob_ok_ = LearnTemplateBlob(templ, MaskFor(templ.size()), &blob_projection_, &blob_,
                               &blob_anchor_px_);
  if (params_.report == TemplateReport::kCentre && blob_ok_) anchor_px_ = blob_anchor_px_;
  if (params_.report == TemplateReport::kSymmetry ||
      (params_.report == TemplateReport::kCentre && !blob_ok_)) {
    // The turned template is matched unmasked: a mask shrunk with it would cut the rim of a
    // disc, which is what carries its position.
    double strength = 0.0;
    const cv::Point2d centre = SymmetryCentre(templ, &strength);
    if (strength >= kMinSymmetry) anchor_px_ = centre;
  }
  rungs_.assign(kRungsBelow + 1 + kRungsAbove, Rung());  // Never resized: RungAt's references stay.
  rung_ = kRungsBelow;
  Rung& selected = rungs_[rung_];
  selected.tried = true;
  selected.templ = std::move(first);
  selected.anchor = anchor_px_;
  RestoreWorkingTemplate();
}

// The rung `index` of the ladder, prepared on first use; nullptr when that scale is impossible.
const Rung* TemplateTracker::RungAt(int index) {
  if (index < 0 || index >= static_cast<int>(rungs_.size())) return nullptr;
  Rung& rung = rungs_[index];
  if (!rung.tried) {
    rung.tried = true;
    const double scale = std::pow(kScaleStep, index - kRungsBelow);
    const cv::Size size(static_cast<int>(std::lround(original_.cols * scale)),
                        static_cast<int>(std::lround(original_.rows * scale)));
    if (std::min(size.width, size.height) >= kMinRungPx &&
        static_cast<int>(size.area()) * original_.channels() <= kMaxTemplateValues &&
        size.width * original_.channels() <= kMaxTemplateRowBytes) {
      cv::Mat scaled;
      cv::resize(original_, scaled, size, 0, 0, scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
      if (rung.templ.Prepare(scaled, MaskFor(size))) {
        rung.anchor = ToRung(anchor_px_, size);
      }
    }
  }
  return rung.templ.empty() ? nullptr : &rung;
}

void TemplateTracker::RestoreWorkingTemplate() {
  const PreparedTemplate& rung = rungs_[rung_].templ;
  working_.Prepare(rung.image(), rung.mask());
  working_mask_ = rung.mask().empty() ? cv::Mat() : rung.mask().clone();
  rung.image().convertTo(working_f_, CV_32F);
  coarse_.clear();
}

bool TemplateTracker::start(const Frame& frame) {
  if (!params_.image.empty() && !params_.rect) {
    init(frame.image, cv::Rect());  // The template is given: the first update searches for it.
    return true;
  }
  if (!params_.image.empty() && frame.index >= params_.template_frame) {
    // An image selected at rect on its frame (a template reselected live and saved): tracking
    // starts there, then, as it did live.
    init(frame.image, cv::Rect());
    return true;
  }
  if (params_.rect && frame.index >= params_.template_frame) {
    init(frame.image, *params_.rect);  // Cut from this frame, where the config says it is.
    return true;
  }
  return false;
}

bool TemplateTracker::ShowsAMarker(const cv::Mat& templ) const {
  cv::Mat projection;
  BlobMeter meter;
  cv::Point2d centroid;
  return LearnTemplateBlob(templ, MaskFor(templ.size()), &projection, &meter, &centroid);
}

void TemplateTracker::init(const cv::Mat& frame_bgr, const cv::Rect& hint) {
  CV_Assert(frame_bgr.type() == CV_8UC3 || frame_bgr.type() == CV_8UC1);
  if (!hint.empty()) {
    const cv::Rect frame_rect(0, 0, frame_bgr.cols, frame_bgr.rows);
    if ((hint & frame_rect) != hint) {
      throw InputError("template rect " + RectText(hint) + " is not inside the " +
                       std::to_string(frame_bgr.cols) + "x" + std::to_string(frame_bgr.rows) +
                       " frame");
    }
    const cv::Mat previous = projection_;  // Kept if the new selection is refused.
    projection_.release();
    if (!params_.colour && params_.contrast_gray && frame_bgr.channels() == 3) {
      projection_ = ContrastProjection(frame_bgr(hint));
    }
    cv::Mat native;
    ToNative(frame_bgr(hint), native);
    try {
      // A box a person drags must hold a marker: a blob at its centre, wholly inside it and
      // standing out from its surroundings. A box of background (or cutting a marker) would be
      // matched wherever that background looks alike, and never lost.
      if (!ShowsAMarker(native)) {
        throw InputError("the box " + RectText(hint) + " holds no marker (nothing at its centre "
                         "stands out from its surroundings): drag it around a marker, with some "
                         "background on every side");
      }
      SetTemplate(native.clone(), "template rect " + RectText(hint));
    } catch (const InputError&) {
      projection_ = previous;
      throw;
    }
    // The person showed where the marker is on this frame: the first update looks right there,
    // in a tracking window, not in a wide search that may hold look-alikes.
    last_centre_ = cv::Point2d(hint.x, hint.y) + HalfSize(hint.size());
    tracking_ = true;
    scan_pending_ = true;
  } else {
    const std::string where = "template image";
    if (params_.image.empty()) {
      throw InputError(
          "template: none given (set template.rect or template.file, or select the "
          "marker on a frame)");
    }
    cv::Mat native;
    const cv::Mat previous = projection_;  // Kept if the image is refused.
    projection_.release();
    if (params_.image.type() == CV_8UC3) {
      if (!params_.colour && params_.contrast_gray) projection_ = ContrastProjection(params_.image);
      ToNative(params_.image, native);
    } else if (params_.image.type() == CV_8UC1 && !params_.colour) {
      native = params_.image;
    } else {
      projection_ = previous;
      throw InputError(where + " must be 8-bit BGR" +
                       std::string(params_.colour ? " for colour matching" : " or gray"));
    }
    try {
      SetTemplate(native.clone(), where);
    } catch (const InputError&) {
      projection_ = previous;
      throw;
    }
    if (params_.rect) {
      // The image was selected at `rect` on the reference frame (a template reselected live and
      // saved): the tracker starts there, as it did when the selection was made.
      last_centre_ = cv::Point2d(params_.rect->x, params_.rect->y) + HalfSize(params_.rect->size());
      tracking_ = true;
    } else {
      last_centre_.reset();  // Position unknown: the first update searches the whole frame.
      tracking_ = false;
    }
    scan_pending_ = true;
  }
  velocity_px_ = {0, 0};
  repeats_ = 0;
  lost_frames_ = 0;
  look_alike_px_ = std::numeric_limits<double>::infinity();
}

// Looks once around the marker (acquire_radius_px) for other places the template fits nearly as
// well: the nearest one's distance bounds every later re-acquisition.
void TemplateTracker::ScanForLookAlikes(const cv::Mat& frame, const cv::Point2d& centre_px) {
  const PreparedTemplate& templ = search_template();
  const cv::Size size = templ.size();
  const int radius = params_.acquire_radius_px > 0 ? params_.acquire_radius_px
                                                   : std::max(frame.cols, frame.rows);
  const cv::Rect region = WindowAround(centre_px, size, radius) & cv::Rect(0, 0, frame.cols, frame.rows);
  if (region.width < size.width || region.height < size.height) return;
  Native(frame, region, region_);
  MatchZncc(region_, templ, sim_, zncc_);
  const cv::Point2d own = centre_px - HalfSize(size) - cv::Point2d(region.tl());
  const int distinct = std::max(2, std::min(size.width, size.height) / 2);
  // A look-alike is a place the tracker would accept as its marker (ZNCC >= min_zncc): a corner
  // of the cart that carries a small dot scores 0.7 against it, and taking it for a look-alike
  // held re-acquisition too close to follow the dot at 30 px a frame.
  const double floor = params_.min_zncc;
  for (int y = 0; y < sim_.rows; ++y) {
    const float* row = sim_.ptr<float>(y);
    for (int x = 0; x < sim_.cols; ++x) {
      if (!(row[x] >= floor)) continue;
      const double d = std::hypot(x - own.x, y - own.y);
      if (d <= distinct || d >= look_alike_px_) continue;
      bool peak = true;  // A local maximum (3x3).
      for (int dy = -1; dy <= 1 && peak; ++dy) {
        for (int dx = -1; dx <= 1 && peak; ++dx) {
          const int yy = y + dy, xx = x + dx;
          if (yy < 0 || xx < 0 || yy >= sim_.rows || xx >= sim_.cols) continue;
          peak = !(sim_.at<float>(yy, xx) > row[x]);
        }
      }
      if (peak) look_alike_px_ = d / rung_scale();
    }
  }
}

void TemplateTracker::Similarity(const cv::Mat& image, const PreparedTemplate& templ,
                                 cv::Mat& sim) {
  const double per_value = 1.0 / templ.values();
  switch (params_.measure) {
    case MatchMeasure::kSad:
      MatchSad(image, templ, raw_);
      raw_.convertTo(sim, CV_32F, -per_value);  // Minus the mean absolute difference.
      break;
    case MatchMeasure::kSsd:
      MatchSsd(image, templ, raw_, zncc_);
      raw_.convertTo(sim, CV_32F, -per_value);  // Minus the mean squared difference.
      break;
    case MatchMeasure::kZncc: MatchZncc(image, templ, sim, zncc_); break;
  }
}

double TemplateTracker::ScoreOf(double similarity) const {
  switch (params_.measure) {
    case MatchMeasure::kSad: return -similarity;
    case MatchMeasure::kSsd: return std::sqrt(std::max(0.0, -similarity));
    case MatchMeasure::kZncc: return similarity;
  }
  return similarity;
}

bool TemplateTracker::Accept(const Hit& m) const {
  if (!(m.zncc >= params_.min_zncc)) return false;
  switch (params_.measure) {
    case MatchMeasure::kSad: return m.score <= params_.max_sad;
    case MatchMeasure::kSsd: return m.score <= params_.max_ssd;
    case MatchMeasure::kZncc: return true;
  }
  return false;
}

cv::Rect TemplateTracker::WindowAround(const cv::Point2d& centre_px, const cv::Size& size,
                                       int margin_px) const {
  const cv::Point2d top_left = centre_px - HalfSize(size);
  return {static_cast<int>(std::lround(top_left.x)) - margin_px,
          static_cast<int>(std::lround(top_left.y)) - margin_px, size.width + 2 * margin_px,
          size.height + 2 * margin_px};
}

std::optional<Hit> TemplateTracker::Search(const cv::Mat& frame, cv::Rect region,
                                           const PreparedTemplate& templ, bool find_rival) {
  const cv::Size size = templ.size();
  region &= cv::Rect(0, 0, frame.cols, frame.rows);
  if (region.width < size.width || region.height < size.height) return std::nullopt;
  Native(frame, region, region_);
  Similarity(region_, templ, sim_);
  cv::Point best;
  if (!BestIn(sim_, &best)) return std::nullopt;
  Hit m;
  m.top_left = region.tl() + best;
  m.offset = SubPixel(sim_, best, params_.measure == MatchMeasure::kSad);
  m.similarity = sim_.at<float>(best);
  m.score = ScoreOf(m.similarity);
  // SAD and SSD alone accept any patch whose grey levels are close enough, e.g. a smooth
  // background patch once the light has changed: one ZNCC at the best placement checks shape.
  m.zncc = params_.measure == MatchMeasure::kZncc ? m.score
                                                  : ZnccAt(region_, best, templ, shape_, zncc_);
  cv::Point rival;
  if (find_rival && params_.ambiguity_margin > 0 &&
      RivalIn(sim_, best, std::max(2, std::min(size.width, size.height) / 2), &rival)) {
    m.rival_zncc = params_.measure == MatchMeasure::kZncc
                       ? sim_.at<float>(rival)
                       : ZnccAt(region_, rival, templ, shape_, zncc_);
  }
  m.on_inner_edge =
      (best.x == 0 && region.x > 0) || (best.x == sim_.cols - 1 && region.br().x < frame.cols) ||
      (best.y == 0 && region.y > 0) || (best.y == sim_.rows - 1 && region.br().y < frame.rows);
  return m;
}

// A small full-resolution search around `top_left`, re-centred while the peak sits on its edge.
std::optional<Hit> TemplateTracker::Refine(const cv::Mat& frame, cv::Point top_left) {
  const PreparedTemplate& templ = search_template();
  const cv::Size size = templ.size();
  std::optional<Hit> m;
  for (int i = 0; i <= kMaxRecentre; ++i) {
    m = Search(frame,
               cv::Rect(top_left.x - kRefineMarginPx, top_left.y - kRefineMarginPx,
                        size.width + 2 * kRefineMarginPx, size.height + 2 * kRefineMarginPx),
               templ, false);
    if (!m || !m->on_inner_edge) return m;
    top_left = m->top_left;
  }
  return std::nullopt;  // Still climbing: no clear peak here.
}

// Searches the region around the last known position (the whole frame without one), which
// grows by search_margin_px per frame lost, coarse-to-fine. The best is returned with the best
// distinct rival it had, so the caller can refuse an ambiguous acquisition.
std::optional<Hit> TemplateTracker::Acquire(const cv::Mat& frame) {
  const PreparedTemplate& templ = search_template();
  const cv::Size size = templ.size();
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  cv::Rect region = frame_rect;
  if (last_centre_) {
    int64_t limit = params_.acquire_radius_px > 0 ? params_.acquire_radius_px
                                                  : std::max(frame.cols, frame.rows);
    if (std::isfinite(look_alike_px_)) {
      limit = std::min<int64_t>(
          limit, std::max<int64_t>(params_.search_margin_px,
                                   static_cast<int64_t>(0.5 * look_alike_px_ * rung_scale())));
    }
    // The whole radius at once: a marker that outran the tracking window (a cart at 30 px a
    // frame from rest) moves on while a region growing by a margin per frame follows it. A
    // look-alike inside the radius makes the search ambiguous, and the session's motion gate
    // judges where the match lies.
    region = WindowAround(*last_centre_ + velocity_px_, size, static_cast<int>(limit)) &
             frame_rect;
  }
  if (region.width < size.width || region.height < size.height) return std::nullopt;

  // The acquisition pyramid of the search template, rebuilt when that template changed.
  if (coarse_.empty()) {
    coarse_.resize(1);
    cv::Mat level = templ.image();
    for (int l = 1; l < params_.pyramid_levels; ++l) {
      cv::Mat down;
      cv::pyrDown(level, down);
      if (std::min(down.cols, down.rows) < kMinCoarseTemplatePx) break;
      PreparedTemplate prepared;
      if (!prepared.Prepare(down, MaskFor(down.size()))) break;
      coarse_.push_back(std::move(prepared));
      level = down;
    }
  }
  auto pyramid = [&](int l) -> const PreparedTemplate& { return l == 0 ? templ : coarse_[l]; };
  int levels = 1;
  while (levels < static_cast<int>(coarse_.size()) &&
         (region.width >> levels) >= coarse_[levels].size().width + 2 &&
         (region.height >> levels) >= coarse_[levels].size().height + 2) {
    ++levels;
  }
  if (levels == 1) {
    std::optional<Hit> m = Search(frame, region, templ, true);
    // The peak on the acquisition region's edge is still the best there is inside it.
    if (m) m->on_inner_edge = false;
    return m;
  }

  levels_.resize(levels);
  ToNative(frame(region), levels_[0]);
  for (int l = 1; l < levels; ++l) cv::pyrDown(levels_[l - 1], levels_[l]);
  const int top = levels - 1;
  Similarity(levels_[top], pyramid(top), sim_);

  // The best few separated peaks at the coarsest level, each refined level by level.
  std::vector<cv::Point>& candidates = candidates_;
  candidates.clear();
  const cv::Size coarse = pyramid(top).size();
  for (int k = 0; k < kCandidates; ++k) {
    cv::Point at;
    if (!BestIn(sim_, &at)) break;
    candidates.push_back(at);
    const cv::Rect suppress(at.x - coarse.width / 2, at.y - coarse.height / 2, coarse.width + 1,
                            coarse.height + 1);
    sim_(suppress & cv::Rect(0, 0, sim_.cols, sim_.rows))
        .setTo(std::numeric_limits<float>::quiet_NaN());
  }
  std::vector<Hit> hits;
  hits.reserve(kCandidates);
  for (cv::Point p : candidates) {
    int level = top;  // The level `p` is in.
    for (int l = top - 1; l >= 1; --l) {
      const cv::Size ts = pyramid(l).size();
      const cv::Rect window =
          cv::Rect(2 * p.x - kRefineMarginPx, 2 * p.y - kRefineMarginPx,
                   ts.width + 2 * kRefineMarginPx, ts.height + 2 * kRefineMarginPx) &
          cv::Rect(0, 0, levels_[l].cols, levels_[l].rows);
      if (window.width < ts.width || window.height < ts.height) break;
      Similarity(levels_[l](window), pyramid(l), level_sim_);
      cv::Point at;
      if (!BestIn(level_sim_, &at)) break;
      p = window.tl() + at;
      level = l;
    }
    std::optional<Hit> m = Refine(frame, region.tl() + p * (1 << level));
    if (m) hits.push_back(*m);
  }
  if (hits.empty()) return std::nullopt;
  size_t best = 0;
  for (size_t i = 1; i < hits.size(); ++i) {
    if (hits[i].similarity > hits[best].similarity) best = i;
  }
  Hit m = hits[best];
  const int distinct = std::max(2, std::min(size.width, size.height) / 2);
  for (size_t i = 0; i < hits.size(); ++i) {
    const cv::Point d = hits[i].top_left - m.top_left;
    if (std::abs(d.x) > distinct || std::abs(d.y) > distinct) {
      m.rival_zncc = std::max(m.rival_zncc, hits[i].zncc);
    }
  }
  return m;
}

// Drift correction: the first template at the current scale, matched in a small window around
// the working template's match, gives the position (and, by its ZNCC, says whether the patch is
// still the marker). Empty when the first template's peak is not inside that window: the
// working template and the first disagree about where the marker is.
std::optional<Fix> TemplateTracker::Measure(const cv::Mat& frame, const cv::Point2d& centre_px) {
  const Rung& rung = rungs_[rung_];
  const cv::Size size = rung.templ.size();
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  const cv::Rect window = WindowAround(centre_px, size, kFineMarginPx) & frame_rect;
  if (window.width < size.width || window.height < size.height) return std::nullopt;
  Native(frame, window, fine_);
  Similarity(fine_, rung.templ, fine_sim_);
  cv::Point best;
  if (!BestIn(fine_sim_, &best)) return std::nullopt;
  const bool inner_edge = (best.x == 0 && window.x > 0) ||
                          (best.x == fine_sim_.cols - 1 && window.br().x < frame.cols) ||
                          (best.y == 0 && window.y > 0) ||
                          (best.y == fine_sim_.rows - 1 && window.br().y < frame.rows);
  if (inner_edge) return std::nullopt;
  const cv::Point2d top_left =
      cv::Point2d(window.tl() + best) +
      SubPixel(fine_sim_, best, params_.measure == MatchMeasure::kSad);
  Fix fix;
  fix.centre = top_left + HalfSize(size);
  fix.reported = top_left + rung.anchor;
  fix.score = ScoreOf(fine_sim_.at<float>(best));
  if (params_.measure != MatchMeasure::kZncc) {
    // Grey levels compared at the sub-pixel position: at the integer placement a sharp edge
    // half a pixel off already differs by tens of levels on a high-contrast marker.
    cv::getRectSubPix(fine_, size, fix.centre - cv::Point2d(window.tl()), patch_, CV_32F);
    rung.templ.image().convertTo(resized_, CV_32F);
    cv::absdiff(patch_, resized_, patch_);
    if (params_.measure == MatchMeasure::kSsd) cv::multiply(patch_, patch_, patch_);
    const cv::Scalar per_channel = rung.templ.mask().empty() ? cv::mean(patch_)
                                                             : cv::mean(patch_, rung.templ.mask());
    const int cn = patch_.channels();
    double mean = 0;
    for (int c = 0; c < cn; ++c) mean += per_channel[c] / cn;
    fix.score = params_.measure == MatchMeasure::kSsd ? std::sqrt(mean) : mean;
  }
  fix.zncc = params_.measure == MatchMeasure::kZncc
                 ? fine_sim_.at<float>(best)
                 : ZnccAt(fine_, best, rung.templ, shape_, zncc_);
  return fix;
}

// The best ZNCC of rung `index` within a pixel of being centred on `centre_px`; -inf when the
// rung does not exist or does not fit in the frame there.
double TemplateTracker::RungZncc(const cv::Mat& frame, int index, const cv::Point2d& centre_px) {
  const Rung* rung = RungAt(index);
  if (!rung) return kNoRival;
  const cv::Size size = rung->templ.size();
  const cv::Rect window = WindowAround(centre_px, size, 1);
  if ((window & cv::Rect(0, 0, frame.cols, frame.rows)) != window) return kNoRival;
  Native(frame, window, fine_);
  MatchZncc(fine_, rung->templ, rung_sim_, zncc_);
  cv::Point best;
  return BestIn(rung_sim_, &best) ? rung_sim_.at<float>(best) : kNoRival;
}

// Scale search: the neighbouring rungs of the ladder against the current one, at the match.
void TemplateTracker::UpdateScale(const cv::Mat& frame, const Fix& fix) {
  const double here = RungZncc(frame, rung_, fix.centre);
  if (!std::isfinite(here)) return;
  const double smaller = RungZncc(frame, rung_ - 1, fix.centre);
  const double larger = RungZncc(frame, rung_ + 1, fix.centre);
  const int step = larger >= smaller ? 1 : -1;
  if (std::max(smaller, larger) <= here + kScaleHysteresis) return;
  rung_ += step;
  if (!adapts()) coarse_.clear();  // The search template changed.
}

// How far to move the match onto the marker's blob (the template's foreground), so the position
// follows the marker, not the background around it. Zero when the blob lies within
// kBlobAgreePx of where the match puts it (a blob's centroid is less precise than the match of a
// template that shows the marker well), except with report: centre, whose position is the blob's
// soft centroid in every frame. A template mostly of background (a box dragged around a small sticker on a tyre)
// matches the tyre well after the sticker has moved on along it. Empty when the blob is not in
// the match: no component of the marker's side within 2 px of where the template puts it, one
// merged with its surroundings (it reaches the patch's edge), one whose area is far from the
// learned blob's at this scale, or one farther than a quarter of the template.
std::optional<cv::Point2d> TemplateTracker::BlobShift(const cv::Mat& frame, const Fix& fix) {
  const Rung& rung = rungs_[rung_];
  const cv::Size size = rung.templ.size();
  const cv::Rect at = WindowAround(fix.centre, size, 0);
  if ((at & cv::Rect(0, 0, frame.cols, frame.rows)) != at) return std::nullopt;
  Native(frame, at, blob_native_);
  BlobChannel(blob_native_, blob_gray_);
  // Where the template puts its blob (patch coordinates): the learned centroid at this rung.
  const cv::Point2d expected =
      fix.centre - HalfSize(size) - cv::Point2d(at.tl()) + ToRung(blob_anchor_px_, size);
  cv::Point2d centroid;
  double area = 0;
  if (!blob_.Locate(blob_gray_, rung.templ.mask(), expected, &centroid, &area)) {
    return std::nullopt;
  }
  const double learned = blob_.area() * rung_scale() * rung_scale();
  if (!(area >= kMinBlobAreaRatio * learned && area <= learned / kMinBlobAreaRatio)) {
    return std::nullopt;
  }
  cv::Point2d shift = centroid - expected;
  if (params_.report != TemplateReport::kCentre && cv::norm(shift) <= kBlobAgreePx) {
    return cv::Point2d(0, 0);
  }
  // To be applied: measured with the soft centroid.
  if (!blob_.Measure(blob_gray_, rung.templ.mask(), expected, &centroid, &area)) {
    return std::nullopt;
  }
  shift = centroid - expected;
  const double reach = std::max(kMinBlobShiftPx, 0.25 * std::min(size.width, size.height));
  if (!(cv::norm(shift) <= reach)) return std::nullopt;
  return shift;
}

void TemplateTracker::UpdateTemplate(const cv::Mat& frame, const cv::Point2d& centre_px) {
  const Rung& rung = rungs_[rung_];
  const cv::Size size = rung.templ.size();
  const cv::Rect around = WindowAround(centre_px, size, 2);
  if ((around & cv::Rect(0, 0, frame.cols, frame.rows)) != around) return;
  Native(frame, around, region_);
  // getRectSubPix centres the patch on its geometric centre, which centre_px is.
  cv::getRectSubPix(region_, size, centre_px - cv::Point2d(around.tl()), patch_, CV_32F);
  if (working_f_.size() != size) {
    // The scale changed: the running template follows it before the blend.
    cv::resize(working_f_, resized_, size, 0, 0, cv::INTER_LINEAR);
    std::swap(working_f_, resized_);
    working_mask_ = rung.templ.mask().empty() ? cv::Mat() : rung.templ.mask().clone();
  }
  cv::addWeighted(working_f_, 1.0 - params_.update_rate, patch_, params_.update_rate, 0.0,
                  working_f_);
  working_f_.convertTo(candidate_, CV_8U);
  // Drift guard: the updated template must still resemble the first at this scale.
  const double similarity = ZnccAt(candidate_, {0, 0}, rung.templ, shape_, zncc_);
  if (!(similarity >= params_.drift_min_zncc) || !working_.Prepare(candidate_, working_mask_)) {
    RestoreWorkingTemplate();  // Drifted: back to the first template at this scale.
    return;
  }
  coarse_.clear();  // The acquisition pyramid is rebuilt from the new template when needed.
}

Observation TemplateTracker::update(const cv::Mat& frame_bgr) {
  CV_Assert(frame_bgr.type() == CV_8UC3 || frame_bgr.type() == CV_8UC1);
  if (rungs_.empty()) return Observation::NotFound(MarkerStatus::kNotStarted);  // No template.
  const cv::Rect frame_rect(0, 0, frame_bgr.cols, frame_bgr.rows);
  native_rect_ = cv::Rect();  // A new frame: nothing converted yet.
  std::optional<Hit> hit;
  if (tracking_) {
    cv::Rect window = WindowAround(*last_centre_ + velocity_px_, search_template().size(),
                                   params_.search_margin_px);
    if (footage_repeats_) {
      window |= WindowAround(*last_centre_, search_template().size(), params_.search_margin_px);
    }
    if ((window & frame_rect).empty()) return Lose(MarkerStatus::kOutOfFrame);
    // The window and a little around it: the later windows (the measurement, kFineMarginPx
    // around the match; the neighbouring rungs of the scale search; the template update's
    // patch) lie in it while the marker is found near where it was predicted, which is most
    // frames; one that does not is converted on its own. (Converting all of them, kFineMarginPx
    // and more around the whole window, cost more than the few it saves.)
    constexpr int kAroundPx = 2;
    ConvertAround(frame_bgr, cv::Rect(window.x - kAroundPx, window.y - kAroundPx,
                                      window.width + 2 * kAroundPx, window.height + 2 * kAroundPx));
    hit = Search(frame_bgr, window, search_template(), true);
    // Moving faster than the window (its best is on the window's edge, or is no match at all
    // because the marker left it): acquire.
    if (hit && (hit->on_inner_edge || !Accept(*hit))) hit.reset();
  }
  if (!hit) hit = Acquire(frame_bgr);
  if (!hit || !Accept(*hit)) return Lose(MarkerStatus::kLost);
  if (params_.ambiguity_margin > 0 && hit->rival_zncc >= hit->zncc - params_.ambiguity_margin) {
    return Lose(MarkerStatus::kAmbiguous, 2);
  }
  if (scan_pending_) {
    scan_pending_ = false;
    ScanForLookAlikes(frame_bgr, cv::Point2d(hit->top_left) + HalfSize(search_template().size()));
  }
  const cv::Point2d matched = cv::Point2d(hit->top_left) + hit->offset +
                              HalfSize(search_template().size());
  const std::optional<Fix> fix = Measure(frame_bgr, matched);
  // SAD and SSD compare grey levels with the first template too: they do not cancel a change of
  // light, and a position they measure against a template the light has left is biased.
  const bool levels_fit = fix && (params_.measure == MatchMeasure::kZncc ||
                                  fix->score <= (params_.measure == MatchMeasure::kSad
                                                     ? params_.max_sad
                                                     : params_.max_ssd));
  if (!fix || !levels_fit || !(fix->zncc >= params_.drift_min_zncc)) {
    if (adapts()) RestoreWorkingTemplate();  // The working template may have drifted.
    return Lose(MarkerStatus::kLost);
  }
  // The template's blob must be in the match, and the match follows it: a template that holds
  // more background than marker is otherwise found on the background the marker has left.
  Fix at = *fix;
  if (blob_ok_) {
    const std::optional<cv::Point2d> shift = BlobShift(frame_bgr, at);
    if (!shift) {
      if (adapts()) RestoreWorkingTemplate();
      return Lose(MarkerStatus::kLost);
    }
    at.centre += *shift;
    at.reported += *shift;
  }
  const cv::Point2d step = tracking_ ? at.centre - *last_centre_ : cv::Point2d(0, 0);
  if (tracking_ && IsRepeatedFrame(step, velocity_px_, repeats_)) {
    ++repeats_;  // A repeated frame: the velocity is the next new frame's.
    footage_repeats_ = true;
  } else {
    repeats_ = 0;
    velocity_px_ = step;
  }
  last_centre_ = at.centre;
  tracking_ = true;
  lost_frames_ = 0;
  if (params_.scale_search) UpdateScale(frame_bgr, at);
  if (adapts()) UpdateTemplate(frame_bgr, at.centre);
  Observation observation;
  observation.position_px = at.reported;
  observation.score = hit->score;
  return observation;
}

}  // namespace

bool TemplateParams::Check(std::string* error) const {
  // Each field's range is in its table row (track/template_options.cc); only rules across fields
  // are written here.
  if (const auto problem = CheckOptions(TemplateParamsOptions(), *this)) {
    return Fail(error, *problem);
  }
  if (rect && !image.empty() && rect->size() != image.size()) {
    // With an image, rect says where it was selected: the image's own size.
    return Fail(error, "template.rect: " + RectText(*rect) + " is not the size of the image (" +
                           std::to_string(image.cols) + "x" +
                           std::to_string(image.rows) + " px)");
  }
  const int cn = colour ? 3 : 1;
  if (rect) {
    if (rect->width < kMinTemplatePx || rect->height < kMinTemplatePx) {
      return Fail(error, "template.rect: " + RectText(*rect) + " must be at least 3x3 px");
    }
    if (rect->area() * cn > kMaxTemplateValues || rect->width * cn > kMaxTemplateRowBytes) {
      return Fail(error, "template.rect: " + RectText(*rect) + " is too large (at most " +
                             std::to_string(kMaxTemplateValues / cn) + " px" +
                             (colour ? " in colour)" : ")"));
    }
  }
  return true;
}

std::unique_ptr<Tracker> CreateTemplateTracker(const TemplateParams& params) {
  std::string problem;
  if (!params.Check(&problem)) throw InputError(problem);
  return std::make_unique<TemplateTracker>(params);
}

}  // namespace softsight
