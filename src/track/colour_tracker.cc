#include "softsight/track/colour_tracker.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "track/colour_tracker_impl.h"
#include "track/track_options.h"

namespace softsight {
namespace {

// Whole-frame style searches of regions at least this large use the coarse-to-fine path.
constexpr int kCoarseMinArea = 200 * 200;
// Leniency of the coarse test: it sees unfiltered pixels, which noise pushes a little off the
// marker's range where the filtered ones are inside it.
constexpr int kCoarseHueSlack = 8;
// Growing a region around a clipped blob gives up after this many rounds and analyses the frame.
constexpr int kMaxGrowRounds = 8;
// Coarse candidate cells are grouped by tiles of this many cells a side.
constexpr int kTile = 8;

// ---- Soft centroid and colour statistics (ColourBlob) ----------------------------------------------
// Pixels within this distance of the binary edge (inside or outside) are weighted by their
// membership; deeper ones count 1, the core colour is their mean. 2 px holds an anti-aliased
// edge blurred by a Gaussian of sigma ~1 px.
constexpr int kSoftBand = 2;
// The local background is the ring from kSoftBand + 1 to kRingOuter px outside the blob.
constexpr int kRingOuter = 4;
// Angular sectors of the ring (about the blob's centroid) that give each edge pixel its local
// background.
constexpr int kSectors = 16;
// Memberships within this of 0 or 1 snap to it (the rest is stretched linearly to keep 0.5 at
// 0.5): background texture and noise next to the marker then add no weight, while an edge,
// whose pixels' coverages spread evenly over 0..1, keeps its total weight and its centre.
constexpr double kMembershipDeadband = 0.12;
// Noise floor (gray levels) in the contrast's denominator: perfectly flat synthetic colours
// would otherwise make any difference infinitely significant.
constexpr double kContrastNoiseFloor = 2.0;
// The core's own spread counts half in the contrast: a marker's core varies by itself when the
// marker is blurred by its motion (its colour ramps along the streak: a dot moving three of its
// widths a frame still stands out), while a patch of background texture differs from its
// surroundings by less than they vary, whatever its core does.
constexpr double kCoreSigmaWeight = 0.5;

// ---- Verification (ColourTracker::judge) -----------------------------------------------------------
// A candidate whose contrast is below this does not stand out from its surroundings.
constexpr double kMinContrast = 2.0;
// Without a learned model only compact blobs are accepted (a disc is 1, a 2:1 ellipse 0.8, a disc
// seen at 50 degrees 0.91): elongated patches of the right colour are common on a bench.
constexpr double kMinCircularityWithoutModel = 0.7;
// A whole-frame first acquisition (no learned model, no roi) accepts only a blob with at least
// this many pixels of its own colour (deeper than the soft band inside its edge): the colour of a
// smaller blob is a mixture with its surroundings, and such specks are everywhere in real footage
// (the yellow rim of a highlight on an orange object, a glint on a blue one).
constexpr int kMinCorePxWithoutModel = 9;
// Tolerances of the colour check against the learned (or nominal) core colour: the angle between
// the BGR vectors (tint, insensitive to illumination gain) and the brightness ratio. A same-hue
// blob at 60 % of the marker's brightness or 9 degrees off in tint is something else.
constexpr double kChromaTolerance = 0.15;   // radians
constexpr double kBrightnessTolerance = 1.6;
// The learned shape: a candidate less circular than the model by this much is at its limit
// (and never below min_circularity).
constexpr double kShapeTolerance = 0.3;
// A pixel of a blob's own mask that was a hole (see FillHoles): part of its region, not of its
// colour.
constexpr uchar kFilledHole = 128;
// A partly hidden round marker is placed at the centre of its visible rim (RimCentre) when it
// was learned round (circularity >= 0.85) and large enough for a rim (area >= 28 px, radius 3),
// the blob has less than 0.97 of its area, at least 170 degrees of the rim show (half the disc,
// less the pixels where the cut meets the rim), and the rim points lie within 0.5 px RMS.
constexpr double kMinRimCircularity = 0.85;
constexpr double kMinRimArea = 28.0;
constexpr double kWholeRimFraction = 0.97;
constexpr double kMinRimArcDeg = 170.0;
constexpr double kMaxRimRmsPx = 0.5;
// Adaptation while tracking only from frames where the marker's shape is within kAdaptShape of
// the learned one (a partial cover changes it; growth and tilt change it slowly); the reference
// area stays within kAdaptMinRange..kAdaptMaxRange times the first one. A jump in area is not
// learned because it is not accepted (min_area_fraction, max_area_factor).
constexpr double kAdaptShape = 0.1;
constexpr double kAdaptMinRange = 0.5;
constexpr double kAdaptMaxRange = 4.0;
// A blob whose asymmetry (ColourBlob::asymmetry_px) exceeds the learned marker's by more than
// this many of its radii, and at least kPartialMinPx, is a marker partly covered: the centroid of
// what is visible lies that far from the marker's centre, so it is not reported. A tenth of the
// radius: a disc a quarter covered by a straight edge shifts its visible centroid by 0.22 radii,
// a twentieth covered by 0.05; 1 px keeps the pixel grid's own wobble of small markers out.
constexpr double kPartialRadii = 0.1;
constexpr double kPartialMinPx = 1.0;
// A blob with less than this fraction of the learned area is partial too (see judge()).
constexpr double kWholeAreaFraction = 0.55;
// A marker partly seen where it should be is held there (its window searched, nothing else) for
// at most this many frames: a second at 30 fps, long enough for a hand or a tool to pass.
constexpr int kHoldCoveredFrames = 30;
// A lone candidate within this of where a candidate tied before (in a first acquisition without
// a model or roi) has not moved since: it is that candidate (sensor noise moves a static blob's
// centroid by hundredths of a pixel).
constexpr double kRivalStillPx = 0.5;

// A marker lost this many frames in a row, with exactly one candidate near where it was last
// seen that fits it in everything but brightness (same chroma, size, shape, contrast), is taken
// to be under a new light and its colour relearned. Half a second at 30 fps: a passing shadow or a
// hand does not relearn anything.
constexpr int kRelearnAfterFrames = 15;
// How near, in learned radii (plus one per frame lost): it may have moved while it was lost.
constexpr double kRelearnRadii = 6.0;

// ---- Automatic colour (ColourParams::auto_bgr) -------------------------------------------------------
constexpr int kAutoHueTolerance = 12;        // hue units (2 degrees each)
constexpr int kAutoGraySaturation = 40;      // below: the nominal colour is a gray level

// A Mat header of `size` and `type` over `store`, which reallocates only when it is too small, so
// frames of a steady size allocate nothing. The header is continuous and has no parent matrix,
// so OpenCV's filters never read stale bytes beyond it as "neighbouring pixels".
cv::Mat Scratch(cv::Mat& store, cv::Size size, int type) {
  const size_t bytes = static_cast<size_t>(size.area()) * CV_ELEM_SIZE(type);
  if (store.empty() || static_cast<size_t>(store.cols) < bytes) {
    store.create(1, static_cast<int>(std::max<size_t>(bytes, 64)), CV_8U);
  }
  return cv::Mat(size, type, store.data);
}

double DistanceToRect(const cv::Point2d& p, const cv::Rect& r) {
  // Pixel areas: column j covers [j - 0.5, j + 0.5].
  const double dx = std::max({r.x - 0.5 - p.x, 0.0, p.x - (r.x + r.width - 0.5)});
  const double dy = std::max({r.y - 0.5 - p.y, 0.0, p.y - (r.y + r.height - 0.5)});
  return std::hypot(dx, dy);
}

bool CentroidBefore(const ColourBlob& a, const ColourBlob& b) {
  if (a.centroid_px.y != b.centroid_px.y) return a.centroid_px.y < b.centroid_px.y;
  if (a.centroid_px.x != b.centroid_px.x) return a.centroid_px.x < b.centroid_px.x;
  return a.area_px < b.area_px;
}

bool SameBlob(const ColourBlob& a, const ColourBlob& b) {
  return a.bbox_px == b.bbox_px && a.area_px == b.area_px && a.centroid_px == b.centroid_px;
}

bool HueIsFull(const HsvRange& h) {
  return (h.lo == 0 && h.hi == 179) || (h.lo > h.hi && h.lo == h.hi + 1);
}

// A pseudo-angle of (dx, dy) in [0, 4): monotonic in atan2 (one unit per quadrant), without a
// transcendental function. 0 for (0, 0).
double DiamondAngle(double dx, double dy) {
  const double sum = std::abs(dx) + std::abs(dy);
  if (sum == 0) return 0;
  if (dy >= 0) return dx >= 0 ? dy / sum : 1 - dx / sum;
  return dx < 0 ? 2 - dy / sum : 3 + dx / sum;
}

// Chamfer (3-4) distance to the edge of the nonzero pixels of `inside`, in thirds of a pixel,
// into `distance` (CV_16U, same size): for an outside pixel, to the nearest inside one; for an
// inside pixel, to the nearest outside one (pixels beyond the image count as inside, as erosion
// by OpenCV's default border does).
void ChamferToEdge(const cv::Mat& inside, cv::Mat& distance) {
  constexpr int kFar = 0x3fff;
  const int w = inside.cols, h = inside.rows;
  // Two transforms in one map: a pixel's seeds are its neighbours of the other kind (one step
  // away); through a neighbour of its own kind it inherits that one's distance plus the step.
  // `inside` holds 0 or 255, so a pixel's kind is its low bit; `same` is all ones when the
  // neighbour's kind is the pixel's, and masks in the neighbour's distance.
  auto relax = [](int d, int k, const uchar* in, const uint16_t* dist, int x, int step) {
    const int same = ((in[x] & 1) ^ k) - 1;
    return std::min(d, step + (dist[x] & same));
  };
  auto forward = [&](const uchar* in, const uchar* in_up, uint16_t* row, const uint16_t* up,
                     int x) {
    const int k = in[x] & 1;
    int d = kFar;
    if (x > 0) d = relax(d, k, in, row, x - 1, 3);
    if (up) {
      if (x > 0) d = relax(d, k, in_up, up, x - 1, 4);
      d = relax(d, k, in_up, up, x, 3);
      if (x + 1 < w) d = relax(d, k, in_up, up, x + 1, 4);
    }
    row[x] = static_cast<uint16_t>(d);
  };
  auto backward = [&](const uchar* in, const uchar* in_down, uint16_t* row, const uint16_t* down,
                      int x) {
    const int k = in[x] & 1;
    int d = row[x];
    if (x + 1 < w) d = relax(d, k, in, row, x + 1, 3);
    if (down) {
      if (x + 1 < w) d = relax(d, k, in_down, down, x + 1, 4);
      d = relax(d, k, in_down, down, x, 3);
      if (x > 0) d = relax(d, k, in_down, down, x - 1, 4);
    }
    row[x] = static_cast<uint16_t>(d);
  };
  for (int y = 0; y < h; ++y) {
    const uchar* in = inside.ptr<uchar>(y);
    uint16_t* row = distance.ptr<uint16_t>(y);
    if (y == 0 || w < 3) {
      const uchar* in_up = y > 0 ? inside.ptr<uchar>(y - 1) : nullptr;
      const uint16_t* up = y > 0 ? distance.ptr<uint16_t>(y - 1) : nullptr;
      for (int x = 0; x < w; ++x) forward(in, in_up, row, up, x);
      continue;
    }
    const uchar* in_up = inside.ptr<uchar>(y - 1);
    const uint16_t* up = distance.ptr<uint16_t>(y - 1);
    forward(in, in_up, row, up, 0);
    for (int x = 1; x + 1 < w; ++x) {  // Every neighbour exists: no bounds tests.
      const int k = in[x] & 1;
      int d = relax(kFar, k, in, row, x - 1, 3);
      d = relax(d, k, in_up, up, x - 1, 4);
      d = relax(d, k, in_up, up, x, 3);
      d = relax(d, k, in_up, up, x + 1, 4);
      row[x] = static_cast<uint16_t>(d);
    }
    forward(in, in_up, row, up, w - 1);
  }
  for (int y = h - 1; y >= 0; --y) {
    const uchar* in = inside.ptr<uchar>(y);
    uint16_t* row = distance.ptr<uint16_t>(y);
    if (y == h - 1 || w < 3) {
      const uchar* in_down = y + 1 < h ? inside.ptr<uchar>(y + 1) : nullptr;
      const uint16_t* down = y + 1 < h ? distance.ptr<uint16_t>(y + 1) : nullptr;
      for (int x = w - 1; x >= 0; --x) backward(in, in_down, row, down, x);
      continue;
    }
    const uchar* in_down = inside.ptr<uchar>(y + 1);
    const uint16_t* down = distance.ptr<uint16_t>(y + 1);
    backward(in, in_down, row, down, w - 1);
    for (int x = w - 2; x >= 1; --x) {
      const int k = in[x] & 1;
      int d = relax(row[x], k, in, row, x + 1, 3);
      d = relax(d, k, in_down, down, x + 1, 4);
      d = relax(d, k, in_down, down, x, 3);
      d = relax(d, k, in_down, down, x - 1, 4);
      row[x] = static_cast<uint16_t>(d);
    }
    backward(in, in_down, row, down, 0);
  }
}

double Norm(const cv::Vec3d& v, int channels) {
  double sum = 0;
  for (int c = 0; c < channels; ++c) sum += v[c] * v[c];
  return std::sqrt(sum);
}

int MorphShape(ColourParams::Shape shape) {
  switch (shape) {
    case ColourParams::Shape::kRect: return cv::MORPH_RECT;
    case ColourParams::Shape::kCross: return cv::MORPH_CROSS;
    case ColourParams::Shape::kEllipse: break;
  }
  return cv::MORPH_ELLIPSE;
}

// The coarse test with a pre-filter: hue widened by kCoarseHueSlack each side, lower S and V
// bounds lowered by a quarter and the upper ones raised a quarter of the way to 255.
HsvBox CoarseBox(const ColourParams& p) {
  const int span = p.h.lo <= p.h.hi ? p.h.hi - p.h.lo : p.h.hi + 180 - p.h.lo;
  HsvRange h{0, 179};
  if (span + 2 * kCoarseHueSlack < 179) {
    h.lo = (p.h.lo - kCoarseHueSlack + 180) % 180;
    h.hi = (p.h.hi + kCoarseHueSlack) % 180;
  }
  const HsvRange s{p.s.lo * 3 / 4, p.s.hi + (255 - p.s.hi) / 4};
  const HsvRange v{p.v.lo * 3 / 4, p.v.hi + (255 - p.v.hi) / 4};
  return HsvBox::Make(h, s, v);
}

}  // namespace

bool ColourParams::Check(std::string* error) const {
  // Each field's range is in its table row (track/colour_options.cc); only rules across fields
  // are written here.
  if (const auto problem = CheckOptions(ColourParamsOptions(), *this)) return Fail(error, *problem);
  std::ostringstream why;
  for (const auto& [name, r] : {std::pair{"s", s}, std::pair{"v", v}}) {
    if (r.lo > r.hi) {
      why << "hsv." << name << ": [" << r.lo << ", " << r.hi << "]: lower bound above upper bound";
      return Fail(error, why.str());
    }
  }
  if (max_area_px != 0.0 && max_area_px < min_area_px) {
    why << "blob.max_area: " << FormatDouble(max_area_px)
        << " must be 0 (no limit) or at least blob.min_area (" << FormatDouble(min_area_px) << ")";
    return Fail(error, why.str());
  }
  if (roi && (roi->width <= 0 || roi->height <= 0)) {
    why << "roi: [" << roi->x << ", " << roi->y << ", " << roi->width << ", " << roi->height
        << "] needs a positive width and height";
    return Fail(error, why.str());
  }
  if (gray && gray->lo > gray->hi) {
    why << "gray: [" << gray->lo << ", " << gray->hi << "]: lower bound above upper bound";
    return Fail(error, why.str());
  }
  if (gray && auto_bgr) return Fail(error, "gray: give either gray or auto_colour, not both");
  return true;
}

bool ColourParams::NeedsColour() const {
  if (gray) return false;
  if (auto_bgr) {
    cv::Mat bgr(1, 1, CV_8UC3, cv::Scalar((*auto_bgr)[0], (*auto_bgr)[1], (*auto_bgr)[2])), hsv;
    cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
    return hsv.at<cv::Vec3b>(0, 0)[1] >= kAutoGraySaturation;
  }
  return !(HueIsFull(h) && s.lo == 0);
}

ColourTracker::ColourTracker(const ColourParams& params) : params_(params) {
  CV_Assert(params_.Check(nullptr));
  const int filter_radius = params_.filter == ColourParams::Filter::kNone ? 0
                                                                          : params_.filter_ksize / 2;
  const int morph_radius = params_.morph_size / 2;
  if (params_.morph_size > 1) {
    kernel_ = cv::getStructuringElement(MorphShape(params_.morph_shape),
                                        cv::Size(params_.morph_size, params_.morph_size));
    if (params_.morph_size == 3) {
      morph_square_ = cv::countNonZero(kernel_) == 9;
      morph_cross_ = cv::countNonZero(kernel_ != cv::getStructuringElement(
                                                     cv::MORPH_CROSS, cv::Size(3, 3))) == 0;
    }
  }
  // Opening then closing is four erosions/dilations, each reaching one radius further; the ring
  // around a blob reaches kRingOuter beyond it. With this margin every pixel a blob inside the
  // region depends on is exactly what a whole-frame pass would see.
  margin_px_ = filter_radius + 4 * morph_radius + kRingOuter + 1;
  HsvRange h = params_.h, s = params_.s, v = params_.v;
  gray_ = params_.gray;
  if (params_.auto_bgr) {
    // The nominal colour gives the threshold and, until the marker's own colour is learned, the
    // colour model: generous bounds, since verification rejects a wrong tint or brightness.
    const cv::Vec3b c = *params_.auto_bgr;
    cv::Mat bgr(1, 1, CV_8UC3, cv::Scalar(c[0], c[1], c[2])), hsv;
    cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
    const cv::Vec3b n = hsv.at<cv::Vec3b>(0, 0);
    if (n[1] < kAutoGraySaturation) {
      cv::Mat level;
      cv::cvtColor(bgr, level, cv::COLOR_BGR2GRAY);
      const int l = level.at<uchar>(0, 0);
      const int reach = std::max(40, l * 2 / 5);
      gray_ = HsvRange{std::max(0, l - reach), std::min(255, l + reach)};
      nominal_ = cv::Vec3d(l, 0, 0);
    } else {
      h = HsvRange{(n[0] - kAutoHueTolerance + 180) % 180, (n[0] + kAutoHueTolerance) % 180};
      s = HsvRange{std::max(30, n[1] / 2), 255};
      v = HsvRange{std::max(30, n[2] * 2 / 5), 255};
      nominal_ = cv::Vec3d(c[0], c[1], c[2]);
    }
  }
  // The coarse test sees single unfiltered pixels. Without a pre-filter those are exactly what
  // the fine test sees, so it is the fine test; a filter moves colours, and the coarse test is
  // then widened so that a marker whose filtered pixels pass is not missed.
  const bool filtered = params_.filter != ColourParams::Filter::kNone;
  if (gray_) {
    coarse_gray_ = filtered ? HsvRange{gray_->lo * 3 / 4, gray_->hi + (255 - gray_->hi) / 4} : *gray_;
  } else {
    ColourParams derived = params_;
    derived.h = h;
    derived.s = s;
    derived.v = v;
    fine_hsv_ = HsvClassifier(HsvBox::Make(h, s, v));
    coarse_hsv_ = HsvClassifier(filtered ? CoarseBox(derived) : HsvBox::Make(h, s, v));
  }
  acquire_roi_ = params_.roi;
  opencv_in_windows_ = gray_ || params_.filter != ColourParams::Filter::kNone ||
                       (!kernel_.empty() && !morph_cross_ && !morph_square_);
}

void ColourTracker::check_frame(const cv::Mat& frame) const {
  if (frame.empty() || (frame.type() != CV_8UC3 && frame.type() != CV_8UC1)) {
    throw InputError("colour tracking needs 8-bit BGR or gray frames, got " +
                     (frame.empty() ? std::string("an empty frame")
                                    : cv::typeToString(frame.type()) + " frames"));
  }
  if (frame.type() == CV_8UC1 && params_.NeedsColour()) {
    throw InputError("the frames are gray, but this colour marker's range needs colour (a gray "
                     "level range `gray: [lo, hi]` or an HSV range of any hue from saturation 0 "
                     "tracks white, gray or black markers)");
  }
}

void ColourTracker::reset() {
  held_frames_ = 0;
  last_px_.reset();
  velocity_px_ = cv::Point2d(0, 0);
  tracking_ = false;
  // The roi says where the marker is when tracking starts; once it has been found (a model is
  // learned), it may be anywhere the camera and the body have taken it since: a search after a
  // reset (a report found implausible, a jump of the camera) covers the whole frame, judged by
  // the model, as after any loss.
  if (!model_) acquire_roi_ = params_.roi;
}

bool ColourTracker::start(const Frame& frame) {
  // A roi picked at a later frame says nothing of where the marker is before it.
  if (frame.index < params_.roi_frame) return false;
  // Without a roi there is nothing to learn before the first update: it acquires on the whole
  // frame.
  if (params_.roi) init(frame.image, *params_.roi);
  return true;
}

void ColourTracker::init(const cv::Mat& frame_bgr, const cv::Rect& hint) {
  check_frame(frame_bgr);
  const cv::Rect frame_rect(cv::Point(0, 0), frame_bgr.size());
  if (hint.width <= 0 || hint.height <= 0) {
    throw InputError("colour marker rectangle [" + std::to_string(hint.x) + ", " +
                     std::to_string(hint.y) + ", " + std::to_string(hint.width) + ", " +
                     std::to_string(hint.height) + "] is empty");
  }
  if ((hint & frame_rect).empty()) {
    throw InputError("colour marker rectangle [" + std::to_string(hint.x) + ", " +
                     std::to_string(hint.y) + ", " + std::to_string(hint.width) + ", " +
                     std::to_string(hint.height) + "] lies outside the " +
                     std::to_string(frame_rect.width) + "x" + std::to_string(frame_rect.height) +
                     " frame");
  }
  // A new selection is a new calibration: learn the model again, inside the hint.
  params_.roi = hint & frame_rect;
  model_.reset();
  reset();
  frame_size_ = frame_bgr.size();
  report(acquire(frame_bgr));
}

Observation ColourTracker::update(const cv::Mat& frame_bgr) {
  check_frame(frame_bgr);
  if (frame_bgr.size() != frame_size_) {
    if (!frame_size_.empty()) reset();
    frame_size_ = frame_bgr.size();
  }
  saved_ = State{model_, acquire_roi_, last_px_, last_seen_px_, velocity_px_, tracking_,
                 held_frames_, lost_frames_};
  return search(frame_bgr);
}

std::optional<Observation> ColourTracker::adopt(size_t index) {
  if (index >= candidates_.size() || candidates_.size() != blobs_.size()) return std::nullopt;
  const CandidateVerdict verdict = candidates_[index].verdict;
  if (verdict != CandidateVerdict::kFits && verdict != CandidateVerdict::kChosen) {
    return std::nullopt;
  }
  // Back to before the last report, then report this candidate as the choice.
  model_ = saved_.model;
  acquire_roi_ = saved_.acquire_roi;
  last_px_ = saved_.last_px;
  last_seen_px_ = saved_.last_seen_px;
  velocity_px_ = saved_.velocity_px;
  tracking_ = saved_.tracking;
  held_frames_ = saved_.held_frames;
  lost_frames_ = saved_.lost_frames;
  if (!model_) return std::nullopt;  // Nothing learned to verify it against.
  for (MarkerCandidate& c : candidates_) {
    if (c.verdict == CandidateVerdict::kChosen) c.verdict = CandidateVerdict::kFits;
  }
  candidates_[index].verdict = CandidateVerdict::kChosen;
  Choice choice;
  choice.blob = blobs_[index];
  choice.status = MarkerStatus::kFound;
  return report(choice);
}

Observation ColourTracker::search(const cv::Mat& frame_bgr) {
  candidates_.clear();
  partly_seen_ = false;
  partly_out_ = false;
  Choice choice;
  if (tracking_ && params_.window_px > 0) {
    choice = track_in_windows(frame_bgr);
  } else if (tracking_) {
    // Whole-frame tracking (window 0): the same choice as in a window, the nearest verified blob.
    const cv::Point2d predicted = *last_px_ + velocity_px_;
    find_blobs(frame_bgr, acquire_downsample(), &blobs_);
    last_search_px_ = cv::Rect(cv::Point(0, 0), frame_bgr.size());
    double best = std::numeric_limits<double>::infinity();
    size_t chosen = 0;
    for (const ColourBlob& b : blobs_) {
      const auto [verdict, misfit] = judge(b);
      candidates_.push_back(candidate(b, verdict, misfit));
      const double d = cv::norm(b.centroid_px - predicted);
      if (verdict == CandidateVerdict::kFits && d < best) {
        best = d;
        choice.blob = b;
        chosen = candidates_.size() - 1;
      }
    }
    if (choice.blob) candidates_[chosen].verdict = CandidateVerdict::kChosen;
  }
  if (!choice.blob && tracking_ && partly_seen_ && held_frames_ < kHoldCoveredFrames) {
    // What is left of the marker is where it should be (covered, or leaving the frame): it is
    // not measured, and not looked for elsewhere either, where a look-alike would be all there
    // is. The window stays on it.
    choice.status = partly_out_ ? MarkerStatus::kOutOfFrame : MarkerStatus::kCovered;
    choice.hold = true;
    return report(choice);
  }
  if (!choice.blob) {
    const bool was_tracking = tracking_;
    const cv::Point2d predicted = last_px_.value_or(cv::Point2d()) + velocity_px_;
    choice = acquire(frame_bgr);
    if (!choice.blob && was_tracking && choice.status == MarkerStatus::kLost) {
      if (partly_out_ ||
          !cv::Rect2d(-0.5, -0.5, frame_bgr.cols, frame_bgr.rows).contains(predicted)) {
        choice.status = MarkerStatus::kOutOfFrame;
      } else if (partly_seen_) {
        choice.status = MarkerStatus::kCovered;
      }
    }
    if (!choice.blob && choice.status != MarkerStatus::kAmbiguous && last_seen_px_ &&
        lost_frames_ + 1 >= kRelearnAfterFrames) {
      const Choice relearned = relearn(*last_seen_px_);
      if (relearned.blob || relearned.status == MarkerStatus::kAmbiguous) choice = relearned;
    }
  }
  return report(choice);
}

void ColourTracker::learn(const ColourBlob& blob, bool tracking) {
  if (!model_) {
    model_ = ColourModel{blob.area_px, blob.area_px, blob.circularity, blob.core_colour,
                         blob.asymmetry_px};
    return;
  }
  // Asymmetry follows only down: a marker learned while partly covered is learned whole later,
  // never the other way round.
  if (tracking && blob.asymmetry_px < model_->asymmetry_px) {
    model_->asymmetry_px += std::max(params_.adapt_rate, 0.1) *
                            (blob.asymmetry_px - model_->asymmetry_px);
  }
  if (!tracking || params_.adapt_rate <= 0) return;
  // Follow slow changes only: a marker growing in perspective, the light drifting. A sudden one
  // (a partial cover, a reflection) is not learned.
  ColourModel& m = *model_;
  if (blob.circularity < m.circularity - kAdaptShape) return;
  const double r = params_.adapt_rate;
  m.area_px = std::clamp(m.area_px + r * (blob.area_px - m.area_px),
                         kAdaptMinRange * m.first_area_px, kAdaptMaxRange * m.first_area_px);
  m.circularity += r * (blob.circularity - m.circularity);
  if (blob.measured) m.colour += r * (blob.core_colour - m.colour);
}

Observation ColourTracker::report(const Choice& choice) {
  if (!choice.blob && choice.hold) {
    ++held_frames_;
    ++lost_frames_;
    // The window follows where the marker goes meanwhile (behind the cover, out of the frame).
    if (last_px_) *last_px_ += velocity_px_;
    return Observation::NotFound(choice.status);
  }
  if (!choice.blob) {
    held_frames_ = 0;
    tracking_ = false;
    velocity_px_ = cv::Point2d(0, 0);
    ++lost_frames_;
    return Observation::NotFound(choice.status, choice.tied);
  }
  const ColourBlob& blob = *choice.blob;
  if (!blob.rim_placed) learn(blob, tracking_);  // What is left of it is not its looks.
  lost_frames_ = 0;
  last_seen_px_ = blob.centroid_px;
  // After frames held covered, the step from the last position spans them: no velocity.
  velocity_px_ = tracking_ && held_frames_ == 0 ? blob.centroid_px - *last_px_ : cv::Point2d(0, 0);
  held_frames_ = 0;
  last_px_ = blob.centroid_px;
  tracking_ = true;
  acquire_roi_.reset();
  Observation obs;
  obs.position_px = blob.centroid_px;
  obs.score = blob.area_px / model_->area_px;
  return obs;
}

MarkerCandidate ColourTracker::candidate(const ColourBlob& b, CandidateVerdict verdict,
                                         double misfit) const {
  MarkerCandidate c;
  c.position_px = b.clipped ? cv::Point2d(b.bbox_px.x + (b.bbox_px.width - 1) / 2.0,
                                          b.bbox_px.y + (b.bbox_px.height - 1) / 2.0)
                            : b.centroid_px;
  c.area_px = b.area_px;
  c.circularity = b.circularity;
  c.misfit = misfit;
  c.verdict = verdict;
  return c;
}

std::pair<CandidateVerdict, double> ColourTracker::judge(const ColourBlob& b,
                                                         bool any_brightness) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (b.clipped) return {CandidateVerdict::kClipped, kInf};
  if (b.area_px < params_.min_area_px || (params_.max_area_px > 0 && b.area_px > params_.max_area_px)) {
    return {CandidateVerdict::kSize, kInf};
  }
  // Without a model and a roi the first acquisition takes the one compact candidate; in a roi a
  // person showed the marker, and the configured limit holds (an elongated sticker).
  const double min_circularity =
      model_ || acquire_roi_ ? params_.min_circularity
                             : std::max(params_.min_circularity, kMinCircularityWithoutModel);
  if (b.circularity < min_circularity || !b.measured) return {CandidateVerdict::kShape, kInf};
  // Part of it hidden: beyond the frame's edge, or covered (more asymmetric than the marker).
  // Judged on for its misfit: a partial blob that would fit is a rival of the others (it may be
  // the marker) and is never reported itself.
  // A blob placed at the centre of its visible rim is partial no more: its position is the
  // marker's.
  bool partial = b.at_frame_edge && !b.rim_placed;
  if (model_ && !b.rim_placed) {
    const double radius = std::sqrt(model_->area_px / CV_PI);
    const double tolerance = std::max(kPartialMinPx, kPartialRadii * radius);
    partial = partial || b.asymmetry_px > model_->asymmetry_px + tolerance;
  }
  if (!model_ && !acquire_roi_ && b.core_px < kMinCorePxWithoutModel) {
    return {CandidateVerdict::kSize, kInf};
  }
  double misfit = 0;
  // Shape: 0 as round as the model (a disc without one), 1 at the limit.
  // Before a model, in a roi, any shape down to the configured limit may be the marker (the
  // person showed it): the span reaches that limit.
  const double ref_circularity = model_ ? model_->circularity : 1.0;
  const double shape_span =
      model_ || !acquire_roi_
          ? std::max(0.05, std::min(kShapeTolerance, ref_circularity - min_circularity))
          : std::max(0.05, ref_circularity - min_circularity);
  const double shape = std::max(0.0, ref_circularity - b.circularity) / shape_span;
  if (shape > 1) return {CandidateVerdict::kShape, kInf};
  misfit += shape;
  // Size against the learned area: the configured fraction and factor are the limits.
  if (model_) {
    const double ratio = b.area_px / model_->area_px;
    double size = 0;
    if (ratio < 1 && params_.min_area_fraction > 0) {
      if (ratio < params_.min_area_fraction) return {CandidateVerdict::kSize, kInf};
      size = std::log(ratio) / std::log(params_.min_area_fraction);
    } else if (ratio > 1 && params_.max_area_factor > 0) {
      if (ratio > params_.max_area_factor) return {CandidateVerdict::kSize, kInf};
      size = std::log(ratio) / std::log(params_.max_area_factor);
    }
    misfit += size;
    // Little more than half its learned area at once (the area follows slow changes only): a
    // disc cut beyond its centre, whose centroid is more than 0.4 radii off. The asymmetry cannot
    // tell: the smallest circle around less than half a disc is no longer the disc's.
    partial = partial || (ratio < kWholeAreaFraction && !b.rim_placed);
  }
  // Contrast to its own surroundings.
  if (!(b.contrast >= kMinContrast)) return {CandidateVerdict::kContrast, kInf};
  misfit += kMinContrast / b.contrast;
  // Colour against the learned core colour, or the nominal one.
  const std::optional<cv::Vec3d> reference =
      model_ ? std::optional<cv::Vec3d>(model_->colour) : nominal_;
  if (reference) {
    const int channels = gray_ ? 1 : 3;
    const double ref_bright = Norm(*reference, channels);
    const double bright = Norm(b.core_colour, channels);
    double colour = 0;
    if (ref_bright > 1 && bright > 1) {
      if (!any_brightness) {
        colour = std::abs(std::log(bright / ref_bright)) / std::log(kBrightnessTolerance);
      }
      if (channels == 3) {
        const double cosine = std::clamp(b.core_colour.dot(*reference) / (bright * ref_bright),
                                         -1.0, 1.0);
        colour = std::max(colour, std::acos(cosine) / kChromaTolerance);
      }
    } else if (std::abs(bright - ref_bright) > 8) {
      colour = kInf;  // One of them black: compare levels directly.
    }
    if (colour > 1) return {CandidateVerdict::kColour, kInf};
    misfit += colour;
  }
  return {partial ? CandidateVerdict::kPartial : CandidateVerdict::kFits, misfit};
}

