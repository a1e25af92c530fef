#include "softsight/track/template_tracker.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "softsight/core/error.h"
#include "softsight/track/tracker.h"
#include "track/match_kernels.h"
#include "track/position_sigma.h"
#include "track/template_parts.h"
#include "track/template_tracker_impl.h"
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

namespace template_internal {

namespace {
// How much less isolated a marker may stand out in its chromaticity than in the matched channel
// and still be reported from it (SelectionBlobs::chroma_reports).
constexpr double kIsolationTie = 0.03;

// What a selected template shows of its marker: its blob in the matched channel and, for a
// coloured selection, in its chromaticity. SetTemplate learns from it, and JudgeBox asks of the
// same blob whether a box is centred on it.
struct SelectionBlobs {
  bool in_gray = false;
  BlobMeter gray;
  cv::Point2d gray_centroid;
  cv::Mat projection;  // The BGR weights giving the matched channel's blob channel.
  bool has_axis = false;
  ChromaAxis axis;
  bool in_chroma = false;
  BlobMeter chroma;
  cv::Point2d chroma_centroid;
  // The gray blob's core is of a colour (kMinCoreChroma or more from grey), not a white or black
  // dot's, whose chromaticity is its surroundings' and the camera noise's.
  bool coloured = false;
  // The marker's centre is reported from its chromaticity's blob where it stands out more there
  // than in the matched channel (a shaded coloured dome: 0.59-0.77 against 0.24-0.43), and a
  // coloured marker's also on a tie (within kIsolationTie): its chromaticity, which shading
  // leaves, not its gray levels (a yellow dome on wood stands out 0.58 and 0.59, and its gray blob,
  // pulled towards the light by the dome's lit top, lay 1.2 px above its centre in every frame). A
  // yellow dot on a green cart, clearly better in the matched channel (0.51 against 0.46), keeps it
  // (its chromaticity blurs with the motion).
  bool chroma_reports() const {
    const double tie = coloured ? kIsolationTie : 0.0;
    return in_chroma && (!in_gray || chroma.isolation() > gray.isolation() - tie);
  }
};

// `selection_bgr`: the selection's BGR pixels (of the template's size), or empty.
SelectionBlobs MeasureSelection(const cv::Mat& templ, const cv::Mat& mask,
                                const cv::Mat& selection_bgr) {
  SelectionBlobs seen;
  seen.in_gray = LearnTemplateBlob(templ, mask, &seen.projection, &seen.gray, &seen.gray_centroid);
  if (!selection_bgr.empty() && selection_bgr.size() == templ.size() &&
      LearnChromaAxis(selection_bgr, &seen.axis)) {
    seen.has_axis = true;
    cv::Mat channel;
    ChromaChannel(selection_bgr, seen.axis, channel);
    seen.in_chroma = seen.chroma.Learn(channel, mask, &seen.chroma_centroid);
    cv::Vec3d core;
    if (seen.in_gray &&
        CoreColour(selection_bgr, seen.gray_centroid,
                   std::max(1.5, 0.6 * std::sqrt(seen.gray.area() / CV_PI)), &core)) {
      seen.coloured = IsColouredCore(core);
    }
  }
  return seen;
}
}  // namespace

// Converts the part `rect` of the frame (clipped to it) for the windows of this update.
void TemplateTracker::ConvertAround(const cv::Mat& frame, const cv::Rect& rect) {
  StopSharingWindowSums(zncc_);  // native_ is about to change.
  native_rect_ = rect & cv::Rect(0, 0, frame.cols, frame.rows);
  if (native_rect_.empty()) return;
  ToNative(frame(native_rect_), native_);
  // The windows matched next (the search, the measurement, the pose rungs) mostly lie in it:
  // its rows' prefix sums once, not each window's again (a gray native_ only).
  ShareWindowSums(native_, zncc_);
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
  const cv::Rect overlap = rect & native_rect_;
  if (frame.channels() == 3 && !params_.colour && overlap.area() * 2 > rect.area()) {
    // Mostly converted already (the blob's window around the match, a pose rung's window: a
    // few pixels beyond the near search's, issue 45: their conversion was 7 % of a frame of
    // ViSP's mire-2 in ZNCC): the part inside native_ copied, only the strips around it
    // converted. The conversion is per pixel, so every level is the one a whole conversion
    // gives.
    out.create(rect.size(), CV_8UC1);
    native_(overlap - native_rect_.tl()).copyTo(out(overlap - rect.tl()));
    const auto convert = [&](const cv::Rect& strip) {
      if (strip.empty()) return;
      cv::Mat part = out(strip - rect.tl());  // Of the right size and type: written in place.
      ToNative(frame(strip), part);
      CV_DbgAssert(part.data == out.ptr(strip.y - rect.y, strip.x - rect.x));
    };
    convert(cv::Rect(rect.x, rect.y, rect.width, overlap.y - rect.y));  // Above.
    convert(cv::Rect(rect.x, overlap.br().y, rect.width, rect.br().y - overlap.br().y));  // Below.
    // Beside it, as at least 16 columns (the vector kernel's; a narrower strip would take the
    // scalar reference, at several times the cost), overlapping the copied part with the same
    // levels.
    const int wide = std::min(16, rect.width);
    if (overlap.x > rect.x) {
      convert(cv::Rect(rect.x, overlap.y, std::max(overlap.x - rect.x, wide), overlap.height));
    }
    if (overlap.br().x < rect.br().x) {
      const int width = std::max(rect.br().x - overlap.br().x, wide);
      convert(cv::Rect(rect.br().x - width, overlap.y, width, overlap.height));
    }
    return;
  }
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
    ProjectLevels(frame, projection_, out);  // cv::transform, in vector lanes.
  } else {
    cv::cvtColor(frame, out, cv::COLOR_BGR2GRAY);
  }
}

