#include "softsight/track/colour_tracker.h"

#include <algorithm>
#include <cmath>
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

void CheckFrame(const cv::Mat& frame) {
  if (frame.empty() || frame.type() != CV_8UC3) {
    throw InputError("colour tracking needs 8-bit BGR colour frames, got " +
                     (frame.empty() ? std::string("an empty frame")
                                    : cv::typeToString(frame.type()) + " frames"));
  }
}

int MorphShape(ColourParams::Shape shape) {
  switch (shape) {
    case ColourParams::Shape::kRect: return cv::MORPH_RECT;
    case ColourParams::Shape::kCross: return cv::MORPH_CROSS;
    case ColourParams::Shape::kEllipse: break;
  }
  return cv::MORPH_ELLIPSE;
}

// The coarse test: hue widened by kCoarseHueSlack each side, lower S and V bounds lowered by a
// quarter and the upper ones raised a quarter of the way to 255.
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
  return true;
}

HsvBox HsvBox::Make(HsvRange h, HsvRange s, HsvRange v) {
  HsvBox box;
  if (h.lo <= h.hi) {
    box.lower = cv::Scalar(h.lo, s.lo, v.lo);
    box.upper = cv::Scalar(h.hi, s.hi, v.hi);
    return box;
  }
  // Wrapping hue (red: 170..10): rotate hue so the range starts at 0, one inRange then tests it.
  box.shift = true;
  box.lut.create(1, 256, CV_8UC3);
  for (int i = 0; i < 256; ++i) {
    const int hue = i < 180 ? (i - h.lo + 180) % 180 : 255;  // 8-bit hue never exceeds 179.
    box.lut.at<cv::Vec3b>(0, i) = cv::Vec3b(static_cast<uchar>(hue), static_cast<uchar>(i),
                                            static_cast<uchar>(i));
  }
  box.lower = cv::Scalar(0, s.lo, v.lo);
  box.upper = cv::Scalar(h.hi + 180 - h.lo, s.hi, v.hi);
  return box;
}

ColourTracker::ColourTracker(const ColourParams& params) : params_(params) {
  CV_Assert(params_.Check(nullptr));
  const int filter_radius = params_.filter == ColourParams::Filter::kNone ? 0
                                                                          : params_.filter_ksize / 2;
  const int morph_radius = params_.morph_size / 2;
  if (params_.morph_size > 1) {
    kernel_ = cv::getStructuringElement(MorphShape(params_.morph_shape),
                                        cv::Size(params_.morph_size, params_.morph_size));
  }
  // Opening then closing is four erosions/dilations, each reaching one radius further.
  margin_px_ = filter_radius + 4 * morph_radius + 1;
  fine_box_ = HsvBox::Make(params_.h, params_.s, params_.v);
  coarse_box_ = CoarseBox(params_);
  acquire_roi_ = params_.roi;
}

void ColourTracker::reset() {
  last_px_.reset();
  velocity_px_ = cv::Point2d(0, 0);
  tracking_ = false;
  acquire_roi_ = params_.roi;
}

void ColourTracker::init(const cv::Mat& frame_bgr, const cv::Rect& hint) {
  CheckFrame(frame_bgr);
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
  // A new selection is a new calibration: learn area and threshold again, inside the hint.
  params_.roi = hint & frame_rect;
  reset();
  reference_area_px_.reset();
  auto_threshold_.reset();
  frame_size_ = frame_bgr.size();
  report(acquire(frame_bgr));
}

Observation ColourTracker::update(const cv::Mat& frame_bgr) {
  CheckFrame(frame_bgr);
  if (frame_bgr.size() != frame_size_) {
    if (!frame_size_.empty()) reset();
    frame_size_ = frame_bgr.size();
  }
  std::optional<ColourBlob> blob;
  if (tracking_ && params_.window_px > 0) {
    blob = track_in_windows(frame_bgr);
  } else if (tracking_) {
    // Whole-frame tracking (window 0): the same choice as in a window, the nearest blob.
    const cv::Point2d predicted = *last_px_ + velocity_px_;
    find_blobs(frame_bgr, acquire_downsample(), &blobs_);
    last_search_px_ = cv::Rect(cv::Point(0, 0), frame_bgr.size());
    double best = std::numeric_limits<double>::infinity();
    for (const ColourBlob& b : blobs_) {
      const double d = cv::norm(b.centroid_px - predicted);
      if (acceptable(b) && d < best) {
        best = d;
        blob = b;
      }
    }
  }
  if (!blob) blob = acquire(frame_bgr);
  return report(blob);
}