ColourTracker::Choice ColourTracker::track_in_windows(const cv::Mat& frame) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  const cv::Point2d predicted = *last_px_ + velocity_px_;
  // The window must hold the whole marker with room to move: at least two diameters.
  const double ref_radius = std::sqrt(model_ ? model_->area_px / CV_PI : 0.0);
  const int base = std::max(params_.window_px, static_cast<int>(std::ceil(4.0 * ref_radius)));
  for (int step = 0; step <= params_.widen_steps; ++step) {
    const int side = base << step;
    const cv::Rect window =
        cv::Rect(cvRound(predicted.x) - side / 2, cvRound(predicted.y) - side / 2, side, side) &
        frame_rect;
    if (window.empty()) continue;  // Prediction far outside the frame: try wider.
    last_search_px_ = window;
    blobs_.clear();
    analyse(frame, window, &blobs_);
    std::sort(blobs_.begin(), blobs_.end(), CentroidBefore);
    candidates_.clear();
    const ColourBlob* best = nullptr;
    size_t best_index = 0;
    double best_dist = std::numeric_limits<double>::infinity();
    double nearest_partial = std::numeric_limits<double>::infinity();
    for (const ColourBlob& b : blobs_) {
      const auto [verdict, misfit] = judge(b);
      candidates_.push_back(candidate(b, verdict, misfit));
      // What is left of a covered marker: of its colour, smaller than it (often a sliver, so of
      // any shape), and within its own radius (plus one frame's motion) of where it should be.
      // So is a partial blob there (part of it covered, or beyond the frame's edge).
      const bool smaller = (verdict == CandidateVerdict::kSize ||
                            verdict == CandidateVerdict::kShape) &&
                           model_ && b.area_px < model_->area_px;
      const double d = cv::norm(b.centroid_px - predicted);
      if ((smaller || verdict == CandidateVerdict::kPartial) && model_ &&
          d <= ref_radius + cv::norm(velocity_px_) + 1.0) {
        partly_seen_ = true;
        if (b.at_frame_edge) partly_out_ = true;
        // A sliver of it where it should be is the marker covered, as much as a partial blob:
        // a whole look-alike farther away is not it.
        nearest_partial = std::min(nearest_partial, d);
      }
      if (verdict == CandidateVerdict::kPartial) {
        nearest_partial = std::min(nearest_partial, d);
      }
      if (verdict != CandidateVerdict::kFits) continue;
      if (d < best_dist) {
        best_dist = d;
        best = &b;
        best_index = candidates_.size() - 1;
      }
    }
    // The marker partly hidden (covered, or leaving the frame) nearer than the best whole blob:
    // that is where the marker is, and what is left of it is not measured. A look-alike farther
    // away is not it.
    if (nearest_partial < best_dist) return Choice{};
    // A blob cut by the window's border may be the marker extending outside, and nearer than
    // the best complete one: never report a clipped centroid, look wider instead.
    bool nearer_clipped = false;
    for (const ColourBlob& b : blobs_) {
      if (b.clipped && DistanceToRect(predicted, b.bbox_px) < best_dist) nearer_clipped = true;
    }
    if (best && !nearer_clipped) {
      candidates_[best_index].verdict = CandidateVerdict::kChosen;
      Choice choice;
      choice.blob = *best;
      choice.status = MarkerStatus::kFound;
      return choice;
    }
    if (window == frame_rect) break;
  }
  return Choice{};
}