void TemplateTracker::SetTemplate(const cv::Mat& templ, const std::string& where,
                                  const cv::Mat& selection_bgr) {
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
  const SelectionBlobs seen = MeasureSelection(templ, MaskFor(templ.size()), selection_bgr);
  blob_ok_ = seen.in_gray;
  blob_ = seen.gray;
  blob_anchor_px_ = seen.gray_centroid;
  blob_projection_ = seen.projection;
  if (seen.has_axis) chroma_ = seen.axis;
  // Both channels show the marker but put its centre apart (a dome's shaded flank is dark in
  // gray and of the marker's tint in chroma; the two carts' yellow dots, 1.8-2.2 px): which of
  // the two is the marker's centre is uncertain by that much, in every frame.
  anchor_spread_px_ =
      seen.in_chroma && seen.in_gray ? cv::norm(seen.chroma_centroid - seen.gray_centroid) : 0.0;
  chroma_ok_ = seen.chroma_reports();
  if (chroma_ok_) {
    blob_ = seen.chroma;
    blob_anchor_px_ = seen.chroma_centroid;
    blob_ok_ = true;
  }
  core_colour_.reset();
  if (!selection_bgr.empty() && selection_bgr.size() == templ.size()) {
    // The blob's core, or a sixth of the box around its centre without a blob.
    const cv::Point2d core = blob_ok_ ? blob_anchor_px_ : HalfSize(templ.size());
    core_radius_px_ = std::max(1.5, blob_ok_ ? 0.6 * std::sqrt(blob_.area() / CV_PI)
                                             : std::min(templ.cols, templ.rows) / 6.0);
    cv::Vec3d chroma;
    if (CoreColour(selection_bgr, core, core_radius_px_, &chroma)) core_colour_ = chroma;
  }
  shade_free_.release();
  if (core_colour_ && IsColouredCore(*core_colour_)) {
    LogChromaticity(selection_bgr, shade_free_);
    shade_free_key_ = -1;
  }
  blob_reported_ = blob_ok_ && (params_.report == TemplateReport::kCentre ||
                                (chroma_ok_ && params_.report == TemplateReport::kSymmetry));
  if (blob_reported_) anchor_px_ = blob_anchor_px_;
  if ((params_.report == TemplateReport::kSymmetry && !blob_reported_) ||
      (params_.report == TemplateReport::kCentre && !blob_ok_)) {
    // The turned template is matched unmasked: a mask shrunk with it would cut the rim of a
    // disc, which is what carries its position.
    double strength = 0.0;
    const cv::Point2d centre =
        blob_ok_ ? MarkerSymmetryCentre(templ, blob_anchor_px_, blob_.area(), &strength)
                 : SymmetryCentre(templ, &strength);
    if (strength >= kMinSymmetry) anchor_px_ = centre;
  }
  rungs_.clear();
  scaled_.clear();
  rung_ = kRungsBelow;
  turn_ = 0;
  turn_step_ = 0;
  pose_zncc_ = kNoRival;
  Rung& selected = rungs_[RungKey(rung_, turn_)];
  selected.tried = true;
  selected.templ = std::move(first);
  selected.anchor = anchor_px_;
  selected.blob_anchor = blob_anchor_px_;
  RestoreWorkingTemplate();
}

namespace {
cv::Point2d Apply(const cv::Matx23d& m, const cv::Point2d& p) {
  return {m(0, 0) * p.x + m(0, 1) * p.y + m(0, 2), m(1, 0) * p.x + m(1, 1) * p.y + m(1, 2)};
}
}  // namespace

// The rung of the ladder at `scale` and `turn` (any whole number of steps: taken round the
// circle), prepared on first use; nullptr when that scale is impossible.
const Rung* TemplateTracker::RungAt(int scale, int turn) {
  if (scale < 0 || scale > kRungsBelow + kRungsAbove) return nullptr;
  turn = ((turn % kTurns) + kTurns) % kTurns;
  Rung& rung = rungs_[RungKey(scale, turn)];
  if (!rung.tried) {
    rung.tried = true;
    const double factor = std::pow(kScaleStep, scale - kRungsBelow);
    const cv::Size size(static_cast<int>(std::lround(original_.cols * factor)),
                        static_cast<int>(std::lround(original_.rows * factor)));
    if (std::min(size.width, size.height) >= kMinRungPx &&
        static_cast<int>(size.area()) * original_.channels() <= kMaxTemplateValues &&
        size.width * original_.channels() <= kMaxTemplateRowBytes) {
      cv::Mat turned, mask;
      cv::Matx23d map;
      auto [at, fresh] = scaled_.try_emplace(scale);
      if (fresh) {
        at->second.image = ScaledTemplate(original_, size);
        at->second.mask = MaskFor(size);
      }
      // Already of `size`: TurnedTemplate scales it no further.
      TurnedTemplate(at->second.image, size, turn * kTurnStepDeg, at->second.mask, &turned, &mask,
                     &map);
      if (rung.templ.Prepare(turned, mask)) {
        rung.anchor = Apply(map, ToRung(anchor_px_, size));
        rung.blob_anchor = Apply(map, ToRung(blob_anchor_px_, size));
      }
    }
  }
  return rung.templ.empty() ? nullptr : &rung;
}