Observation ColourTracker::report(const std::optional<ColourBlob>& blob) {
  Observation obs;
  if (!blob) {
    tracking_ = false;
    velocity_px_ = cv::Point2d(0, 0);
    return obs;
  }
  if (!reference_area_px_) {
    reference_area_px_ = blob->area_px;
    reference_circularity_ = blob->circularity;
  }
  velocity_px_ = tracking_ ? blob->centroid_px - *last_px_ : cv::Point2d(0, 0);
  last_px_ = blob->centroid_px;
  tracking_ = true;
  acquire_roi_.reset();
  obs.position_px = blob->centroid_px;
  obs.score = blob->area_px / *reference_area_px_;
  return obs;
}

bool ColourTracker::acceptable(const ColourBlob& b) const {
  if (b.clipped || b.area_px < params_.min_area_px) return false;
  if (params_.max_area_px > 0 && b.area_px > params_.max_area_px) return false;
  if (b.circularity < params_.min_circularity) return false;
  if (reference_area_px_) {
    if (b.area_px < params_.min_area_fraction * *reference_area_px_) return false;
    if (params_.max_area_factor > 0 && b.area_px > params_.max_area_factor * *reference_area_px_) {
      return false;
    }
  }
  return true;
}

std::optional<ColourBlob> ColourTracker::track_in_windows(const cv::Mat& frame) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  const cv::Point2d predicted = *last_px_ + velocity_px_;
  // The window must hold the whole marker with room to move: at least two diameters.
  const double ref_radius = std::sqrt(reference_area_px_.value_or(0.0) / CV_PI);
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
    const ColourBlob* best = nullptr;
    double best_dist = std::numeric_limits<double>::infinity();
    for (const ColourBlob& b : blobs_) {
      if (!acceptable(b)) continue;
      const double d = cv::norm(b.centroid_px - predicted);
      if (d < best_dist) {
        best_dist = d;
        best = &b;
      }
    }
    // A blob cut by the window's border may be the marker extending outside, and nearer than
    // the best complete one: never report a clipped centroid, look wider instead.
    bool nearer_clipped = false;
    for (const ColourBlob& b : blobs_) {
      if (b.clipped && DistanceToRect(predicted, b.bbox_px) < best_dist) nearer_clipped = true;
    }
    if (best && !nearer_clipped) return *best;
    if (window == frame_rect) break;
  }
  return std::nullopt;
}

std::optional<ColourBlob> ColourTracker::acquire(const cv::Mat& frame) {
  const cv::Rect frame_rect(cv::Point(0, 0), frame.size());
  cv::Rect region = frame_rect;
  if (acquire_roi_) {
    region = *acquire_roi_ & frame_rect;
    if (region.empty()) return std::nullopt;  // ROI outside this (smaller) frame.
  }
  if (params_.auto_bgr && !auto_threshold_) learn_auto_threshold(frame, region);
  last_search_px_ = region;
  blobs_.clear();
  const int factor = acquire_downsample();
  if (factor > 1 && region.area() >= kCoarseMinArea) {
    coarse_to_fine(frame, region, factor, &blobs_);
  } else {
    complete_blobs(frame, region, &blobs_);
  }
  std::sort(blobs_.begin(), blobs_.end(), CentroidBefore);

  // Before the first acquisition the marker is the largest acceptable blob; afterwards the one
  // whose area and shape match the marker's best, preferring the neighbourhood of the last
  // known position.
  const double diagonal = std::hypot(frame.cols, frame.rows);
  const cv::Rect2d roi_area = acquire_roi_ ? cv::Rect2d(acquire_roi_->x - 0.5, acquire_roi_->y - 0.5,
                                                        acquire_roi_->width, acquire_roi_->height)
                                           : cv::Rect2d();
  const ColourBlob* best = nullptr;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const ColourBlob& b : blobs_) {
    if (!acceptable(b)) continue;
    if (acquire_roi_ && !roi_area.contains(b.centroid_px)) continue;
    double cost = -b.area_px;
    if (reference_area_px_) {
      cost = std::abs(std::log(b.area_px / *reference_area_px_)) +
             std::abs(b.circularity - reference_circularity_);
      if (last_px_) cost += cv::norm(b.centroid_px - *last_px_) / diagonal;
    }
    if (cost < best_cost) {
      best_cost = cost;
      best = &b;
    }
  }
  if (!best) return std::nullopt;
  return *best;
}