ColourTracker::Choice ColourTracker::acquire(const cv::Mat& frame) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  cv::Rect region = frame_rect;
  if (acquire_roi_) {
    region = *acquire_roi_ & frame_rect;
    if (region.empty()) return Choice{std::nullopt, MarkerStatus::kOutOfFrame, 0};
  }
  last_search_px_ = region;
  blobs_.clear();
  const int factor = acquire_downsample();
  if (factor > 1 && region.area() >= kCoarseMinArea) {
    coarse_to_fine(frame, region, factor, &blobs_);
  } else {
    complete_blobs(frame, region, &blobs_);
  }
  std::sort(blobs_.begin(), blobs_.end(), CentroidBefore);

  // Every candidate is judged against the model (or, before one is learned, the configured
  // ranges and a compact, contrasted shape); among those that fit, the best fit wins, with a
  // preference for the neighbourhood of the last known position. A runner-up nearly as good
  // makes the marker ambiguous: a coin toss between look-alikes is not a measurement.
  const double diagonal = std::hypot(frame.cols, frame.rows);
  const cv::Rect2d roi_area = acquire_roi_ ? cv::Rect2d(acquire_roi_->x - 0.5, acquire_roi_->y - 0.5,
                                                        acquire_roi_->width, acquire_roi_->height)
                                           : cv::Rect2d();
  candidates_.clear();
  size_t best = 0;
  double best_cost = std::numeric_limits<double>::infinity(), second_cost = best_cost;
  double partial_cost = best_cost;  // The best rival partly hidden ...
  bool partial_at_edge = false;     // ... and whether it is cut by the frame's edge.
  for (const ColourBlob& b : blobs_) {
    auto [verdict, misfit] = judge(b);
    if (verdict == CandidateVerdict::kFits && acquire_roi_ && !roi_area.contains(b.centroid_px)) {
      verdict = CandidateVerdict::kOutsideRoi;
    }
    candidates_.push_back(candidate(b, verdict, misfit));
    const bool partial = verdict == CandidateVerdict::kPartial;
    if (verdict != CandidateVerdict::kFits && !partial) continue;
    double cost = misfit;
    if (last_px_) cost += cv::norm(b.centroid_px - *last_px_) / diagonal;
    if (partial) {
      // Partly hidden: never the one reported, but a rival (it may be the marker).
      if (cost < partial_cost) {
        partial_cost = cost;
        partial_at_edge = b.at_frame_edge;
      }
      continue;
    }
    const size_t index = candidates_.size() - 1;
    if (cost < best_cost) {
      second_cost = best_cost;
      best = index;
      best_cost = cost;
    } else if (cost < second_cost) {
      second_cost = cost;
    }
  }
  Choice choice;
  if (!std::isfinite(best_cost)) {
    // kLost: nothing whole fits; what fits is partly hidden.
    if (std::isfinite(partial_cost)) {
      choice.status = partial_at_edge ? MarkerStatus::kOutOfFrame : MarkerStatus::kCovered;
    }
    return choice;
  }
  second_cost = std::min(second_cost, partial_cost);
  // Before a model is learned, the misfit knows only the configured ranges and a compact,
  // contrasted shape: it cannot tell a marker from a look-alike (a glint, a dot of the bench), so
  // a whole-frame first acquisition needs the one candidate that fits at all.
  const double margin = !model_ && !acquire_roi_ ? std::numeric_limits<double>::infinity()
                                                 : params_.ambiguity_margin;
  const bool by_uniqueness = !model_ && !acquire_roi_;
  if (std::isfinite(second_cost) && second_cost - best_cost < margin) {
    choice.status = MarkerStatus::kAmbiguous;
    if (by_uniqueness) rivals_.clear();
    for (size_t i = 0; i < candidates_.size(); ++i) {
      const bool partial = candidates_[i].verdict == CandidateVerdict::kPartial;
      if (candidates_[i].verdict != CandidateVerdict::kFits && !partial) continue;
      double cost = candidates_[i].misfit;
      if (last_px_) cost += cv::norm(blobs_[i].centroid_px - *last_px_) / diagonal;
      if (!partial && cost - best_cost < margin) ++choice.tied;
      if (by_uniqueness) {
        // A partial rival too: the marker leaving the frame is one.
        rivals_.push_back({blobs_[i].centroid_px, std::sqrt(blobs_[i].area_px / CV_PI)});
      }
    }
    return choice;
  }
  if (by_uniqueness && !rivals_.empty()) {
    // The one candidate left may be one of those that were tied before, still exactly in its
    // place (a look-alike of the background does not move; a marker on a bending body does).
    // If another of them is still there (a blob in its place that no longer fits: the checks told
    // them apart), the candidate is the marker. If another has vanished, it may have been the
    // marker (gone, or covered) and the one left a look-alike: as ambiguous as before. A
    // candidate that has moved, or is in none of their places, is the marker.
    const ColourBlob& only = blobs_[best];
    const auto at = [](const cv::Point2d& p, const Rival& rival) {
      return cv::norm(p - rival.position_px) <= rival.radius_px + 2.0;
    };
    bool was_a_rival = false, a_rival_vanished = false;
    for (const Rival& rival : rivals_) {
      if (cv::norm(only.centroid_px - rival.position_px) <= kRivalStillPx) {
        was_a_rival = true;
        continue;
      }
      bool still_there = false;
      for (const ColourBlob& b : blobs_) still_there = still_there || at(b.centroid_px, rival);
      a_rival_vanished = a_rival_vanished || !still_there;
    }
    if (was_a_rival && a_rival_vanished) {
      choice.status = MarkerStatus::kAmbiguous;
      choice.tied = 2;
      return choice;
    }
    rivals_.clear();
  }
  candidates_[best].verdict = CandidateVerdict::kChosen;
  choice.blob = blobs_[best];
  choice.status = MarkerStatus::kFound;
  return choice;
}