void TemplateTracker::RestoreWorkingTemplate() {
  const PreparedTemplate& rung = current().templ;
  working_.Prepare(rung.image(), rung.mask());
  working_mask_ = rung.mask().empty() ? cv::Mat() : rung.mask().clone();
  working_key_ = RungKey(rung_, turn_);
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

TemplateTracker::BoxVerdict TemplateTracker::JudgeBox(const cv::Mat& native,
                                                      const cv::Mat& selection_bgr) const {
  // A coloured marker may stand out only in its chromaticity where a groove, a shadow or wood
  // grain beside it is as dark as it in the matched channel: SetTemplate measures its blob there.
  const SelectionBlobs seen = MeasureSelection(native, MaskFor(native.size()), selection_bgr);
  BoxVerdict verdict;
  if (!seen.in_gray && !seen.in_chroma) {
    verdict.contrast = std::max(seen.gray.learned_contrast(),
                                seen.has_axis ? seen.chroma.learned_contrast() : 0.0);
    return verdict;
  }
  const BlobMeter& found = seen.in_gray ? seen.gray : seen.chroma;
  verdict.marker = true;
  verdict.centroid = seen.in_gray ? seen.gray_centroid : seen.chroma_centroid;
  verdict.contrast = found.learned_contrast();
  verdict.blob_box = found.blob_box();
  verdict.area = found.area();
  const bool chroma = seen.chroma_reports();
  verdict.reported_centroid = chroma ? seen.chroma_centroid : seen.gray_centroid;
  verdict.reported_area = chroma ? seen.chroma.area() : seen.gray.area();
  return verdict;
}

void TemplateTracker::PrepareSelection(const cv::Mat& frame_bgr, const cv::Rect& box,
                                       cv::Mat& native) {
  projection_.release();
  if (!params_.colour && params_.contrast_gray && frame_bgr.channels() == 3) {
    projection_ = ContrastProjection(frame_bgr(box));
  }
  ToNative(frame_bgr(box), native);
}

// The box a person dragged, or the same box widened to hold the marker's surroundings. A person
// drags the box around the whole marker, so the marker is the largest blob at its centre that
// lies inside the box dragged (give or take a cut rim) with kMinSurroundPx of surroundings on
// every side of it in the template. A box drawn tight around the marker shows only what stands
// out inside it (a domed disc's highlight): its rim reaches the box's edge, so the disc itself
// needs a wider box to stand out from. Empty when no box shows a marker so; `contrast` gets the
// most levels anything at the centre stood out by, `off_centre` how far (in its own radii) from
// the centre of the box dragged lay the farthest blob refused for that alone.
cv::Rect TemplateTracker::BoxShowingTheMarker(const cv::Mat& frame_bgr, const cv::Rect& hint,
                                              cv::Mat& native, double* contrast,
                                              double* off_centre) {
  const cv::Rect frame_rect(0, 0, frame_bgr.cols, frame_bgr.rows);
  const int side = std::min(hint.width, hint.height);
  const int rim = std::max(2, side / 6);  // How far a blob may stick out of the box dragged.
  const cv::Rect allowed(hint.x - rim, hint.y - rim, hint.width + 2 * rim, hint.height + 2 * rim);
  const cv::Point2d hint_centre = cv::Point2d(hint.tl()) + HalfSize(hint.size());
  const bool hint_at_frame_edge = (hint & frame_rect) != hint || hint.x == 0 || hint.y == 0 ||
                                  hint.br().x == frame_rect.width ||
                                  hint.br().y == frame_rect.height;
  *off_centre = 0;  // The most any blob otherwise acceptable lay off the box's centre, in radii.
  // The reported blob lies on the box's centre (kMaxBlobOffBoxCentre); a box cut by the frame's
  // edge may hold only part of a marker, whose centre is then anywhere in it.
  const auto centred = [&](const BoxVerdict& v, const cv::Rect& box) {
    if (hint_at_frame_edge || v.reported_area <= 0) return true;
    const double off = cv::norm(v.reported_centroid + cv::Point2d(box.tl()) - hint_centre) /
                       std::sqrt(v.reported_area / CV_PI);
    *off_centre = std::max(*off_centre, off);
    return off <= kMaxBlobOffBoxCentre;
  };
  const auto acceptable = [&](const BoxVerdict& v, const cv::Rect& box) {
    const cv::Rect blob = v.blob_box + box.tl();
    const cv::Point2d at = v.centroid + cv::Point2d(box.tl());
    // An edge of the frame cannot be widened past: there the blob needs no surroundings.
    return v.marker && (blob & allowed) == blob && at.x >= hint.x - 0.5 &&
           at.y >= hint.y - 0.5 && at.x <= hint.br().x - 0.5 && at.y <= hint.br().y - 0.5 &&
           (blob.x - box.x >= kMinSurroundPx || box.x == 0) &&
           (blob.y - box.y >= kMinSurroundPx || box.y == 0) &&
           (box.br().x - blob.br().x >= kMinSurroundPx || box.br().x == frame_rect.width) &&
           (box.br().y - blob.br().y >= kMinSurroundPx || box.br().y == frame_rect.height) &&
           centred(v, box);
  };
  *contrast = 0;
  cv::Rect best;
  double best_area = 0;
  for (const double fraction : {0.0, 0.25, 0.5, 1.0}) {
    const int margin = fraction == 0.0 ? 0 : std::max(kMinSurroundPx,
                                                      static_cast<int>(std::lround(fraction * side)));
    const cv::Rect box = cv::Rect(hint.x - margin, hint.y - margin, hint.width + 2 * margin,
                                  hint.height + 2 * margin) & frame_rect;
    if (static_cast<int>(box.area()) * frame_bgr.channels() > kMaxTemplateValues ||
        box.width * frame_bgr.channels() > kMaxTemplateRowBytes) {
      break;
    }
    PrepareSelection(frame_bgr, box, native);
    const BoxVerdict verdict =
        JudgeBox(native, frame_bgr.channels() == 3 ? frame_bgr(box) : cv::Mat());
    *contrast = std::max(*contrast, verdict.contrast);
    // A wider box wins only with a clearly larger blob (not the same one measured again).
    if (acceptable(verdict, box) && verdict.area > 1.25 * best_area) {
      best = box;
      best_area = verdict.area;
    }
  }
  if (!best.empty()) PrepareSelection(frame_bgr, best, native);
  return best;
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
    cv::Mat native;
    try {
      // A box a person drags must hold a marker: a blob at its centre, wholly inside it and
      // standing out from its surroundings. A box of background (or cutting a marker) would be
      // matched wherever that background looks alike, and never lost.
      double contrast = 0;
      double off_centre = 0;
      const cv::Rect box = BoxShowingTheMarker(frame_bgr, hint, native, &contrast, &off_centre);
      if (box.empty()) {
        char measured[200];
        if (off_centre > kMaxBlobOffBoxCentre) {
          std::snprintf(measured, sizeof measured,
                        "what stands out in it lies %.1f of its own radii from the box's centre, "
                        "at most %.2f allowed: a piece of the marker, or something beside it",
                        off_centre, kMaxBlobOffBoxCentre);
        } else if (contrast >= kMinBlobContrast) {
          std::snprintf(measured, sizeof measured,
                        "what stands out at its centre, by %.0f levels, is no blob lying "
                        "inside the box with its surroundings, even with the box widened",
                        contrast);
        } else {
          std::snprintf(measured, sizeof measured,
                        "nothing at its centre stands out from its surroundings: %.0f levels at "
                        "most, %.0f needed", contrast, kMinBlobContrast);
        }
        throw InputError("the box " + RectText(hint) + " holds no marker (" + measured +
                         "): drag it around a marker, centred on it, with some background on "
                         "every side");
      }
      SetTemplate(native.clone(), "template rect " + RectText(box),
                  frame_bgr.channels() == 3 ? frame_bgr(box) : cv::Mat());
      // The person showed where the marker is on this frame: the first update looks right
      // there, in a tracking window, not in a wide search that may hold look-alikes.
      last_centre_ = cv::Point2d(box.x, box.y) + HalfSize(box.size());
      selection_box_ = box;
    } catch (const InputError&) {
      projection_ = previous;
      throw;
    }
    tracking_ = true;
    scan_pending_ = true;
  } else {
    const std::string where = "template image";
    selection_box_ = cv::Rect();
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
      SetTemplate(native.clone(), where,
                  params_.image.type() == CV_8UC3 ? params_.image : cv::Mat());
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
  LookAlikeMap(templ);
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

// The look-alike scan's map (LookAlikeZncc), with the acquisition pyramid's first level.
void TemplateTracker::LookAlikeMap(const PreparedTemplate& templ) {
  if (params_.measure != MatchMeasure::kZncc) {
    MatchZncc(region_, templ, sim_, zncc_);
    return;
  }
  BuildAcquisitionPyramid(templ);
  LookAlikeZncc(region_, templ, coarse_.size() > 1 ? &coarse_[1] : nullptr, params_.min_zncc,
                sim_, look_alike_scratch_, zncc_);
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

bool TemplateTracker::Accept(const Hit& m, bool colour_agrees, bool followed) const {
  // A marker followed from frame to frame whose blob is found at the match (Verify) may change
  // its look faster than the working template follows (a segment turning under a marker, its
  // edges in the box): the motion and the blob are evidence beside the score. Never when the
  // whole region is searched, where a look-alike of the marker's colour and size could be.
  const double floor = params_.min_zncc - (colour_agrees ? kColourZnccAllowance : 0.0) -
                       (followed && blob_ok_ ? kBlobDriftAllowance : 0.0);
  if (!(m.zncc >= floor)) return false;
  switch (params_.measure) {
    case MatchMeasure::kSad: return m.score <= params_.max_sad;
    case MatchMeasure::kSsd: return m.score <= params_.max_ssd;
    case MatchMeasure::kZncc: return true;
  }
  return false;
}

bool TemplateTracker::AcceptOn(const cv::Mat& frame, const Hit& m, bool followed,
                               std::optional<ShadeFreePeak>* shaded) {
  const bool colour_agrees = ColourAgreesAt(frame, m);
  shaded->reset();
  if (Accept(m, colour_agrees, followed)) return true;
  if (!followed || !colour_agrees) return false;
  const std::optional<ShadeFreePeak> peak = ShadeFreePeakNear(frame, m.top_left);
  if (!peak || !(peak->zncc >= params_.min_zncc)) return false;
  *shaded = peak;
  return true;
}

// The first template's log-chromaticity at the placements within kShadeFreeReachPx of `origin`
// (a top-left corner), compared by ZNCC with the frame's (converted once for all of them), the
// best placed to a fraction of a pixel by a parabola through it and its neighbours on each axis.
// Absent when it cannot be judged (gray footage, a grey marker: its chromaticity is its
// surroundings' and the camera noise's), or the best lies on the edge of the placements tried
// (not a peak of them) or not wholly in the frame.
std::optional<TemplateTracker::ShadeFreePeak> TemplateTracker::ShadeFreePeakNear(
    const cv::Mat& frame, cv::Point origin) {
  if (shade_free_.empty() || frame.type() != CV_8UC3) return std::nullopt;
  constexpr int kReach = kShadeFreeReachPx;
  constexpr int kSide = 2 * kReach + 1;
  const cv::Size size = current().templ.size();
  const cv::Rect region = cv::Rect(origin - cv::Point(kReach, kReach),
                                   size + cv::Size(2 * kReach, 2 * kReach)) &
                          cv::Rect(0, 0, frame.cols, frame.rows);
  // The first template at the current rung's scale and turn, as RungAt made the rung from it,
  // kept while the rung stays.
  const int key = RungKey(rung_, turn_);
  if (shade_free_key_ != key) {
    cv::Matx23d map;
    TurnedTemplate(shade_free_, size, turn_ * kTurnStepDeg, MaskFor(size), &shade_free_rung_,
                   &shade_free_mask_, &map);
    shade_free_key_ = key;
  }
  LogChromaticity(frame(region), shade_free_region_);
  std::array<double, kSide * kSide> zncc;
  int best = 0;
  for (int i = 0; i < kSide * kSide; ++i) {
    const cv::Rect place(origin + cv::Point(i % kSide - kReach, i / kSide - kReach), size);
    zncc[i] = (place & region) == place
                  ? TwoChannelZncc(shade_free_rung_, shade_free_region_(place - region.tl()),
                                   shade_free_mask_)
                  : kNoRival;
    if (zncc[i] > zncc[best]) best = i;
  }
  const int bx = best % kSide, by = best / kSide;
  if (bx == 0 || by == 0 || bx == kSide - 1 || by == kSide - 1 || zncc[best] == kNoRival) {
    return std::nullopt;
  }
  const auto vertex = [](double before, double at, double after) {
    const double curvature = before - 2 * at + after;
    return curvature < 0 ? std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5) : 0.0;
  };
  ShadeFreePeak peak;
  peak.zncc = zncc[best];
  peak.top_left = cv::Point2d(origin + cv::Point(bx - kReach, by - kReach)) +
                  cv::Point2d(vertex(zncc[best - 1], zncc[best], zncc[best + 1]),
                              vertex(zncc[best - kSide], zncc[best], zncc[best + kSide]));
  return peak;
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
      RivalIn(sim_, best, RivalRadius(size), &rival)) {
    m.rival_zncc = params_.measure == MatchMeasure::kZncc
                       ? sim_.at<float>(rival)
                       : ZnccAt(region_, rival, templ, shape_, zncc_);
    m.rival_top_left = region.tl() + rival;
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

// Most frames the marker is within a few pixels of where its constant velocity puts it: the
// window kNearMarginPx around that (81 placements, not the 289 of the default search_margin_px)
// decides the search when its best lies inside it (not on its edge) and passes min_zncc itself
// (no allowance: a weak peak may be a look-alike beside a marker that moved elsewhere), and the
// whole window could hold no distinct rival to it (a template larger than about twice
// search_margin_px; any size without the ambiguity check). The ZNCC of a placement depends on
// its pixels alone, so this is the whole window's answer unless a higher peak lies in the rest
// of the window within the rival radius of this one (issue 45: docs/measurements.md).
// On footage that repeats frames the whole window spans the marker's last place too (a repeated
// frame shows it there): the near window around the prediction decides the same way when no
// placement of that wider window lies farther than the rival radius from its peak (a repeated
// frame puts the marker more than kNearMarginPx off a prediction that moved on: the peak is then
// on the near window's edge, or none, and the whole window is searched). ViSP's mire-2 repeats
// frames: four of its five dots searched their whole window in every frame (issue 45).
std::optional<Hit> TemplateTracker::NearSearch(const cv::Mat& frame, const cv::Point2d& predicted) {
  const int margin = params_.search_margin_px;
  if (kNearMarginPx >= margin) return std::nullopt;
  const PreparedTemplate& templ = search_template();
  const cv::Size size = templ.size();
  const bool rivals = params_.ambiguity_margin > 0;
  const int radius = RivalRadius(size);
  // The whole window's placements (top-left corners, both ends included) on repeating footage.
  cv::Rect placements;
  if (footage_repeats_) {
    const cv::Rect window =
        WindowAround(predicted, size, margin) | WindowAround(*last_centre_, size, margin);
    placements = cv::Rect(window.x, window.y, window.width - size.width, window.height - size.height);
  }
  // No placement of the whole window lies farther than the rival radius from `peak` (per axis).
  const auto no_rival_reachable = [&](cv::Point peak) {
    return peak.x - placements.x <= radius && placements.br().x - peak.x <= radius &&
           peak.y - placements.y <= radius && placements.br().y - peak.y <= radius;
  };
  if (rivals) {
    // Even a peak at the window's centre could have a rival: the near window cannot decide.
    if (footage_repeats_ ? !no_rival_reachable(placements.tl() + cv::Point(placements.width / 2,
                                                                             placements.height / 2))
                         : !NoRivalReachable(margin, {0, 0}, radius)) {
      return std::nullopt;
    }
  }
  const cv::Rect near = WindowAround(predicted, size, kNearMarginPx);
  ConvertAround(frame, cv::Rect(near.x - kAroundPx, near.y - kAroundPx,
                                near.width + 2 * kAroundPx, near.height + 2 * kAroundPx));
  const cv::Point predicted_tl = near.tl() + cv::Point(kNearMarginPx, kNearMarginPx);
  // Whether `hit` decides: passed, and no rival reachable.
  const auto decides = [&](const Hit& hit) {
    if (!Accept(hit)) return false;
    const cv::Point from_prediction = hit.top_left - predicted_tl;
    return !rivals || (footage_repeats_ ? no_rival_reachable(hit.top_left)
                                        : NoRivalReachable(margin, from_prediction, radius));
  };
  // Climbing first: the kFirstNearMarginPx window around the prediction, moved onto its best
  // while that lies on its edge, as long as it stays inside the near window (each placement's
  // score depends on its pixels alone: a peak inside the window that climbed to it is a local
  // peak of the near window, its best unless a higher one lies within kNearMarginPx of the
  // prediction too: two peaks a few pixels apart, not a marker). Most frames the prediction is
  // within a pixel: 9 placements, not 81.
  cv::Point at(0, 0);  // The climbing window's centre, from the prediction.
  for (int step = 0; step <= 2 * kNearMarginPx; ++step) {
    const cv::Rect window = WindowAround(predicted, size, kFirstNearMarginPx) + at;
    std::optional<Hit> hit = Search(frame, window, templ, false);
    if (!hit) break;
    if (!hit->on_inner_edge) {
      if (decides(*hit)) return hit;
      break;
    }
    at = hit->top_left - predicted_tl;
    if (std::abs(at.x) > kNearMarginPx - kFirstNearMarginPx ||
        std::abs(at.y) > kNearMarginPx - kFirstNearMarginPx) {
      break;
    }
  }
  // The near window whole when the climb did not decide.
  std::optional<Hit> hit = Search(frame, near, templ, false);
  if (!hit || hit->on_inner_edge || !decides(*hit)) return std::nullopt;
  return hit;
}

namespace {

// The best of the refined hits, with the best distinct rival among them: one placed farther than
// half the template's smaller side from it.
Hit BestWithRival(const std::vector<Hit>& hits, const cv::Size& size) {
  size_t best = 0;
  for (size_t i = 1; i < hits.size(); ++i) {
    if (hits[i].similarity > hits[best].similarity) best = i;
  }
  Hit m = hits[best];
  const int distinct = std::max(2, std::min(size.width, size.height) / 2);
  for (size_t i = 0; i < hits.size(); ++i) {
    const cv::Point d = hits[i].top_left - m.top_left;
    if ((std::abs(d.x) > distinct || std::abs(d.y) > distinct) && hits[i].zncc > m.rival_zncc) {
      m.rival_zncc = hits[i].zncc;
      m.rival_top_left = hits[i].top_left;
    }
  }
  return m;
}

}  // namespace

// Searches the region around the last known position (the whole frame without one), which
// grows by search_margin_px per frame lost, coarse-to-fine. The best is returned with the best
// distinct rival it had, so the caller can refuse an ambiguous acquisition.
std::optional<Hit> TemplateTracker::Acquire(const cv::Mat& frame) {
  const PreparedTemplate& templ = search_template();
  const cv::Size size = templ.size();
  const cv::Rect region = AcquisitionRegion(frame, size);
  if (region.width < size.width || region.height < size.height) return std::nullopt;
  BuildAcquisitionPyramid(templ);
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
  // A colour tells look-alikes apart: more peaks are refined, those of another colour dropped.
  const int peaks = core_colour_ && frame.type() == CV_8UC3 ? 2 * kCandidates : kCandidates;
  FindCoarsePeaks(pyramid(top).size(), peaks);
  std::vector<Hit> hits;
  hits.reserve(peaks);
  for (cv::Point p : candidates_) {
    int level = top;  // The level `p` is in.
    p = RefineThroughLevels(p, top, &level);
    std::optional<Hit> m = Refine(frame, region.tl() + p * (1 << level));
    if (m && !OtherColourAt(frame, cv::Point2d(m->top_left) + m->offset + HalfSize(size))) {
      hits.push_back(*m);
    }
  }
  if (hits.empty()) return std::nullopt;
  return BestWithRival(hits, size);
}

cv::Rect TemplateTracker::AcquisitionRegion(const cv::Mat& frame, const cv::Size& size) const {
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  if (!last_centre_) return frame_rect;
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
  return WindowAround(*last_centre_ + velocity_px_, size, static_cast<int>(limit)) & frame_rect;
}

void TemplateTracker::BuildAcquisitionPyramid(const PreparedTemplate& templ) {
  // Rebuilt only when the search template changed (which empties it).
  if (!coarse_.empty()) return;
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

void TemplateTracker::FindCoarsePeaks(const cv::Size& coarse, int peaks) {
  candidates_.clear();
  for (int k = 0; k < peaks; ++k) {
    cv::Point at;
    if (!BestIn(sim_, &at)) break;
    candidates_.push_back(at);
    const cv::Rect suppress(at.x - coarse.width / 2, at.y - coarse.height / 2, coarse.width + 1,
                            coarse.height + 1);
    sim_(suppress & cv::Rect(0, 0, sim_.cols, sim_.rows))
        .setTo(std::numeric_limits<float>::quiet_NaN());
  }
}

cv::Point TemplateTracker::RefineThroughLevels(cv::Point p, int top, int* level) {
  for (int l = top - 1; l >= 1; --l) {
    const cv::Size ts = coarse_[l].size();
    const cv::Rect window =
        cv::Rect(2 * p.x - kRefineMarginPx, 2 * p.y - kRefineMarginPx,
                 ts.width + 2 * kRefineMarginPx, ts.height + 2 * kRefineMarginPx) &
        cv::Rect(0, 0, levels_[l].cols, levels_[l].rows);
    if (window.width < ts.width || window.height < ts.height) break;
    Similarity(levels_[l](window), coarse_[l], level_sim_);
    cv::Point at;
    if (!BestIn(level_sim_, &at)) break;
    p = window.tl() + at;
    *level = l;
  }
  return p;
}

// Drift correction: the first template at the current scale, matched in a small window around
// the working template's match, gives the position (and, by its ZNCC, says whether the patch is
// still the marker). Empty when the first template's peak is not inside that window: the
// working template and the first disagree about where the marker is.
std::optional<Fix> TemplateTracker::Measure(const cv::Mat& frame, const cv::Point2d& centre_px) {
  const Rung& rung = current();
  const cv::Size size = rung.templ.size();
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  measured_zncc_ = false;
  // Climbing first, as NearSearch: the kFirstFineMarginPx window around the match, moved onto
  // its best while that lies on its edge, inside the kFineMarginPx window (the first template's
  // peak, which the working one's match is mostly within a pixel of); the whole kFineMarginPx
  // window decides as before when the climb leaves it.
  cv::Rect window;
  cv::Point best;
  bool inner_edge = true;
  const cv::Rect centred = WindowAround(centre_px, size, 0);
  cv::Point at(0, 0);  // The climbing window's centre, from the match.
  for (int step = 0; step <= 2 * kFineMarginPx && inner_edge; ++step) {
    window = (WindowAround(centre_px, size, kFirstFineMarginPx) + at) & frame_rect;
    if (window.width < size.width || window.height < size.height) break;
    Native(frame, window, fine_);
    Similarity(fine_, rung.templ, fine_sim_);
    if (!BestIn(fine_sim_, &best)) break;
    inner_edge = (best.x == 0 && window.x > 0) ||
                 (best.x == fine_sim_.cols - 1 && window.br().x < frame.cols) ||
                 (best.y == 0 && window.y > 0) ||
                 (best.y == fine_sim_.rows - 1 && window.br().y < frame.rows);
    at = window.tl() + best - centred.tl();
    if (std::abs(at.x) > kFineMarginPx - kFirstFineMarginPx ||
        std::abs(at.y) > kFineMarginPx - kFirstFineMarginPx) {
      break;
    }
  }
  if (inner_edge) {
    window = WindowAround(centre_px, size, kFineMarginPx) & frame_rect;
    if (window.width < size.width || window.height < size.height) return std::nullopt;
    Native(frame, window, fine_);
    Similarity(fine_, rung.templ, fine_sim_);
    if (!BestIn(fine_sim_, &best)) return std::nullopt;
    inner_edge = (best.x == 0 && window.x > 0) ||
                 (best.x == fine_sim_.cols - 1 && window.br().x < frame.cols) ||
                 (best.y == 0 && window.y > 0) ||
                 (best.y == fine_sim_.rows - 1 && window.br().y < frame.rows);
  }
  measured_zncc_ = params_.measure == MatchMeasure::kZncc;
  measured_tl_ = window.tl();
  cv::Point2d top_left;
  if (!inner_edge) {
    top_left = cv::Point2d(window.tl() + best) +
               SubPixel(fine_sim_, best, params_.measure == MatchMeasure::kSad);
  } else if (blob_ok_) {
    // The first template fits best farther than the window from the working template's match:
    // a marker seen at a slant (a dot squashed by a tilt) fits its frontal template along a
    // ridge, not at a point. The marker's blob places it (BlobShift); the first template only
    // guards against drift, judged where the working template matched.
    const cv::Point at(static_cast<int>(std::lround(centre_px.x - HalfSize(size).x)) - window.x,
                       static_cast<int>(std::lround(centre_px.y - HalfSize(size).y)) - window.y);
    if (at.x < 0 || at.y < 0 || at.x >= fine_sim_.cols || at.y >= fine_sim_.rows) return std::nullopt;
    best = at;
    top_left = cv::Point2d(window.tl() + best);
  } else {
    return std::nullopt;
  }
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

// The best ZNCC of the rung at `scale` and `turn` within a pixel of being centred on
// `centre_px`; -inf when the rung does not exist or does not fit in the frame there.
double TemplateTracker::RungZncc(const cv::Mat& frame, int scale, int turn,
                                 const cv::Point2d& centre_px) {
  const Rung* rung = RungAt(scale, turn);
  if (!rung) return kNoRival;
  const cv::Size size = rung->templ.size();
  const cv::Rect window = WindowAround(centre_px, size, 1);
  if ((window & cv::Rect(0, 0, frame.cols, frame.rows)) != window) return kNoRival;
  Native(frame, window, fine_);
  MatchZncc(fine_, rung->templ, rung_sim_, zncc_);
  cv::Point best;
  return BestIn(rung_sim_, &best) ? rung_sim_.at<float>(best) : kNoRival;
}

// The ZNCC of each placement is computed from exact integer sums over its own pixels, so the
// measurement's map of the same rung holds, bit for bit, what RungZncc would compute where its
// 3x3 placements lie inside it (most frames: the blob moves the match by less than
// kFineMarginPx - 1): one small match a frame fewer.
bool TemplateTracker::CurrentRungZnccMeasured(const cv::Mat& frame, const cv::Point2d& centre_px,
                                              double* zncc) {
  if (!measured_zncc_) return false;
  measured_zncc_ = false;  // Used once: the pose search may change the rung.
  const cv::Size size = current().templ.size();
  const cv::Rect window = WindowAround(centre_px, size, 1);
  if ((window & cv::Rect(0, 0, frame.cols, frame.rows)) != window) return false;
  const cv::Rect placements(window.tl() - measured_tl_, cv::Size(3, 3));
  if ((placements & cv::Rect(0, 0, fine_sim_.cols, fine_sim_.rows)) != placements) return false;
  cv::Point best;
  *zncc = BestIn(fine_sim_(placements), &best) ? fine_sim_(placements).at<float>(best) : kNoRival;
  return true;
}

// Scale and turn search: the neighbouring rungs of the ladder (one scale up and down, one turn
// either way) against the current one, at the match; the best becomes current when it fits
// better by the hysteresis. The turn found is the marker's spin from the last frame's.
void TemplateTracker::UpdatePose(const cv::Mat& frame, const Fix& fix, int last_turn) {
  double here;
  if (!CurrentRungZnccMeasured(frame, fix.centre, &here)) {
    here = RungZncc(frame, rung_, turn_, fix.centre);
  }
  if (!std::isfinite(here)) return;
  // The current rung still fits as well as when its neighbours were last tried: they are tried
  // again only every kPoseEvery-th frame (the turn steps on by the last spin meanwhile).
  if (std::isfinite(pose_zncc_) && here >= pose_zncc_ - kPoseDrop && pose_skips_ < kPoseEvery - 1) {
    ++pose_skips_;
    return;
  }
  pose_skips_ = 0;
  pose_zncc_ = here;
  int scale = rung_, turn = turn_;
  double best = here + kScaleHysteresis;
  const auto consider = [&](int s, int t) {
    const double zncc = RungZncc(frame, s, t, fix.centre);
    if (zncc > best) {
      best = zncc;
      scale = s;
      turn = t;
    }
  };
  if (params_.scale_search) {
    consider(rung_ + 1, turn_);  // Larger first: it wins a tie.
    consider(rung_ - 1, turn_);
  }
  if (params_.turn_search) {
    best = std::max(best, here + kTurnHysteresis);  // A turn must fit better by more.
    consider(rung_, turn_ + 1);
    consider(rung_, turn_ - 1);
  }
  turn = ((turn % kTurns) + kTurns) % kTurns;
  if (params_.turn_search) {
    int spin = turn - last_turn;  // Steps since the last match, the short way round.
    if (spin > kTurns / 2) spin -= kTurns;
    if (spin < -kTurns / 2) spin += kTurns;
    turn_step_ = spin;
  }
  if (scale == rung_ && turn == turn_) return;
  pose_zncc_ = best;
  const bool turned = turn != turn_;
  rung_ = scale;
  turn_ = turn;
  if (turned) {
    TurnedTo();
  } else if (!adapts()) {
    coarse_.clear();  // The search template changed.
  }
}

// The current turn changed: the working template, a blend of the patches the marker showed
// turned as it was, starts again from the first template at the new turn (blending a turning
// marker's patches smears it, and a search with that lost a sticker turning 5 degrees a frame).
void TemplateTracker::TurnedTo() {
  if (adapts()) {
    RestoreWorkingTemplate();
  } else {
    coarse_.clear();
  }
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
  blob_disagreement_px_ = 0.0;  // This frame's, set below where both centroids are measured.
  blob_area_ratio_ = 1.0;
  const Rung& rung = current();
  const cv::Size size = rung.templ.size();
  // Measured on the template's place and some of its surroundings, unmasked: a marker seen at a
  // slant (a disc squashed by a tilt) matches best at a scale where its long axis reaches the
  // template's edge, and a blob cut by the edge is no blob (ViSP's mire-2: the big dot lost for
  // 112 frames while plainly in view).
  // (As much of them as the frame holds: the template's own place must be in it.)
  const cv::Rect frame_rect(0, 0, frame.cols, frame.rows);
  const cv::Rect own = WindowAround(fix.centre, size, 0);
  if ((own & frame_rect) != own) return std::nullopt;
  const int grow = std::max(kMinSurroundPx, std::min(size.width, size.height) / 4);
  const cv::Rect at = WindowAround(fix.centre, size, grow) & frame_rect;
  if (chroma_ok_ && frame.type() == CV_8UC3) {
    ChromaChannel(frame(at), chroma_, blob_gray_);
  } else {
    Native(frame, at, blob_native_);
    BlobChannel(blob_native_, blob_gray_);
  }
  // A gray window inside the part converted this update is a view of it, with that part's row
  // step: BlobMeter's pixel-index flood and span fill need a continuous patch, and took the
  // reference flood (points in vectors), fill and cv::moments there, several times the work
  // (issue 45: a quarter of ViSP's mire-2 blob checks, the small dots'). The same pixels
  // copied: the same component, levels and bits.
  if (!blob_gray_.isContinuous()) {
    blob_gray_.copyTo(blob_continuous_);
    blob_gray_ = blob_continuous_;
  }
  // Where the template puts its blob (patch coordinates): the learned centroid at this rung.
  const cv::Point2d expected =
      fix.centre - HalfSize(size) - cv::Point2d(at.tl()) + rung.blob_anchor;
  cv::Point2d centroid;
  double area = 0;
  const cv::Mat unmasked;
  if (!blob_.Locate(blob_gray_, unmasked, expected, &centroid, &area)) {
    return std::nullopt;
  }
  const double learned = blob_.area() * rung_scale() * rung_scale();
  blob_area_ratio_ = area / learned;
  if (!(area >= kMinBlobAreaRatio * learned && area <= learned / kMinBlobAreaRatio)) {
    return std::nullopt;
  }
  cv::Point2d shift = centroid - expected;
  if (!blob_reported_ && cv::norm(shift) <= kBlobAgreePx) {
    return cv::Point2d(0, 0);
  }
  // To be applied: measured with the soft centroid (how far it lies from the binary one goes
  // into the position's sigma: track/position_sigma.h).
  const cv::Point2d binary = centroid;
  if (!blob_.MeasureLocated(blob_gray_, unmasked, &centroid, &area)) {
    return std::nullopt;
  }
  blob_disagreement_px_ = cv::norm(centroid - binary);
  shift = centroid - expected;
  const double reach = std::max(kMinBlobShiftPx, 0.25 * std::min(size.width, size.height));
  if (!(cv::norm(shift) <= reach)) return std::nullopt;
  return shift;
}

std::optional<double> TemplateTracker::ColourDistanceAt(const cv::Mat& frame,
                                                       const cv::Point2d& centre_px) const {
  if (!core_colour_ || frame.type() != CV_8UC3) return std::nullopt;
  const Rung& rung = current();
  const cv::Point2d core = centre_px - HalfSize(rung.templ.size()) + rung.blob_anchor;
  cv::Vec3d chroma;
  if (!CoreColour(frame, core, core_radius_px_ * rung_scale(), &chroma)) return std::nullopt;
  const cv::Vec3d d = chroma - *core_colour_;
  return std::sqrt(d.dot(d));
}

bool TemplateTracker::ColourAgreesAt(const cv::Mat& frame, const Hit& hit) const {
  // A grey marker's colour is every grey place's: agreeing with it says nothing.
  if (!core_colour_) return false;
  if (!IsColouredCore(*core_colour_)) return false;
  const std::optional<double> distance = ColourDistanceAt(
      frame, cv::Point2d(hit.top_left) + hit.offset + HalfSize(search_template().size()));
  return distance && *distance <= kSameColourDistance;
}

bool TemplateTracker::OtherColourAt(const cv::Mat& frame, const cv::Point2d& centre_px) const {
  const std::optional<double> distance = ColourDistanceAt(frame, centre_px);
  return distance && *distance > kOtherColourDistance;
}

void TemplateTracker::UpdateTemplate(const cv::Mat& frame, const cv::Point2d& centre_px) {
  const Rung& rung = current();
  const cv::Size size = rung.templ.size();
  const cv::Rect around = WindowAround(centre_px, size, 2);
  if ((around & cv::Rect(0, 0, frame.cols, frame.rows)) != around) return;
  Native(frame, around, region_);
  if (working_key_ != RungKey(rung_, turn_)) {
    // The scale or turn changed: the running template follows its size and mask before the blend
    // (its pixels follow a turn through the blend itself).
    if (working_f_.size() != size) {
      cv::resize(working_f_, resized_, size, 0, 0, cv::INTER_LINEAR);
      std::swap(working_f_, resized_);
    }
    working_mask_ = rung.templ.mask().empty() ? cv::Mat() : rung.templ.mask().clone();
    working_key_ = RungKey(rung_, turn_);
  }
  // The patch centred on centre_px (its geometric centre, as getRectSubPix places it) blended
  // in, and rounded into the candidate, in one pass (BlendPatch).
  BlendPatch(region_, centre_px - cv::Point2d(around.tl()), params_.update_rate, working_f_,
             candidate_, patch_);
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
  weighed_.clear();
  weighed_centres_.clear();
  if (rungs_.empty()) return Observation::NotFound(MarkerStatus::kNotStarted);  // No template.
  const cv::Rect frame_rect(0, 0, frame_bgr.cols, frame_bgr.rows);
  native_rect_ = cv::Rect();  // A new frame: nothing converted yet.
  StopSharingWindowSums(zncc_);  // Nor summed (the last frame's pixels may have changed).
  frame_ = frame_bgr;  // A header: adopt() verifies another candidate on this frame.
  saved_ = State{last_centre_, velocity_px_, tracking_, repeats_, lost_frames_,
                 rung_,        turn_,        turn_step_};
  // A marker that spins (a sticker on a wheel) is looked for turned on as it turned last frame.
  const int last_turn = turn_;
  if (tracking_ && turn_step_ != 0 && RungAt(rung_, turn_ + turn_step_)) {
    turn_ = ((turn_ + turn_step_) % kTurns + kTurns) % kTurns;
    TurnedTo();
  }
  std::optional<Hit> hit;
  std::optional<ShadeFreePeak> shaded;  // Accepted in log-chromaticity alone (AcceptOn).
  if (tracking_) {
    const cv::Point2d predicted = *last_centre_ + velocity_px_;
    cv::Rect window = WindowAround(predicted, search_template().size(), params_.search_margin_px);
    if (footage_repeats_) {
      window |= WindowAround(*last_centre_, search_template().size(), params_.search_margin_px);
    }
    if ((window & frame_rect).empty()) return Lose(MarkerStatus::kOutOfFrame);
    hit = NearSearch(frame_bgr, predicted);
    if (!hit) {
      ConvertAround(frame_bgr, cv::Rect(window.x - kAroundPx, window.y - kAroundPx,
                                        window.width + 2 * kAroundPx,
                                        window.height + 2 * kAroundPx));
      hit = Search(frame_bgr, window, search_template(), true);
      // Moving faster than the window (its best is on the window's edge, or is no match at all
      // because the marker left it): acquire.
      if (hit && (hit->on_inner_edge || !AcceptOn(frame_bgr, *hit, true, &shaded))) {
        hit.reset();
      }
    }
  }
  const bool followed = hit.has_value();
  if (!hit) hit = Acquire(frame_bgr);
  if (!hit || !AcceptOn(frame_bgr, *hit, followed, &shaded)) {
    return Lose(MarkerStatus::kLost);
  }
  // Of another colour than the marker: a look-alike (a blue disc for the green one's gray
  // template), not the marker; a rival of another colour is no rival.
  const auto centre_of = [&](cv::Point top_left) {
    return cv::Point2d(top_left) + HalfSize(search_template().size());
  };
  if (hit->rival_zncc >= params_.min_zncc && OtherColourAt(frame_bgr, centre_of(hit->rival_top_left))) {
    hit->rival_zncc = kNoRival;
  }
  if (OtherColourAt(frame_bgr, centre_of(hit->top_left) + hit->offset)) {
    return Lose(MarkerStatus::kLost);
  }
  const cv::Point2d matched = cv::Point2d(hit->top_left) + hit->offset +
                              HalfSize(search_template().size());
  // The places the tracker would take for its marker, for the session's association: the best
  // match and a distinct second peak that passes min_zncc too (a look-alike: a twin the motion
  // may tell apart where the scores cannot).
  const bool rival_fits = hit->rival_zncc >= params_.min_zncc;
  Weigh(matched, hit->zncc, CandidateVerdict::kFits);
  if (rival_fits) {
    Weigh(cv::Point2d(hit->rival_top_left) + HalfSize(search_template().size()), hit->rival_zncc,
          CandidateVerdict::kFits);
  }
  if (params_.ambiguity_margin > 0 && hit->rival_zncc >= hit->zncc - params_.ambiguity_margin) {
    return Lose(MarkerStatus::kAmbiguous, 2);
  }
  if (scan_pending_) {
    scan_pending_ = false;
    ScanForLookAlikes(frame_bgr, cv::Point2d(hit->top_left) + HalfSize(search_template().size()));
  }
  Observation observation = Verify(frame_bgr, matched, hit->score, last_turn, hit->zncc, shaded);
  if (observation.found()) {
    weighed_.front().verdict = CandidateVerdict::kChosen;
    weighed_.front().position_px = *observation.position_px;
  } else {
    weighed_.front().verdict = CandidateVerdict::kShape;  // The first template or blob refused it.
  }
  return observation;
}

void TemplateTracker::Weigh(const cv::Point2d& centre_px, double zncc, CandidateVerdict verdict) {
  const Rung& rung = current();
  MarkerCandidate c;
  // The point the match would report (the rung's anchor), to within the verification's shift.
  c.position_px = centre_px - HalfSize(rung.templ.size()) + rung.anchor;
  c.area_px = rung.templ.count();
  c.circularity = 1.0;
  c.misfit = std::clamp(1.0 - zncc, 0.0, 2.0);
  c.verdict = verdict;
  weighed_.push_back(c);
  weighed_centres_.push_back(centre_px);
}

std::optional<Observation> TemplateTracker::adopt(size_t index) {
  if (index >= weighed_.size() || frame_.empty()) return std::nullopt;
  if (weighed_[index].verdict != CandidateVerdict::kFits &&
      weighed_[index].verdict != CandidateVerdict::kChosen) {
    return std::nullopt;
  }
  // Back to before the last update, then verify this candidate as if it had been the choice.
  last_centre_ = saved_.last_centre;
  velocity_px_ = saved_.velocity_px;
  tracking_ = saved_.tracking;
  repeats_ = saved_.repeats;
  lost_frames_ = saved_.lost_frames;
  rung_ = saved_.rung;
  turn_ = saved_.turn;
  turn_step_ = saved_.turn_step;
  pose_zncc_ = kNoRival;
  if (adapts()) RestoreWorkingTemplate();  // It may have blended in the other candidate.
  native_rect_ = cv::Rect();
  StopSharingWindowSums(zncc_);
  const Observation observation =
      Verify(frame_, weighed_centres_[index], 1.0 - weighed_[index].misfit, turn_, kNoRival);
  if (!observation.found()) return std::nullopt;
  for (MarkerCandidate& c : weighed_) {
    if (c.verdict == CandidateVerdict::kChosen) c.verdict = CandidateVerdict::kFits;
  }
  weighed_[index].verdict = CandidateVerdict::kChosen;
  weighed_[index].position_px = *observation.position_px;
  return observation;
}

// The first template's measurement at the working template's match `matched` (its centre), the
// drift guard, the template's blob, then the tracker's state moves on to it.
Observation TemplateTracker::Verify(const cv::Mat& frame_bgr, const cv::Point2d& matched,
                                    double score, int last_turn, double working_zncc,
                                    const std::optional<ShadeFreePeak>& shaded) {
  if (shaded) return VerifyShaded(*shaded, score);
  const std::optional<Fix> fix = Measure(frame_bgr, matched);
  // SAD and SSD compare grey levels with the first template too: they do not cancel a change of
  // light, and a position they measure against a template the light has left is biased.
  const bool levels_fit = fix && (params_.measure == MatchMeasure::kZncc ||
                                  fix->score <= (params_.measure == MatchMeasure::kSad
                                                     ? params_.max_sad
                                                     : params_.max_ssd));
  // A marker with a blob may leave its first template further (a dot squashed by a tilt): the
  // blob found at the match, of the marker's area, is the second piece of evidence against drift.
  const double drift_floor = params_.drift_min_zncc - (blob_ok_ ? kBlobDriftAllowance : 0.0);
  if (!fix || !levels_fit || !(fix->zncc >= drift_floor)) {
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
  // A blob well below the marker's area at a match that holds is cut: a shadow across part of a
  // dome leaves only its lit part, or only its shaded part, in the blob's channel, and that
  // part's centroid is not the marker's centre (2.2-2.5 px off for half a disc). Where the first
  // template matches as well as a match must in log-chromaticity, which the shadow leaves as it
  // was, and far better than in gray levels (the light changed across the marker, not its
  // look: kShadedZnccGap), the marker is placed there.
  bool placed_shade_free = false;
  if (blob_ok_ && blob_area_ratio_ < kCutBlobAreaRatio) {
    const cv::Size size = current().templ.size();
    const std::optional<ShadeFreePeak> peak =
        ShadeFreePeakNear(frame_bgr, WindowAround(fix->centre, size, 0).tl());
    if (peak && peak->zncc >= params_.min_zncc && peak->zncc - fix->zncc >= kShadedZnccGap) {
      at.centre = peak->top_left + HalfSize(size);
      at.reported = peak->top_left + current().anchor;
      placed_shade_free = true;
    }
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
  if (params_.scale_search || params_.turn_search) UpdatePose(frame_bgr, at, last_turn);
  // Blended only where the working template no longer shows what the frame shows at the match
  // (kSteadyWorkingZncc), or the pose search changed its rung (it follows the rung's size there).
  const bool steady = params_.measure == MatchMeasure::kZncc &&
                      working_zncc >= kSteadyWorkingZncc && working_key_ == RungKey(rung_, turn_);
  if (adapts() && !steady) UpdateTemplate(frame_bgr, at.centre);
  Observation observation;
  observation.position_px = at.reported;
  observation.score = score;
  BlobEvidence blob;
  if (blob_ok_ && !placed_shade_free) {
    blob.area_px = blob_.area() * rung_scale() * rung_scale();
    blob.centroid_disagreement_px = blob_disagreement_px_;
    blob.definition_spread_px = anchor_spread_px_ * rung_scale();
    blob.own_asymmetry_px = blob_.asymmetry_px() * rung_scale();
  }
  const cv::Size size = current().templ.size();
  observation.sigma_px = TemplateMatchSigmaPx(fix->zncc, size.width, size.height, blob);
  return observation;
}

// The match accepted in log-chromaticity alone at `peak` (AcceptOn measured its place there: the gray
// levels a shadow changed neither place nor measure it; the template's blob, cut by the shadow,
// would put the centre off towards the lit side). The pose and the working template are left as
// they were.
Observation TemplateTracker::VerifyShaded(const ShadeFreePeak& peak, double score) {
  const cv::Size size = current().templ.size();
  const cv::Point2d centre = peak.top_left + HalfSize(size);
  const cv::Point2d step = tracking_ ? centre - *last_centre_ : cv::Point2d(0, 0);
  repeats_ = 0;
  velocity_px_ = step;
  turn_step_ = 0;  // The turn was not measured: looked for as it is.
  last_centre_ = centre;
  tracking_ = true;
  lost_frames_ = 0;
  Observation observation;
  observation.position_px = peak.top_left + current().anchor;
  observation.score = score;
  observation.sigma_px = TemplateMatchSigmaPx(peak.zncc, size.width, size.height, BlobEvidence());
  return observation;
}

}  // namespace template_internal


using template_internal::kMaxTemplateRowBytes;
using template_internal::kMinTemplatePx;
using template_internal::RectText;

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
  return std::make_unique<template_internal::TemplateTracker>(params);
}

}  // namespace softsight