int ColourTracker::acquire_downsample() const {
  if (params_.acquire_downsample > 0) return params_.acquire_downsample;
  // The smallest blob that can count as the marker must hold sample points of the coarse grid
  // (spacing f): a disc of radius r >= f / sqrt(2) holds one, r >= f holds at least three.
  const double min_area =
      std::max(params_.min_area_px, params_.min_area_fraction * reference_area_px_.value_or(0.0));
  const double radius = std::sqrt(min_area / CV_PI);
  int factor = 1;
  while (factor < 8 && radius >= 2.0 * factor) factor *= 2;
  return factor;
}

void ColourTracker::find_blobs(const cv::Mat& frame_bgr, int downsample,
                               std::vector<ColourBlob>* blobs) {
  CheckFrame(frame_bgr);
  blobs->clear();
  const cv::Rect frame_rect(cv::Point(0, 0), frame_bgr.size());
  if (params_.auto_bgr && !auto_threshold_) learn_auto_threshold(frame_bgr, frame_rect);
  if (downsample > 1) {
    coarse_to_fine(frame_bgr, frame_rect, downsample, blobs);
  } else {
    complete_blobs(frame_bgr, frame_rect, blobs);
  }
  std::sort(blobs->begin(), blobs->end(), CentroidBefore);
}

void ColourTracker::classify(const cv::Mat& src, const HsvBox& box, int distance_threshold,
                             cv::Mat& mask) {
  cv::Mat work = Scratch(hsv_store_, src.size(), CV_8UC3);
  if (params_.auto_bgr) {
    const cv::Vec3b c = *params_.auto_bgr;
    cv::absdiff(src, cv::Scalar(c[0], c[1], c[2]), work);
    // Mean absolute channel difference: a colour distance 0..255.
    cv::transform(work, mask, cv::Matx13f(1.f / 3, 1.f / 3, 1.f / 3));
    cv::threshold(mask, mask, distance_threshold, 255, cv::THRESH_BINARY_INV);
    return;
  }
  cv::cvtColor(src, work, cv::COLOR_BGR2HSV);
  if (box.shift) cv::LUT(work, box.lut, work);
  cv::inRange(work, box.lower, box.upper, mask);
}