ColourTracker::Choice ColourTracker::relearn(const cv::Point2d& last_seen) {
  // Chroma is what tells the marker from a darker or brighter look-alike here, so a gray-level
  // marker (brightness is all it has) is never relearned.
  Choice choice;
  if (!model_ || gray_) return choice;
  // Anywhere in the searched region, every candidate that fits in all but brightness counts: the
  // one relearned must be the only one.
  std::optional<size_t> only;
  int fitting = 0;
  for (size_t i = 0; i < candidates_.size() && i < blobs_.size(); ++i) {
    const CandidateVerdict verdict = candidates_[i].verdict;
    if (verdict == CandidateVerdict::kFits ||
        (verdict == CandidateVerdict::kColour &&
         judge(blobs_[i], true).first == CandidateVerdict::kFits)) {
      ++fitting;
      only = i;
    }
  }
  if (fitting > 1) {
    choice.status = MarkerStatus::kAmbiguous;
    choice.tied = fitting;
    return choice;
  }
  // And near where the marker was last seen: a few of its radii, and one more for every frame it
  // has been lost (a marker moving a radius a frame is fast).
  const double reach =
      (kRelearnRadii + lost_frames_) * std::sqrt(model_->area_px / CV_PI);
  if (!only || cv::norm(blobs_[*only].centroid_px - last_seen) > reach) return choice;
  candidates_[*only].verdict = CandidateVerdict::kChosen;
  choice.blob = blobs_[*only];
  choice.status = MarkerStatus::kFound;
  model_->colour = choice.blob->core_colour;  // The new light's colour, learned afresh.
  return choice;
}

