#include "pipeline/body_constellation.h"

#include <algorithm>
#include <cmath>

namespace softsight {
namespace {

// A report's own noise (px, 1 sigma): centroids and match peaks are sub-pixel, but a shape seen
// in perspective, blurred or partly hidden moves its centre by a few tenths.
constexpr double kReportSigmaPx = 0.5;
// Until a marker has been seen moving against its body for this many frames, its relative motion
// is taken as this (px per frame, 1 sigma): a little, so that a marker never tracked beside its
// body is not held to a rigid arrangement.
constexpr int kRelativeSamplesToTrust = 5;
constexpr double kRelativeUntrustedPx = 2.0;
// The running RMS forgets at this rate per frame (about a second at 30 fps).
constexpr double kRelativeForget = 1.0 / 30.0;
// A miss larger than this many sigma is not learned from in full (a wrong report, or the body
// jumped): it is clipped, so one outlier cannot open the tolerance wide.
constexpr double kRelativeClipSigmas = 4.0;
// With one anchor the body's turn and scale since the snapshot are unknown: this fraction of the
// marker's distance from the anchor (1 sigma: a turn of 9 degrees, or 15 % nearer the camera).
constexpr double kOneAnchorTurn = 0.15;

// Weighted centroids of `from` and `to`.
void WeightedMeans(const std::vector<cv::Point2d>& from, const std::vector<cv::Point2d>& to,
                   const std::vector<double>& w, cv::Point2d* mf, cv::Point2d* mt, double* sw) {
  *mf = cv::Point2d(0, 0);
  *mt = cv::Point2d(0, 0);
  *sw = 0;
  for (size_t k = 0; k < from.size(); ++k) {
    *mf += w[k] * from[k];
    *mt += w[k] * to[k];
    *sw += w[k];
  }
  *mf *= 1.0 / *sw;
  *mt *= 1.0 / *sw;
}

// The RMS residual of `transform` over the pairs, weighted, per coordinate, with `params` of the
// 2n coordinates spent on the fit (0 when none are left to check it).
double ResidualRms(const std::vector<cv::Point2d>& from, const std::vector<cv::Point2d>& to,
                   const std::vector<double>& w, const cv::Matx23d& t, int params) {
  const double n = static_cast<double>(from.size());
  if (2 * n <= params) return 0.0;
  double ss = 0, sw = 0;
  for (size_t k = 0; k < from.size(); ++k) {
    const cv::Point2d p(t(0, 0) * from[k].x + t(0, 1) * from[k].y + t(0, 2),
                        t(1, 0) * from[k].x + t(1, 1) * from[k].y + t(1, 2));
    const cv::Point2d r = p - to[k];
    ss += w[k] * r.dot(r);
    sw += w[k];
  }
  return std::sqrt(ss / sw * n / (2 * n - params));
}

// The weighted least-squares similarity (z' = a z + b in complex numbers) taking `from` to `to`:
// two anchors, or anchors along one line. Returns false when `from` has no extent.
bool FitSimilarity(const std::vector<cv::Point2d>& from, const std::vector<cv::Point2d>& to,
                   const std::vector<double>& w, cv::Matx23d* transform, double* residual_rms) {
  cv::Point2d mf, mt;
  double sw = 0;
  WeightedMeans(from, to, w, &mf, &mt, &sw);
  double sxx = 0, re = 0, im = 0;
  for (size_t k = 0; k < from.size(); ++k) {
    const cv::Point2d f = from[k] - mf, t = to[k] - mt;
    sxx += w[k] * f.dot(f);
    re += w[k] * (f.x * t.x + f.y * t.y);
    im += w[k] * (f.x * t.y - f.y * t.x);
  }
  if (sxx < 1e-6 * sw) return false;  // The anchors are at one place: nothing to turn or scale.
  const double a = re / sxx, b = im / sxx;
  *transform = cv::Matx23d(a, -b, mt.x - (a * mf.x - b * mf.y), b, a, mt.y - (b * mf.x + a * mf.y));
  *residual_rms = ResidualRms(from, to, w, *transform, 4);
  return true;
}

// The weighted least-squares affine transform taking `from` to `to` (three anchors or more,
// spread in two directions: a plate seen in changing perspective is affine to a good
// approximation, a similarity is not). Returns false when the anchors are too close to one line
// to fix it.
bool FitAffine(const std::vector<cv::Point2d>& from, const std::vector<cv::Point2d>& to,
               const std::vector<double>& w, cv::Matx23d* transform, double* residual_rms) {
  if (from.size() < 3) return false;
  cv::Point2d mf, mt;
  double sw = 0;
  WeightedMeans(from, to, w, &mf, &mt, &sw);
  cv::Matx22d s = cv::Matx22d::zeros(), c = cv::Matx22d::zeros();
  for (size_t k = 0; k < from.size(); ++k) {
    const cv::Vec2d f(from[k].x - mf.x, from[k].y - mf.y), t(to[k].x - mt.x, to[k].y - mt.y);
    s += w[k] * (f * f.t());
    c += w[k] * (t * f.t());
  }
  // The spread's smaller axis against its larger (eigenvalues of s): below kMinSpreadRatio the
  // anchors lie along a line (an actuator's markers), and the affine's shear is a guess.
  constexpr double kMinSpreadRatio = 0.2;
  const double tr = s(0, 0) + s(1, 1), det = s(0, 0) * s(1, 1) - s(0, 1) * s(1, 0);
  const double disc = std::sqrt(std::max(0.0, tr * tr / 4 - det));
  const double lmax = tr / 2 + disc, lmin = tr / 2 - disc;
  if (lmax <= 0 || lmin < kMinSpreadRatio * kMinSpreadRatio * lmax) return false;
  const cv::Matx22d a = c * s.inv();
  const cv::Vec2d b = cv::Vec2d(mt.x, mt.y) - a * cv::Vec2d(mf.x, mf.y);
  *transform = cv::Matx23d(a(0, 0), a(0, 1), b[0], a(1, 0), a(1, 1), b[1]);
  *residual_rms = ResidualRms(from, to, w, *transform, 6);
  return true;
}

}  // namespace

BodyConstellation::BodyConstellation(size_t markers)
    : snapshot_(markers, std::vector<std::optional<cv::Point2d>>(markers)),
      has_snapshot_(markers, 0),
      relative_px_(markers, kRelativeUntrustedPx),
      relative_samples_(markers, 0) {}

std::optional<BodyConstellation::Prediction> BodyConstellation::predict(
    size_t i, const std::vector<std::optional<cv::Point2d>>& anchors_px, int frames_since) const {
  if (!has_snapshot_.at(i) || !snapshot_[i][i]) return std::nullopt;
  from_.clear();
  to_.clear();
  weight_.clear();
  for (size_t j = 0; j < anchors_px.size(); ++j) {
    if (j == i || !anchors_px[j] || !snapshot_[i][j]) continue;
    from_.push_back(*snapshot_[i][j]);
    to_.push_back(*anchors_px[j]);
    // An anchor that moves against the body (an actuator's bending tip) says less of where the
    // body is than one that keeps its place on it: weighted by its own uncertainty.
    const double r = relative_of(j);
    weight_.push_back(1.0 / (kReportSigmaPx * kReportSigmaPx + r * r));
  }
  if (from_.empty()) return std::nullopt;
  const double gap = static_cast<double>(std::max(1, frames_since));
  const double relative = relative_of(i);
  const cv::Point2d s = *snapshot_[i][i];
  Prediction p;
  p.anchors = static_cast<int>(from_.size());
  if (from_.size() == 1) {
    // One anchor: the body moved with it, and may have turned or scaled about it by any amount.
    const double turn = kOneAnchorTurn * cv::norm(s - from_[0]);
    p.position_px = s + (to_[0] - from_[0]);
    p.sigma_px = std::sqrt(2 * kReportSigmaPx * kReportSigmaPx + turn * turn +
                           gap * gap * relative * relative);
    p.exact = true;
    return p;
  }
  cv::Matx23d t;
  double residual = 0.0;
  bool exact = false;
  if (FitAffine(from_, to_, weight_, &t, &residual)) {
    exact = from_.size() == 3;
  } else if (FitSimilarity(from_, to_, weight_, &t, &residual)) {
    exact = from_.size() == 2;
  } else {
    return std::nullopt;
  }
  p.position_px = cv::Point2d(t(0, 0) * s.x + t(0, 1) * s.y + t(0, 2),
                              t(1, 0) * s.x + t(1, 1) * s.y + t(1, 2));
  // The marker lies outside the anchors' spread (extrapolation): the fit's residual grows with
  // how far outside; scale it by the ratio of its distance from their centre to their spread.
  cv::Point2d centre(0, 0);
  for (const cv::Point2d& q : from_) centre += q;
  centre *= 1.0 / static_cast<double>(from_.size());
  double spread = 0.0;
  for (const cv::Point2d& q : from_) spread += cv::norm(q - centre);
  spread /= static_cast<double>(from_.size());
  const double lever = spread > 0 ? std::max(1.0, cv::norm(s - centre) / spread) : 1.0;
  // A marker lost for frames may have moved against its body on every one of them, in one
  // direction (a bend going on): linear in the frames (`gap`), not their square root.
  // The anchors' own noise and the fit's residual, carried out to the marker by the lever.
  p.sigma_px = std::sqrt(kReportSigmaPx * kReportSigmaPx * (1 + lever * lever) +
                         lever * lever * residual * residual + gap * gap * relative * relative);
  p.exact = exact;
  return p;
}

double BodyConstellation::relative_of(size_t i) const {
  return relative_samples_[i] >= kRelativeSamplesToTrust
             ? relative_px_[i]
             : std::max(relative_px_[i], kRelativeUntrustedPx);
}

void BodyConstellation::remember(const std::vector<std::optional<cv::Point2d>>& believed_px,
                                 const std::vector<std::optional<Prediction>>& predicted) {
  const size_t n = snapshot_.size();
  for (size_t i = 0; i < n; ++i) {
    if (!believed_px[i]) continue;
    if (i < predicted.size() && predicted[i]) {
      // Learn how far i moves against its body in one frame (the residual's share removed).
      const double miss = cv::norm(*believed_px[i] - predicted[i]->position_px);
      const double clip = kRelativeClipSigmas * std::max(predicted[i]->sigma_px, kReportSigmaPx);
      const double m = std::min(miss, clip);
      const double w = relative_samples_[i] == 0 ? 1.0 : std::max(kRelativeForget, 1.0 / (1 + relative_samples_[i]));
      relative_px_[i] = std::sqrt((1 - w) * relative_px_[i] * relative_px_[i] + w * m * m);
      ++relative_samples_[i];
    }
    for (size_t j = 0; j < n; ++j) snapshot_[i][j] = believed_px[j];
    has_snapshot_[i] = 1;
  }
}

void BodyConstellation::forget(size_t i) {
  has_snapshot_.at(i) = 0;
  relative_px_[i] = kRelativeUntrustedPx;
  relative_samples_[i] = 0;
  // Nor is i an anchor in any other marker's snapshot: where it was is not where it is now known
  // to have been.
  for (auto& row : snapshot_) row[i].reset();
}

}  // namespace softsight
