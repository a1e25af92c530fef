#include "softsight/track/template_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "softsight/track/tracker.h"
#include "track/match_kernels.h"
#include "track/track_options.h"

namespace softsight {

const char* MatchMeasureName(MatchMeasure measure) {
  switch (measure) {
    case MatchMeasure::kSad: return "sad";
    case MatchMeasure::kSsd: return "ssd";
    case MatchMeasure::kZncc: return "zncc";
  }
  return "?";
}

namespace {

constexpr int kMinTemplatePx = 3;           // Smaller templates have no sub-pixel neighbourhood.
constexpr int kMaxTemplateRowBytes = 2048;  // The SAD kernel's 16-bit accumulator limit.
constexpr int kMinCoarseTemplatePx = 8;     // Coarsest pyramid template side.
constexpr int kRefineMarginPx = 2;          // Search margin per pyramid level while refining.
constexpr int kCandidates = 3;              // Coarse peaks refined to full resolution.
constexpr int kMaxRecentre = 4;             // Re-centrings of the final window onto its peak.

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

// The highest non-NaN value of a CV_32F map; false when every value is NaN.
bool BestIn(const cv::Mat& sim, cv::Point* at);

// The point about which `templ` is most nearly point-symmetric, in template coordinates: the
// template is matched (ZNCC) against itself turned by 180 degrees; a shift d between the two puts
// the centre of symmetry at the geometric centre + d / 2. Falls back to the geometric centre.
cv::Point2d SymmetryCentre(const cv::Mat& templ) {
  const cv::Point2d centre = HalfSize(templ.size());
  const int m = std::min({3, (templ.cols - 3) / 2, (templ.rows - 3) / 2});
  if (m < 1) return centre;
  cv::Mat turned;
  cv::flip(templ, turned, -1);
  PreparedTemplate inner;
  if (!inner.Prepare(turned(cv::Rect(m, m, templ.cols - 2 * m, templ.rows - 2 * m)))) {
    return centre;
  }
  cv::Mat zncc;
  ZnccScratch scratch;
  MatchZncc(templ, inner, zncc, scratch);
  cv::Point best;
  if (!BestIn(zncc, &best)) return centre;
  cv::Point2d shift(best.x - m, best.y - m);
  if (best.x > 0 && best.x < zncc.cols - 1) {
    shift.x += PeakOffset(zncc.at<float>(best.y, best.x - 1), zncc.at<float>(best),
                          zncc.at<float>(best.y, best.x + 1), false);
  }
  if (best.y > 0 && best.y < zncc.rows - 1) {
    shift.y += PeakOffset(zncc.at<float>(best.y - 1, best.x), zncc.at<float>(best),
                          zncc.at<float>(best.y + 1, best.x), false);
  }
  return centre + 0.5 * shift;
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

struct Match {
  cv::Point2d centre_px;  // Sub-pixel template centre in frame coordinates.
  double similarity = 0;  // Map value at the integer best (higher is better), for ranking.
  double score = 0;       // The reported score (see the header).
  double zncc = 1;        // SAD/SSD: ZNCC at the same placement (the shape check); else = score.
  bool on_inner_edge = false;  // Best on a window edge that is not the frame's: may lie outside.
  cv::Point top_left;          // Integer best placement in frame coordinates.
};

class TemplateTracker final : public Tracker {
 public:
  explicit TemplateTracker(const TemplateParams& params) : params_(params) {
    params_.image = params.image.clone();  // Own the pixels; the spec may change later.
  }

  void init(const cv::Mat& frame_bgr, const cv::Rect& hint) override;
  Observation update(const cv::Mat& frame_bgr) override;
  void reset() override {
    tracking_ = false;
    last_px_.reset();
    velocity_px_ = {0, 0};
  }

 private:
  int channels() const { return params_.colour ? 3 : 1; }
  cv::Size template_size() const { return pyramid_[0].size(); }
  void ToNative(const cv::Mat& bgr, cv::Mat& out) const;
  void SetTemplate(const cv::Mat& templ, const std::string& where);
  cv::Mat MaskFor(const cv::Size& size) const;
  void Similarity(const cv::Mat& image, const PreparedTemplate& templ, cv::Mat& sim);
  double ScoreOf(double similarity) const;
  bool Accept(const Match& m) const;
  cv::Rect WindowAround(const cv::Point2d& centre_px, int margin_px) const;
  std::optional<Match> SearchWindow(const cv::Mat& frame, cv::Rect region);
  std::optional<Match> Refine(const cv::Mat& frame, cv::Point top_left);
  std::optional<Match> Acquire(const cv::Mat& frame);
  void UpdateTemplate(const cv::Mat& frame, const cv::Point2d& centre_px);

  TemplateParams params_;
  std::vector<PreparedTemplate> pyramid_;  // [0]: full resolution; [l]: pyramid level l.
  cv::Mat original_;                       // The selected template (drift guard reference).
  cv::Mat blended_;                        // CV_32F running template when update_rate > 0.
  std::optional<cv::Point2d> last_px_;     // Last known centre (last match, or the hint).
  cv::Point2d anchor_px_{0, 0};            // The reported point, in template coordinates.
  cv::Point2d velocity_px_{0, 0};          // Per frame; zero unless the last two frames matched.
  bool tracking_ = false;                  // The previous update found the marker.

  // Buffers reused from frame to frame.
  cv::Mat region_, raw_, sim_, patch_, candidate_, drift_, shape_;
  std::vector<cv::Mat> levels_;
  std::vector<cv::Point> candidates_;
  cv::Mat level_sim_, mask_;  // mask_: the level-0 round mask (or empty).
  cv::Mat projection_;        // Gray only: 1x4 BGR weights + offset, or empty for plain luma.
  PreparedTemplate updated_;
  ZnccScratch zncc_;
};

void TemplateTracker::ToNative(const cv::Mat& bgr, cv::Mat& out) const {
  if (params_.colour) {
    out = bgr;  // A header only: the kernels read strided regions.
  } else if (!projection_.empty()) {
    cv::transform(bgr, out, projection_);
  } else {
    cv::cvtColor(bgr, out, cv::COLOR_BGR2GRAY);
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

// The ellipse inscribed in the template (pixel centres within it count), or none.
cv::Mat TemplateTracker::MaskFor(const cv::Size& size) const {
  if (!params_.round_mask) return {};
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
  std::vector<PreparedTemplate> pyramid(1);
  if (!pyramid[0].Prepare(templ, MaskFor(templ.size()))) {
    throw InputError(where +
                     ": template has no contrast (all pixels equal); select the marker "
                     "with some background around it");
  }
  cv::Mat level = templ;
  for (int l = 1; l < params_.pyramid_levels; ++l) {
    cv::Mat down;
    cv::pyrDown(level, down);
    if (std::min(down.cols, down.rows) < kMinCoarseTemplatePx) break;
    PreparedTemplate prepared;
    if (!prepared.Prepare(down, MaskFor(down.size()))) break;
    pyramid.push_back(std::move(prepared));
    level = down;
  }
  pyramid_ = std::move(pyramid);
  anchor_px_ = params_.centre_on_symmetry ? SymmetryCentre(templ) : HalfSize(templ.size());
  mask_ = pyramid_[0].mask().empty() ? cv::Mat() : MaskFor(templ.size());
  original_ = templ.clone();
  original_.convertTo(blended_, CV_32F);
}

void TemplateTracker::init(const cv::Mat& frame_bgr, const cv::Rect& hint) {
  CV_Assert(frame_bgr.type() == CV_8UC3);
  if (!hint.empty()) {
    const cv::Rect frame_rect(0, 0, frame_bgr.cols, frame_bgr.rows);
    if ((hint & frame_rect) != hint) {
      throw InputError("template rect " + RectText(hint) + " is not inside the " +
                       std::to_string(frame_bgr.cols) + "x" + std::to_string(frame_bgr.rows) +
                       " frame");
    }
    const cv::Mat previous = projection_;  // Kept if the new selection is refused.
    projection_.release();
    if (!params_.colour && params_.contrast_gray) projection_ = ContrastProjection(frame_bgr(hint));
    cv::Mat native;
    ToNative(frame_bgr(hint), native);
    try {
      SetTemplate(native.clone(), "template rect " + RectText(hint));
    } catch (const InputError&) {
      projection_ = previous;
      throw;
    }
    last_px_ = cv::Point2d(hint.x, hint.y) + anchor_px_;
  } else {
    const std::string where =
        params_.image_file.empty() ? std::string("template image") : params_.image_file;
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
      throw InputError(where + ": template image must be 8-bit BGR" +
                       std::string(params_.colour ? " for colour matching" : " or gray"));
    }
    try {
      SetTemplate(native.clone(), where);
    } catch (const InputError&) {
      projection_ = previous;
      throw;
    }
    last_px_.reset();  // Position unknown: the first update searches the whole frame.
  }
  tracking_ = false;
  velocity_px_ = {0, 0};
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
      MatchSsd(image, templ, raw_);
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

bool TemplateTracker::Accept(const Match& m) const {
  if (!(m.zncc >= params_.min_zncc)) return false;
  switch (params_.measure) {
    case MatchMeasure::kSad: return m.score <= params_.max_sad;
    case MatchMeasure::kSsd: return m.score <= params_.max_ssd;
    case MatchMeasure::kZncc: return true;
  }
  return false;
}

cv::Rect TemplateTracker::WindowAround(const cv::Point2d& centre_px, int margin_px) const {
  const cv::Size size = template_size();
  const cv::Point2d top_left = centre_px - anchor_px_;
  return {static_cast<int>(std::lround(top_left.x)) - margin_px,
          static_cast<int>(std::lround(top_left.y)) - margin_px, size.width + 2 * margin_px,
          size.height + 2 * margin_px};
}

std::optional<Match> TemplateTracker::SearchWindow(const cv::Mat& frame, cv::Rect region) {
  const cv::Size size = template_size();
  region &= cv::Rect(0, 0, frame.cols, frame.rows);
  if (region.width < size.width || region.height < size.height) return std::nullopt;
  ToNative(frame(region), region_);
  Similarity(region_, pyramid_[0], sim_);
  cv::Point best;
  if (!BestIn(sim_, &best)) return std::nullopt;
  const bool v_shaped = params_.measure == MatchMeasure::kSad;
  cv::Point2d offset(0, 0);
  const float* row = sim_.ptr<float>(best.y);
  if (best.x > 0 && best.x < sim_.cols - 1) {
    offset.x = PeakOffset(row[best.x - 1], row[best.x], row[best.x + 1], v_shaped);
  }
  if (best.y > 0 && best.y < sim_.rows - 1) {
    offset.y = PeakOffset(sim_.at<float>(best.y - 1, best.x), row[best.x],
                          sim_.at<float>(best.y + 1, best.x), v_shaped);
  }
  Match m;
  m.top_left = region.tl() + best;
  m.centre_px = cv::Point2d(m.top_left) + offset + anchor_px_;
  m.similarity = row[best.x];
  m.score = ScoreOf(m.similarity);
  m.zncc = m.score;
  if (params_.measure != MatchMeasure::kZncc) {
    // One ZNCC at the best placement: SAD and SSD alone accept any patch whose grey levels are
    // close enough, e.g. a smooth background patch once the light has changed.
    MatchZnccReference(region_(cv::Rect(best, size)), pyramid_[0].image(), shape_,
                       pyramid_[0].mask());
    m.zncc = shape_.at<float>(0, 0);  // NaN (flat window) fails the check below.
  }
  m.on_inner_edge =
      (best.x == 0 && region.x > 0) || (best.x == sim_.cols - 1 && region.br().x < frame.cols) ||
      (best.y == 0 && region.y > 0) || (best.y == sim_.rows - 1 && region.br().y < frame.rows);
  return m;
}

// A small full-resolution search around `top_left`, re-centred while the peak sits on its edge.
std::optional<Match> TemplateTracker::Refine(const cv::Mat& frame, cv::Point top_left) {
  const cv::Size size = template_size();
  std::optional<Match> m;
  for (int i = 0; i <= kMaxRecentre; ++i) {
    m = SearchWindow(frame,
                     cv::Rect(top_left.x - kRefineMarginPx, top_left.y - kRefineMarginPx,
                              size.width + 2 * kRefineMarginPx, size.height + 2 * kRefineMarginPx));
    if (!m || !m->on_inner_edge) return m;
    top_left = m->top_left;
  }
  return std::nullopt;  // Still climbing: no clear peak here.
}

std::optional<Match> TemplateTracker::Acquire(const cv::Mat& frame) {
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  cv::Rect region = frame_rect;
  if (last_px_ && params_.acquire_radius_px > 0) {
    region = WindowAround(*last_px_, params_.acquire_radius_px) & frame_rect;
  }
  const cv::Size size = template_size();
  if (region.width < size.width || region.height < size.height) return std::nullopt;

  int levels = 1;
  while (levels < static_cast<int>(pyramid_.size()) &&
         (region.width >> levels) >= pyramid_[levels].size().width + 2 &&
         (region.height >> levels) >= pyramid_[levels].size().height + 2) {
    ++levels;
  }
  if (levels == 1) {
    std::optional<Match> m = SearchWindow(frame, region);
    // The peak on the acquisition region's edge is still the best there is inside it.
    if (m) m->on_inner_edge = false;
    return m;
  }

  levels_.resize(levels);
  ToNative(frame(region), levels_[0]);
  for (int l = 1; l < levels; ++l) cv::pyrDown(levels_[l - 1], levels_[l]);
  const int top = levels - 1;
  Similarity(levels_[top], pyramid_[top], sim_);

  // The best few separated peaks at the coarsest level, each refined level by level.
  std::vector<cv::Point>& candidates = candidates_;
  candidates.clear();
  const cv::Size coarse = pyramid_[top].size();
  for (int k = 0; k < kCandidates; ++k) {
    cv::Point at;
    if (!BestIn(sim_, &at)) break;
    candidates.push_back(at);
    const cv::Rect suppress(at.x - coarse.width / 2, at.y - coarse.height / 2, coarse.width + 1,
                            coarse.height + 1);
    sim_(suppress & cv::Rect(0, 0, sim_.cols, sim_.rows))
        .setTo(std::numeric_limits<float>::quiet_NaN());
  }
  std::optional<Match> best;
  cv::Mat& level_sim = level_sim_;
  for (cv::Point p : candidates) {
    int level = top;  // The level `p` is in.
    for (int l = top - 1; l >= 1; --l) {
      const cv::Size ts = pyramid_[l].size();
      const cv::Rect window =
          cv::Rect(2 * p.x - kRefineMarginPx, 2 * p.y - kRefineMarginPx,
                   ts.width + 2 * kRefineMarginPx, ts.height + 2 * kRefineMarginPx) &
          cv::Rect(0, 0, levels_[l].cols, levels_[l].rows);
      if (window.width < ts.width || window.height < ts.height) break;
      Similarity(levels_[l](window), pyramid_[l], level_sim);
      cv::Point at;
      if (!BestIn(level_sim, &at)) break;
      p = window.tl() + at;
      level = l;
    }
    std::optional<Match> m = Refine(frame, region.tl() + p * (1 << level));
    if (m && (!best || m->similarity > best->similarity)) best = m;
  }
  return best;
}

void TemplateTracker::UpdateTemplate(const cv::Mat& frame, const cv::Point2d& centre_px) {
  const cv::Rect around = WindowAround(centre_px, 2);
  if ((around & cv::Rect(0, 0, frame.cols, frame.rows)) != around) return;
  ToNative(frame(around), region_);
  // getRectSubPix centres the patch on its geometric centre, HalfSize from its corner.
  const cv::Point2d patch_centre = centre_px - anchor_px_ + HalfSize(template_size());
  cv::getRectSubPix(region_, template_size(), patch_centre - cv::Point2d(around.tl()), patch_,
                    CV_32F);
  cv::addWeighted(blended_, 1.0 - params_.update_rate, patch_, params_.update_rate, 0.0, blended_);
  blended_.convertTo(candidate_, CV_8U);
  const cv::Mat& mask = mask_;
  MatchZnccReference(candidate_, original_, drift_, mask);
  const float similarity = drift_.at<float>(0, 0);
  PreparedTemplate& prepared = updated_;  // Reused: Prepare keeps its buffers' capacity.
  if (!(similarity >= params_.drift_min_zncc) || !prepared.Prepare(candidate_, mask)) {
    original_.convertTo(blended_, CV_32F);  // Drifted: back to the selected template.
    pyramid_[0].Prepare(original_, mask);
    return;
  }
  std::swap(pyramid_[0], prepared);
}

Observation TemplateTracker::update(const cv::Mat& frame_bgr) {
  CV_Assert(frame_bgr.type() == CV_8UC3);
  if (pyramid_.empty()) return {};  // No template yet.
  std::optional<Match> m;
  if (tracking_) {
    m = SearchWindow(frame_bgr, WindowAround(*last_px_ + velocity_px_, params_.search_margin_px));
    if (m && (m->on_inner_edge || !Accept(*m))) m.reset();
  }
  if (!m) m = Acquire(frame_bgr);
  if (!m || !Accept(*m)) {
    tracking_ = false;  // Keep last_px_: the next acquisition looks around it.
    velocity_px_ = {0, 0};
    return {};
  }
  velocity_px_ = tracking_ ? m->centre_px - *last_px_ : cv::Point2d(0, 0);
  last_px_ = m->centre_px;
  tracking_ = true;
  if (params_.update_rate > 0) UpdateTemplate(frame_bgr, m->centre_px);
  Observation observation;
  observation.position_px = m->centre_px;
  observation.score = m->score;
  return observation;
}

}  // namespace

bool TemplateParams::Check(std::string* error) const {
  // Each field's range is in its table row (track/template_options.cc); only rules across fields
  // are written here.
  if (const auto problem = CheckOptions(TemplateParamsOptions(), *this)) {
    return Fail(error, *problem);
  }
  if (rect && !image_file.empty()) {
    return Fail(error, "template.file: give either rect or file, not both");
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