std::optional<double> ColourTracker::rim_radius_px() const {
  if (!model_ || model_->circularity < kMinRimCircularity || model_->area_px < kMinRimArea) {
    return std::nullopt;
  }
  // The centres of a disc's edge pixels lie half a pixel inside its outline.
  return std::sqrt(model_->area_px / CV_PI) - 0.5;
}

std::optional<cv::Point2d> ColourTracker::RimCentre(const ColourBlob& blob) const {
  const std::optional<double> radius = rim_radius_px();
  if (!blob.rim || !radius) return std::nullopt;
  const RimFit& fit = *blob.rim;
  // Half of the rim or more, densely on the circle (a disc's edge has about 1.1 pixels per
  // pixel of its length), within half a pixel of it.
  const double expected = 2 * CV_PI * *radius * fit.arc_deg / 360.0;
  if (fit.arc_deg < kMinRimArcDeg || fit.rms_px > kMaxRimRmsPx || fit.rim_points < 0.8 * expected) {
    return std::nullopt;
  }
  // What is left of the marker lies inside its circle: a blob reaching outside it is not this
  // marker partly hidden (a look-alike touching it, another shape).
  const double reach = *radius + 1.0;
  const cv::Point2d c = fit.centre_px;
  const cv::Rect2d circle_box(c.x - reach, c.y - reach, 2 * reach, 2 * reach);
  if (blob.bbox_px.x < circle_box.x || blob.bbox_px.y < circle_box.y ||
      blob.bbox_px.x + blob.bbox_px.width - 1 > circle_box.x + circle_box.width ||
      blob.bbox_px.y + blob.bbox_px.height - 1 > circle_box.y + circle_box.height) {
    return std::nullopt;
  }
  return c;
}

double ColourTracker::min_blob_radius_px() const {
  const double min_area = std::max(params_.min_area_px,
                                   params_.min_area_fraction * (model_ ? model_->area_px : 0.0));
  return std::sqrt(min_area / CV_PI);
}