void ColourTracker::learn_auto_threshold(const cv::Mat& frame, const cv::Rect& region) {
  // Otsu's two classes of minimal within-class variance, on the colour distance to the nominal
  // colour, over the first acquisition's region (the ROI or hint if given: the marker is then a
  // large share of the pixels, which is where Otsu's split is meaningful).
  cv::Mat src = frame(region);
  cv::Mat filtered = src;
  if (params_.filter == ColourParams::Filter::kGaussian) {
    filtered = Scratch(filtered_store_, region.size(), CV_8UC3);
    cv::GaussianBlur(src, filtered, cv::Size(params_.filter_ksize, params_.filter_ksize), 0);
  } else if (params_.filter == ColourParams::Filter::kMedian) {
    filtered = Scratch(filtered_store_, region.size(), CV_8UC3);
    cv::medianBlur(src, filtered, params_.filter_ksize);
  }
  cv::Mat work = Scratch(hsv_store_, region.size(), CV_8UC3);
  cv::Mat distance = Scratch(mask_store_, region.size(), CV_8U);
  const cv::Vec3b c = *params_.auto_bgr;
  cv::absdiff(filtered, cv::Scalar(c[0], c[1], c[2]), work);
  cv::transform(work, distance, cv::Matx13f(1.f / 3, 1.f / 3, 1.f / 3));
  const double threshold =
      cv::threshold(distance, distance, 0, 255, cv::THRESH_BINARY_INV | cv::THRESH_OTSU);
  auto_threshold_ = static_cast<int>(threshold);
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
  // parallel region of a single task: OpenCV executes parallel loops nested in it inline.
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
  const cv::Mat src = frame(extended);

  // 1. Filter. The source is a view into the frame, so near the frame's edges the filter sees
  //    the same border as a whole-frame pass would.
  cv::Mat filtered = src;
  if (params_.filter == ColourParams::Filter::kGaussian) {
    filtered = Scratch(filtered_store_, extended.size(), CV_8UC3);
    cv::GaussianBlur(src, filtered, cv::Size(params_.filter_ksize, params_.filter_ksize), 0);
  } else if (params_.filter == ColourParams::Filter::kMedian) {
    filtered = Scratch(filtered_store_, extended.size(), CV_8UC3);
    cv::medianBlur(src, filtered, params_.filter_ksize);
  }

  // 2. Binarise.
  cv::Mat mask = Scratch(mask_store_, extended.size(), CV_8U);
  classify(filtered, fine_box_, auto_threshold_.value_or(0), mask);

  // 3. Opening then closing, only where it can change anything: outside the bounding box of the
  //    marker-coloured pixels the mask is 0 and stays 0 (opening only removes, closing only fills
  //    between pixels), so morphology and labelling work on that box plus the reach of the four
  //    passes. Beyond the box the parent mask holds zeros, exactly what a whole pass would read.
  const cv::Rect extended_local(cv::Point(0, 0), extended.size());
  cv::Rect active = cv::boundingRect(mask);
  if (active.empty()) return;
  if (!kernel_.empty()) {
    const int reach = 4 * (params_.morph_size / 2) + 1;
    active = cv::Rect(active.x - reach, active.y - reach, active.width + 2 * reach,
                      active.height + 2 * reach) &
             extended_local;
    cv::Mat opened = Scratch(morph_store_, active.size(), CV_8U);
    cv::morphologyEx(mask(active), opened, cv::MORPH_OPEN, kernel_);
    cv::Mat cleaned = mask(active);
    cv::morphologyEx(opened, cleaned, cv::MORPH_CLOSE, kernel_);
  }

  // 4. Blobs of the region proper (the margin only fed the filters); the region is 0 outside
  //    `labelled`, so its components are the region's components.
  const cv::Rect inner_local(region.tl() - extended.tl(), region.size());
  const cv::Rect labelled = active & inner_local;
  if (labelled.empty()) return;
  const cv::Point offset = labelled.tl() - inner_local.tl();  // Of `labelled` in the region.
  cv::Mat labels = Scratch(labels_store_, labelled.size(), CV_32S);
  const int count =
      cv::connectedComponentsWithStats(mask(labelled), labels, stats_, centroids_, 8, CV_32S);
  const bool open_left = region.x > 0;
  const bool open_top = region.y > 0;
  const bool open_right = region.x + region.width < frame.cols;
  const bool open_bottom = region.y + region.height < frame.rows;
  for (int i = 1; i < count; ++i) {
    const int* s = stats_.ptr<int>(i);
    const cv::Rect box(s[cv::CC_STAT_LEFT], s[cv::CC_STAT_TOP], s[cv::CC_STAT_WIDTH],
                       s[cv::CC_STAT_HEIGHT]);
    const cv::Rect in_region = box + offset;
    ColourBlob blob;
    blob.area_px = s[cv::CC_STAT_AREA];
    blob.clipped = (open_left && in_region.x == 0) || (open_top && in_region.y == 0) ||
                   (open_right && in_region.x + in_region.width == region.width) ||
                   (open_bottom && in_region.y + in_region.height == region.height);
    blob.bbox_px = in_region + region.tl();
    if (!blob.clipped) {
      if (blob.area_px < params_.min_area_px) continue;
      if (params_.max_area_px > 0 && blob.area_px > params_.max_area_px) continue;
      // 5. Centroid from the binary moments of this blob alone (another blob may share its
      //    bounding box), then the exact integer offset of the box in the frame.
      cv::Mat blob_mask = Scratch(blob_store_, box.size(), CV_8U);
      cv::compare(labels(box), i, blob_mask, cv::CMP_EQ);
      const cv::Moments mo = cv::moments(blob_mask, true);
      blob.centroid_px = cv::Point2d(mo.m10 / mo.m00 + blob.bbox_px.x,
                                     mo.m01 / mo.m00 + blob.bbox_px.y);
      // Polar moment of the pixels as unit squares (each adds 1/6 about its own centre).
      const double polar = mo.mu20 + mo.mu02 + mo.m00 / 6.0;
      blob.circularity = mo.m00 * mo.m00 / (2.0 * CV_PI * polar);
    }
    blobs->push_back(blob);
  }
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
  cv::Mat coarse = Scratch(coarse_store_, cv::Size(coarse_cols, coarse_rows), CV_8UC3);
  cv::resize(src, coarse, coarse.size(), 0, 0, cv::INTER_NEAREST_EXACT);
  cv::Mat mask = Scratch(coarse_mask_store_, coarse.size(), CV_8U);
  const int threshold = std::min(255, auto_threshold_.value_or(0) * 5 / 4 + 4);
  classify(coarse, coarse_box_, threshold, mask);
  // Group the candidate cells by tiles of kTile x kTile cells, 8-connected tiles together:
  // labelling a tile grid is ~60x cheaper than labelling the coarse mask itself.
  windows_.clear();
  cv::findNonZero(mask, points_);
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