int ColourTracker::acquire_downsample() const {
  if (params_.acquire_downsample > 0) return params_.acquire_downsample;
  // The smallest blob that can count as the marker must hold sample points of the coarse grid
  // (spacing f): a disc of radius r >= f / sqrt(2) holds one, r >= f holds at least three.
  const double radius = min_blob_radius_px();
  int factor = 1;
  while (factor < 8 && radius >= 2.0 * factor) factor *= 2;
  return factor;
}

void ColourTracker::find_blobs(const cv::Mat& frame_bgr, int downsample,
                               std::vector<ColourBlob>* blobs) {
  check_frame(frame_bgr);
  blobs->clear();
  const cv::Rect frame_rect(cv::Point(0, 0), frame_bgr.size());
  if (downsample > 1) {
    coarse_to_fine(frame_bgr, frame_rect, downsample, blobs);
  } else {
    complete_blobs(frame_bgr, frame_rect, blobs);
  }
  std::sort(blobs->begin(), blobs->end(), CentroidBefore);
}

cv::Mat ColourTracker::prepare(const cv::Mat& src, cv::Mat& store) {
  const int channels = gray_ ? 1 : 3;
  if (src.channels() == channels) return src;
  cv::Mat converted = Scratch(store, src.size(), CV_MAKETYPE(CV_8U, channels));
  cv::cvtColor(src, converted, channels == 1 ? cv::COLOR_BGR2GRAY : cv::COLOR_GRAY2BGR);
  return converted;
}

bool ColourTracker::membership(const cv::Mat& frame_bgr, cv::Mat& mask) const {
  cv::Mat src = frame_bgr;
  const int channels = gray_ ? 1 : 3;
  if (src.channels() != channels) {
    cv::cvtColor(frame_bgr, src, channels == 1 ? cv::COLOR_BGR2GRAY : cv::COLOR_GRAY2BGR);
  }
  if (gray_) {
    cv::inRange(src, cv::Scalar(gray_->lo), cv::Scalar(gray_->hi), mask);
  } else {
    mask.create(src.size(), CV_8UC1);
    fine_hsv_.Classify(src, mask);
  }
  return true;
}

void ColourTracker::classify(const cv::Mat& src, bool coarse, cv::Mat& mask) {
  if (gray_) {
    const HsvRange& g = coarse ? *coarse_gray_ : *gray_;
    cv::inRange(src, cv::Scalar(g.lo), cv::Scalar(g.hi), mask);
    return;
  }
  // One pass, bit-exact with cvtColor(BGR2HSV) + inRange (track/colour_kernels.h).
  (coarse ? coarse_hsv_ : fine_hsv_).Classify(src, mask);
}

void ColourTracker::analyse(const cv::Mat& frame, cv::Rect region,
                            std::vector<ColourBlob>* blobs) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  region &= frame_rect;
  if (region.empty()) return;
  if (region.area() >= kCoarseMinArea) {
    analyse_region(frame, region, blobs);
    return;
  }
  // A window is a few thousand pixels: handing its pieces to OpenCV's thread pool (TBB) costs
  // more than the work (connected components alone doubles). Run the window as one OpenCV
  // parallel region of a single task: OpenCV executes parallel loops nested in it inline. Only
  // OpenCV's own filters, conversions and morphology parallelise; without them (the default
  // pipeline: our kernels alone) the window runs directly, since the region itself costs a few
  // allocations and microseconds per window, and a re-acquisition analyses dozens.
  const bool opencv_parallel = opencv_in_windows_ || frame.channels() != (gray_ ? 1 : 3);
  if (!opencv_parallel) {
    analyse_region(frame, region, blobs);
    return;
  }
  cv::parallel_for_(cv::Range(0, 1),
                    [&](const cv::Range&) { analyse_region(frame, region, blobs); });
}

void ColourTracker::analyse_region(const cv::Mat& frame, const cv::Rect& region,
                                   std::vector<ColourBlob>* blobs) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  const int m = margin_px_;
  const cv::Rect extended =
      cv::Rect(region.x - m, region.y - m, region.width + 2 * m, region.height + 2 * m) &
      frame_rect;
  // A view into the frame (when it has the channels the classifier needs), so near the frame's
  // edges the filter sees the same border as a whole-frame pass would.
  const cv::Mat src = prepare(frame(extended), prepared_store_);

  // 1. Filter.
  cv::Mat filtered = src;
  if (params_.filter == ColourParams::Filter::kGaussian) {
    filtered = Scratch(filtered_store_, extended.size(), src.type());
    cv::GaussianBlur(src, filtered, cv::Size(params_.filter_ksize, params_.filter_ksize), 0);
  } else if (params_.filter == ColourParams::Filter::kMedian) {
    filtered = Scratch(filtered_store_, extended.size(), src.type());
    cv::medianBlur(src, filtered, params_.filter_ksize);
  }

  // 2. Binarise.
  cv::Mat mask = Scratch(mask_store_, extended.size(), CV_8U);
  classify(filtered, false, mask);

  // 3. Opening then closing, only where it can change anything: outside the bounding box of the
  //    marker-coloured pixels the mask is 0 and stays 0 (opening only removes, closing only fills
  //    between pixels), so morphology and labelling work on that box plus the reach of the four
  //    passes. Beyond the box the parent mask holds zeros, exactly what a whole pass would read.
  const cv::Rect extended_local(cv::Point(0, 0), extended.size());
  cv::Rect active = NonZeroBounds(mask);
  if (active.empty()) return;
  if (!kernel_.empty()) {
    const int reach = 4 * (params_.morph_size / 2) + 1;
    active = cv::Rect(active.x - reach, active.y - reach, active.width + 2 * reach,
                      active.height + 2 * reach) &
             extended_local;
    cv::Mat cleaned = mask(active);
    if (morph_cross_ || morph_square_) {
      // The reach padding keeps `active`'s border rows zero, so reading the outside as the
      // border (the kernel) equals reading the parent's zeros (morphologyEx on the view).
      OpenClose3x3(cleaned, morph_cross_, morph_store_);
    } else {
      cv::Mat opened = Scratch(morph_store_, active.size(), CV_8U);
      cv::morphologyEx(cleaned, opened, cv::MORPH_OPEN, kernel_);
      cv::morphologyEx(opened, cleaned, cv::MORPH_CLOSE, kernel_);
    }
  }

  // 4. Blobs of the region proper (the margin only fed the filters); the region is 0 outside
  //    `labelled`, so its components are the region's components.
  const cv::Rect inner_local(region.tl() - extended.tl(), region.size());
  const cv::Rect labelled = active & inner_local;
  if (labelled.empty()) return;
  const cv::Point offset = labelled.tl() - inner_local.tl();  // Of `labelled` in the region.
  labeller_.Label(mask(labelled));
  const bool open_left = region.x > 0;
  const bool open_top = region.y > 0;
  const bool open_right = region.x + region.width < frame.cols;
  const bool open_bottom = region.y + region.height < frame.rows;
  const std::vector<RunLabeller::Component>& components = labeller_.components();
  for (size_t i = 0; i < components.size(); ++i) {
    const RunLabeller::Component& comp = components[i];
    const cv::Rect& box = comp.box;
    const cv::Rect in_region = box + offset;
    ColourBlob blob;
    blob.area_px = comp.area;
    blob.clipped = (open_left && in_region.x == 0) || (open_top && in_region.y == 0) ||
                   (open_right && in_region.x + in_region.width == region.width) ||
                   (open_bottom && in_region.y + in_region.height == region.height);
    blob.bbox_px = in_region + region.tl();
    blob.at_frame_edge = blob.bbox_px.x == 0 || blob.bbox_px.y == 0 ||
                         blob.bbox_px.x + blob.bbox_px.width == frame.cols ||
                         blob.bbox_px.y + blob.bbox_px.height == frame.rows;
    if (!blob.clipped) {
      if (blob.area_px < params_.min_area_px) continue;
      if (params_.max_area_px > 0 && blob.area_px > params_.max_area_px) continue;
      // 5. Centroid from the binary moments of this blob alone (exact integer sums relative to
      //    its box, as cv::moments of its own pixels), then the box's integer offset in the frame.
      const double m00 = comp.area, inv_m00 = 1.0 / m00;
      const double cx = static_cast<double>(comp.m10) * inv_m00;
      const double cy = static_cast<double>(comp.m01) * inv_m00;
      blob.binary_centroid_px = cv::Point2d(cx + blob.bbox_px.x, cy + blob.bbox_px.y);
      blob.centroid_px = blob.binary_centroid_px;
      // Polar moment of the pixels as unit squares (each adds 1/6 about its own centre).
      const double mu20 = static_cast<double>(comp.m20) - static_cast<double>(comp.m10) * cx;
      const double mu02 = static_cast<double>(comp.m02) - static_cast<double>(comp.m01) * cy;
      const double polar = mu20 + mu02 + m00 / 6.0;
      blob.circularity = m00 * m00 / (2.0 * CV_PI * polar);
      // 6. Colour statistics and the soft centroid, for blobs that may be the marker.
      if (blob.circularity >= params_.min_circularity) {
        measure(filtered, mask, static_cast<int>(i), box, labelled.tl(), extended.tl(), &blob);
        if (blob.rim_placed) blob.centroid_px = blob.rim->centre_px;  // Over the soft centroid.
      }
    }
    blobs->push_back(blob);
  }
}

void ColourTracker::FillHoles(cv::Mat& own, cv::Point own_origin, ColourBlob* blob) {
  // A hole is a part of the blob's background that does not reach the outside: a specular
  // highlight on a glossy marker, a glint, pixels noise pushed out of the range. They are part of
  // the marker: its area, centroid and shape are the filled region's, and its colour and ring
  // are measured around the filled region (a highlight inside is not its surroundings).
  cv::Mat outside = Scratch(holes_store_, cv::Size(own.cols + 2, own.rows + 2), CV_8U);
  outside.setTo(0);
  own.copyTo(outside(cv::Rect(1, 1, own.cols, own.rows)));
  cv::floodFill(outside, cv::Point(0, 0), cv::Scalar(128), nullptr, cv::Scalar(), cv::Scalar(), 4);
  int filled = 0;
  for (int y = 0; y < own.rows; ++y) {
    const uchar* o = outside.ptr<uchar>(y + 1) + 1;
    uchar* w = own.ptr<uchar>(y);
    for (int x = 0; x < own.cols; ++x) {
      if (o[x] == 0) {
        w[x] = kFilledHole;
        ++filled;
      }
    }
  }
  if (filled == 0) return;
  const cv::Moments m = cv::moments(own, true);
  if (!(m.m00 > 0)) return;
  blob->area_px = m.m00;
  blob->binary_centroid_px =
      cv::Point2d(m.m10 / m.m00 + own_origin.x, m.m01 / m.m00 + own_origin.y);
  blob->centroid_px = blob->binary_centroid_px;
  blob->circularity = m.m00 * m.m00 / (2.0 * CV_PI * (m.mu20 + m.mu02 + m.m00 / 6.0));
}

void ColourTracker::measure(const cv::Mat& filtered, const cv::Mat& mask, int component,
                            const cv::Rect& box, cv::Point labelled_tl, cv::Point origin,
                            ColourBlob* blob) {
  // The blob's box in `filtered`, padded by the ring's reach.
  const cv::Rect box_local = box + labelled_tl;
  const cv::Rect padded =
      cv::Rect(box_local.x - kRingOuter - 1, box_local.y - kRingOuter - 1,
               box_local.width + 2 * kRingOuter + 2, box_local.height + 2 * kRingOuter + 2) &
      cv::Rect(cv::Point(0, 0), filtered.size());
  const cv::Size size = padded.size();
  cv::Mat own = Scratch(blob_store_, size, CV_8U);
  for (int y = 0; y < size.height; ++y) {
    std::memset(own.ptr<uchar>(y), 0, static_cast<size_t>(size.width));
  }
  labeller_.Draw(component, own, padded.tl() - labelled_tl);
  FillHoles(own, padded.tl() + origin, blob);
  // Asymmetry: the binary centroid against the centre of the smallest circle around the blob
  // (its convex hull's points are among each row's leftmost and rightmost pixels).
  edge_points_.clear();
  for (int y = 0; y < size.height; ++y) {
    const uchar* row = own.ptr<uchar>(y);
    int first = -1, last = -1;
    for (int x = 0; x < size.width; ++x) {
      if (!row[x]) continue;
      if (first < 0) first = x;
      last = x;
    }
    if (first < 0) continue;
    edge_points_.emplace_back(first, y);
    if (last != first) edge_points_.emplace_back(last, y);
  }
  if (!edge_points_.empty()) {
    cv::Point2f circle_centre;
    float circle_radius = 0.0f;
    cv::minEnclosingCircle(edge_points_, circle_centre, circle_radius);
    const cv::Point2d binary_centre = blob->binary_centroid_px - cv::Point2d(padded.tl() + origin);
    blob->asymmetry_px = cv::norm(cv::Point2d(circle_centre) - binary_centre);
  }
  // Distances to the blob's edge (chamfer, thirds of a pixel): near = within kSoftBand outside,
  // core = more than kSoftBand inside, reach = within kRingOuter outside.
  cv::Mat distance = Scratch(distance_store_, size, CV_16U);
  ChamferToEdge(own, distance);
  constexpr int kNear = 3 * kSoftBand, kReach = 3 * kRingOuter;
  const cv::Mat pixels = filtered(padded);
  const cv::Mat others = mask(padded);
  const int channels = pixels.channels();

  // The local background varies around a marker (the body's edge, texture): the ring is split
  // into kSectors angular sectors about the blob's centroid, and an edge pixel's background is
  // interpolated between the two sectors nearest its direction.
  const cv::Point2d centre = blob->binary_centroid_px - cv::Point2d(padded.tl() + origin);
  auto sector_of = [&](int x, int y) {
    const double u = DiamondAngle(x - centre.x, y - centre.y) * (kSectors / 4.0);
    return std::clamp(u, 0.0, kSectors - 1e-9);
  };

  // The core: deeper than kSoftBand, or the whole blob when it is too small to have such pixels.
  bool core_empty = true;
  for (int y = 0; y < size.height && core_empty; ++y) {
    const uchar* ow = own.ptr<uchar>(y);
    const uint16_t* d = distance.ptr<uint16_t>(y);
    for (int x = 0; x < size.width; ++x) core_empty = core_empty && !(ow[x] == 255 && d[x] > kNear);
  }
  const int core_depth = core_empty ? 0 : kNear;
  const bool pure_core = !core_empty;

  // Pass 1: core colour, ring colour (overall and per sector).
  cv::Vec3d core_sum, core_sq, ring_sum, ring_sq;
  std::array<cv::Vec3d, kSectors> sector_sum{};
  std::array<int, kSectors> sector_n{};
  double core_n = 0, ring_n = 0;
  for (int y = 0; y < size.height; ++y) {
    const uchar* p = pixels.ptr<uchar>(y);
    const uchar* ow = own.ptr<uchar>(y);
    const uint16_t* d = distance.ptr<uint16_t>(y);
    const uchar* ot = others.ptr<uchar>(y);
    for (int x = 0; x < size.width; ++x) {
      const uchar* c = p + x * channels;
      if (ow[x] == 255 && d[x] > core_depth) {  // A filled hole is not the marker's colour.
        for (int k = 0; k < channels; ++k) {
          core_sum[k] += c[k];
          core_sq[k] += c[k] * c[k];
        }
        core_n += 1;
      } else if (!ow[x] && d[x] > kNear && d[x] <= kReach && !ot[x]) {
        const int sector = static_cast<int>(sector_of(x, y));
        for (int k = 0; k < channels; ++k) {
          ring_sum[k] += c[k];
          ring_sq[k] += c[k] * c[k];
          sector_sum[sector][k] += c[k];
        }
        ++sector_n[sector];
        ring_n += 1;
      }
    }
  }
  if (core_n < 1 || ring_n < 3) return;  // Crowded by other blobs: no local background.
  double core_var = 0, ring_var = 0;
  for (int k = 0; k < channels; ++k) {
    blob->core_colour[k] = core_sum[k] / core_n;
    blob->ring_colour[k] = ring_sum[k] / ring_n;
    core_var += std::max(0.0, core_sq[k] / core_n - blob->core_colour[k] * blob->core_colour[k]);
    ring_var += std::max(0.0, ring_sq[k] / ring_n - blob->ring_colour[k] * blob->ring_colour[k]);
  }
  blob->core_px = pure_core ? static_cast<int>(core_n) : 0;
  blob->core_sigma = std::sqrt(core_var);
  blob->ring_sigma = std::sqrt(ring_var);
  const cv::Vec3d axis = blob->core_colour - blob->ring_colour;
  const double axis2 = axis.dot(axis);
  blob->contrast = std::sqrt(axis2) /
                   (kCoreSigmaWeight * blob->core_sigma + blob->ring_sigma + kContrastNoiseFloor);
  blob->measured = true;
  // A round marker partly hidden: the circle of its radius through its edge (not where the
  // frame cuts it).
  if (const std::optional<double> radius = rim_radius_px();
      radius && blob->area_px < kWholeRimFraction * model_->area_px) {
    edge_points_.clear();
    const cv::Point frame_origin = padded.tl() + origin;
    for (int y = 0; y < size.height; ++y) {
      const uchar* ow = own.ptr<uchar>(y);
      for (int x = 0; x < size.width; ++x) {
        if (!ow[x]) continue;
        const bool edge = x == 0 || y == 0 || x == size.width - 1 || y == size.height - 1 ||
                          !ow[x - 1] || !ow[x + 1] || !own.ptr<uchar>(y - 1)[x] ||
                          !own.ptr<uchar>(y + 1)[x];
        const int fx = x + frame_origin.x, fy = y + frame_origin.y;
        const bool at_frame_edge = fx == 0 || fy == 0 || fx == frame_size_.width - 1 ||
                                   fy == frame_size_.height - 1;
        if (edge && !at_frame_edge) edge_points_.emplace_back(fx, fy);
      }
    }
    rim_points_.assign(edge_points_.begin(), edge_points_.end());
    blob->rim = FitRimOfRadius(rim_points_, *radius);
    if (const std::optional<cv::Point2d> centre = RimCentre(*blob)) {
      blob->centroid_px = *centre;
      blob->rim_placed = true;
    }
  }
  if (params_.centroid == ColourParams::Centroid::kBinary || axis2 < 1.0) return;

  // Pass 2: the soft centroid. Deep inside counts 1; near the edge, the membership: where the
  // pixel's colour lies between its local background (0) and the core colour (1), on the line
  // through them. Pixels of other blobs count 0.
  std::array<cv::Vec3d, kSectors> sector_mean;
  for (int i = 0; i < kSectors; ++i) {
    sector_mean[i] = sector_n[i] >= 2 ? sector_sum[i] / sector_n[i] : blob->ring_colour;
  }
  const cv::Vec3d& f = blob->core_colour;
  const double deadband_scale = 1.0 / (1.0 - 2.0 * kMembershipDeadband);
  double sw = 0, sx = 0, sy = 0;
  for (int y = 0; y < size.height; ++y) {
    const uchar* p = pixels.ptr<uchar>(y);
    const uchar* ow = own.ptr<uchar>(y);
    const uint16_t* dist = distance.ptr<uint16_t>(y);
    const uchar* ot = others.ptr<uchar>(y);
    double row_w = 0, row_x = 0;
    for (int x = 0; x < size.width; ++x) {
      if (!ow[x] && dist[x] > kNear) continue;  // Beyond the band.
      double w = 1.0;
      if (!(ow[x] && dist[x] > kNear)) {
        if (ot[x] && !ow[x]) continue;
        const uchar* c = p + x * channels;
        // Sector centres sit at i + 0.5.
        const double u = sector_of(x, y) - 0.5;
        const double lower = std::floor(u);
        const double t = u - lower;
        const int i0 = (static_cast<int>(lower) + kSectors) % kSectors;
        const int i1 = (i0 + 1) % kSectors;
        double num = 0, den = 0;
        for (int k = 0; k < channels; ++k) {
          const double g = (1 - t) * sector_mean[i0][k] + t * sector_mean[i1][k];
          const double d = f[k] - g;
          num += (c[k] - g) * d;
          den += d * d;
        }
        w = den > 1.0 ? std::clamp((num / den - kMembershipDeadband) * deadband_scale, 0.0, 1.0)
                      : (ow[x] ? 1.0 : 0.0);
      }
      row_w += w;
      row_x += w * x;
    }
    sw += row_w;
    sx += row_x;
    sy += row_w * y;
  }
  if (sw <= 0) return;
  // Offsets added as one integer: the same blob in a window and in the whole frame gives the
  // same bits.
  blob->centroid_px = cv::Point2d(sx / sw + (padded.x + origin.x), sy / sw + (padded.y + origin.y));
}

void ColourTracker::complete_blobs(const cv::Mat& frame, cv::Rect region,
                                   std::vector<ColourBlob>* blobs) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  region &= frame_rect;
  for (int round = 0; round < kMaxGrowRounds && !region.empty(); ++round) {
    pending_.clear();
    analyse(frame, region, &pending_);
    cv::Rect grown = region;
    bool clipped = false;
    const int pad = std::max(16, std::min(region.width, region.height) / 2);
    for (const ColourBlob& b : pending_) {
      if (!b.clipped) continue;
      clipped = true;
      grown |= cv::Rect(b.bbox_px.x - pad, b.bbox_px.y - pad, b.bbox_px.width + 2 * pad,
                        b.bbox_px.height + 2 * pad);
    }
    if (!clipped) {
      blobs->insert(blobs->end(), pending_.begin(), pending_.end());
      return;
    }
    region = grown & frame_rect;
  }
  // Something long and thin keeps leaving the region: the whole frame has no clipped blobs.
  pending_.clear();
  analyse(frame, frame_rect, &pending_);
  blobs->insert(blobs->end(), pending_.begin(), pending_.end());
}

void ColourTracker::coarse_to_fine(const cv::Mat& frame, cv::Rect region, int factor,
                                   std::vector<ColourBlob>* blobs) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  region &= frame_rect;
  const int coarse_cols = region.width / factor;
  const int coarse_rows = region.height / factor;
  if (coarse_cols < 4 || coarse_rows < 4) {
    complete_blobs(frame, region, blobs);
    return;
  }
  // One pixel per cell of factor x factor pixels (its centre). Sampling, not averaging: a blob
  // of radius >= factor always holds several sample points, and a sample is a real pixel of the
  // frame, not a mix of marker and background. Columns beyond a multiple of the factor are
  // covered by the last cell's window below.
  const cv::Mat src = frame(cv::Rect(region.x, region.y, coarse_cols * factor, coarse_rows * factor));
  cv::Mat sampled = Scratch(coarse_store_, cv::Size(coarse_cols, coarse_rows), src.type());
  // The pixel cv::resize's INTER_NEAREST_EXACT takes, (i + 1/2) * factor, copied directly.
  const int channels = src.channels(), half = factor / 2;
  const size_t row_bytes = static_cast<size_t>(src.cols) * channels;
  for (int y = 0; y < coarse_rows; ++y) {
    // The next sampled row is asked for while this one is copied: every factor-th row of a frame
    // not yet in the cache is a pattern the hardware prefetcher does not follow, and the copy
    // waited on every line.
    if (y + 1 < coarse_rows) {
      const uchar* ahead = src.ptr<uchar>((y + 1) * factor + half);
      for (size_t i = 0; i < row_bytes; i += 64) __builtin_prefetch(ahead + i);
    }
    const uchar* in = src.ptr<uchar>(y * factor + half) + half * channels;
    uchar* out = sampled.ptr<uchar>(y);
    const int step = factor * channels;
    if (channels == 3) {
      // Pixel by pixel as one copy: byte by byte, GCC built vectors from the bytes through the
      // stack, a stall per 16 bytes that cost as much as classifying them.
      for (int x = 0; x < coarse_cols; ++x, in += step, out += 3) std::memcpy(out, in, 3);
    } else {
      for (int x = 0; x < coarse_cols; ++x, in += step) out[x] = in[0];
    }
  }
  const cv::Mat coarse = prepare(sampled, coarse_prepared_store_);
  cv::Mat mask = Scratch(coarse_mask_store_, coarse.size(), CV_8U);
  classify(coarse, true, mask);
  // Group the candidate cells by tiles of kTile x kTile cells, 8-connected tiles together:
  // labelling a tile grid is ~60x cheaper than labelling the coarse mask itself.
  windows_.clear();
  NonZeroPoints(mask, points_);
  // A blob that can be the marker has radius >= factor (as acquire_downsample chooses it), so it
  // holds at least two 8-adjacent sample points: a lone lit sample is a speck of background texture.
  if (min_blob_radius_px() >= factor) {
    auto alone = [&](const cv::Point& p) {
      for (int y = std::max(0, p.y - 1); y <= std::min(mask.rows - 1, p.y + 1); ++y) {
        const uchar* row = mask.ptr<uchar>(y);
        for (int x = std::max(0, p.x - 1); x <= std::min(mask.cols - 1, p.x + 1); ++x) {
          if ((x != p.x || y != p.y) && row[x]) return false;
        }
      }
      return true;
    };
    points_.erase(std::remove_if(points_.begin(), points_.end(), alone), points_.end());
  }
  if (points_.empty()) return;
  const cv::Size grid((coarse_cols + kTile - 1) / kTile, (coarse_rows + kTile - 1) / kTile);
  cv::Mat tiles = Scratch(tiles_store_, grid, CV_8U);
  tiles.setTo(0);
  for (const cv::Point& p : points_) tiles.at<uchar>(p.y / kTile, p.x / kTile) = 255;
  cv::Mat labels = Scratch(coarse_labels_store_, grid, CV_32S);
  int count = 0;
  cv::parallel_for_(cv::Range(0, 1), [&](const cv::Range&) {  // Inline: see analyse().
    count = cv::connectedComponentsWithStats(tiles, labels, coarse_stats_, coarse_centroids_, 8,
                                             CV_32S);
  });
  // The cells' own bounding box per tile group, so windows stay tight.
  boxes_.assign(static_cast<size_t>(count), cv::Rect());
  for (const cv::Point& p : points_) {
    cv::Rect& box = boxes_[static_cast<size_t>(labels.at<int>(p.y / kTile, p.x / kTile))];
    box = box.empty() ? cv::Rect(p.x, p.y, 1, 1) : (box | cv::Rect(p.x, p.y, 1, 1));
  }
  // Each group becomes a full-resolution window: its cells plus one cell all round.
  for (int i = 1; i < count; ++i) {
    const cv::Rect& cells = boxes_[static_cast<size_t>(i)];
    const int x0 = cells.x - 1, y0 = cells.y - 1;
    const int x1 = cells.x + cells.width + 1, y1 = cells.y + cells.height + 1;
    const int right = x1 >= coarse_cols ? region.width : x1 * factor;
    const int bottom = y1 >= coarse_rows ? region.height : y1 * factor;
    const cv::Rect window(region.x + x0 * factor, region.y + y0 * factor,
                          right - x0 * factor, bottom - y0 * factor);
    windows_.push_back(window & frame_rect);
  }
  // Overlapping windows merge, so a blob is analysed (and completed) once.
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t a = 0; a < windows_.size() && !merged; ++a) {
      for (size_t b = a + 1; b < windows_.size(); ++b) {
        if ((windows_[a] & windows_[b]).empty()) continue;
        windows_[a] |= windows_[b];
        windows_.erase(windows_.begin() + static_cast<std::ptrdiff_t>(b));
        merged = true;
        break;
      }
    }
  }
  const size_t first = blobs->size();
  for (const cv::Rect& window : windows_) complete_blobs(frame, window, blobs);
  // Regions grown around clipped blobs may overlap: keep each blob once.
  std::sort(blobs->begin() + static_cast<std::ptrdiff_t>(first), blobs->end(), CentroidBefore);
  blobs->erase(std::unique(blobs->begin() + static_cast<std::ptrdiff_t>(first), blobs->end(),
                           SameBlob),
               blobs->end());
}

}  // namespace softsight
