// The one interface every marker tracker implements, and the table that builds them by name.
// The concrete trackers' parameters are in colour_tracker.h and template_tracker.h; a kind of
// marker (built in, or added by a program: tracker_kind.h) is registered with the registry,
// which builds its tracker, so this interface names no concrete tracker.
//
// A tracker follows one marker. It knows nothing of files, windows or serial ports: it is given
// images and answers with Observations. Modelled on OpenCV's cv::Tracker (init + update).
#pragma once

#include <functional>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <typeindex>
#include <typeinfo>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"

namespace softsight {

// What a tracker made of one blob or match it considered in its last update(): the session's
// joint checks and the live window's mask view read them.
enum class CandidateVerdict : uint8_t {
  kChosen,      // Reported as the marker.
  kFits,        // Fits the marker's model, but another one was chosen (or tied: ambiguous).
  kClipped,     // Cut by the searched region's border: its centroid is not the whole blob's.
  kSize,        // Area outside the configured range or too far from the learned area.
  kShape,       // Not compact enough, or unlike the learned shape.
  kColour,      // Its colour is not the marker's (tint or brightness).
  kContrast,    // Does not stand out from its surroundings (a patch of background texture).
  kOutsideRoi,  // Outside the region the first acquisition is restricted to.
  kPartial,     // Part of the marker is hidden (covered, or beyond the frame's edge): the centroid
                // of what is left is not the marker's centre.
};

// "chosen", "fits", "clipped", "size", "shape", "colour", "contrast", "outside_roi", "partial".
const char* CandidateVerdictName(CandidateVerdict verdict);

struct MarkerCandidate {
  cv::Point2d position_px{};   // Centroid (complete blobs) or bounding-box centre (clipped ones).
  double area_px = 0;
  double circularity = 0;      // See ColourParams::min_circularity.
  double misfit = 0;           // 0 perfect; above 1 rejected (see ColourParams::ambiguity_margin).
  CandidateVerdict verdict = CandidateVerdict::kFits;
};

class Tracker {
 public:
  virtual ~Tracker() = default;

  // Tells the tracker where its marker is on `frame_bgr`: the rectangle a person dragged around it.
  // Colour trackers restrict their next acquisition to `hint` and learn the marker's reference
  // area there; template trackers cut their template from `hint`. Throws InputError when the hint
  // cannot be used (empty, or outside the frame).
  virtual void init(const cv::Mat& frame_bgr, const cv::Rect& hint) = 0;

  // Starts the tracker from what its parameters say, on the first frame where it can: a colour
  // tracker once frame.index reaches its roi frame (learning its marker in its roi when one is
  // set); a template tracker from its template image, or from its rect once frame.index reaches
  // its template frame. Returns false while it cannot start (no template yet, or the roi's or
  // template's frame is still ahead): its marker is then not
  // started, and the caller asks again with the next frame. Throws InputError as init() does.
  virtual bool start(const Frame& frame) = 0;

  // Finds the marker in the next frame (CV_8UC3 BGR). found() == false is a normal result; a
  // tracker never reports a stale or predicted position.
  virtual Observation update(const cv::Mat& frame_bgr) = 0;

  // Forgets position and velocity; the next update() acquires on the full frame (or, for a
  // marker never found yet, in its roi) with what the tracker learned of the marker's looks.
  virtual void reset() = 0;

  // The candidates the last update() (or init()) weighed, with the verdict on each; empty for
  // trackers that do not report them. Valid until the next update().
  virtual const std::vector<MarkerCandidate>& candidates() const;

  // The session's association (which marker is which candidate, decided for all markers at once
  // with their motion) chose candidate `index` of candidates() as this tracker's marker, in
  // place of what the last update() reported: the tracker continues from it as if it had chosen
  // it itself, and returns the observation it reports for it. Absent when it cannot (a
  // candidate that does not fit, or a tracker without candidates); the caller then reports the
  // marker not found and resets the tracker.
  virtual std::optional<Observation> adopt(size_t index);

  // Diagnostics for the live window's mask view. The pixels of `frame_bgr` this tracker counts
  // as its marker's colour (CV_8U, 255 = member; before filtering and morphology): false for
  // trackers without such a notion (templates).
  virtual bool membership(const cv::Mat& frame_bgr, cv::Mat& mask) const;
  // The region the last update() searched, when the tracker restricts its search to one.
  virtual std::optional<cv::Rect> search_region() const;
};

class TrackerKind;  // What a kind of marker is to the program: softsight/track/tracker_kind.h.

namespace tracker_detail {
// The registered kind whose parameter set is of `type`. A type no kind registered is a
// programming error: it throws std::logic_error.
const TrackerKind& KindOfParams(std::type_index type);
}  // namespace tracker_detail

// A marker's tracking parameters: the parameter set of one kind of marker. Built in: ColourParams
// (colour or gray-level thresholding) and TemplateParams (template matching, whose measure, sad,
// ssd or zncc, and gray/colour choice it carries); a kind registered with RegisterTrackerKind
// (tracker_kind.h, by the library or by a program) adds its own set. A value: copies are independent. What differs between kinds (checks, YAML
// keys, what a tracker needs from a frame, how a person selects the marker) is asked of kind(),
// so only the track library tells kinds apart; code that edits one kind's own fields (the live
// window's colour ranges) asks for that set by type with get_if<P>().
class MarkerParams {
 public:
  MarkerParams();  // ColourParams' defaults.
  // Any registered kind's parameter set (implicit, so `spec.params = colour;` reads as it says).
  template <typename P,
            typename = std::enable_if_t<!std::is_same_v<std::decay_t<P>, MarkerParams>>>
  MarkerParams(P params)  // NOLINT(google-explicit-constructor)
      : kind_(&tracker_detail::KindOfParams(typeid(std::decay_t<P>))),
        value_(std::make_unique<Value<std::decay_t<P>>>(std::move(params))) {}
  MarkerParams(const MarkerParams& other)
      : kind_(other.kind_), value_(other.value_ ? other.value_->clone() : nullptr) {}
  MarkerParams(MarkerParams&&) noexcept = default;
  MarkerParams& operator=(const MarkerParams& other) {
    if (this != &other) *this = MarkerParams(other);
    return *this;
  }
  MarkerParams& operator=(MarkerParams&&) noexcept = default;

  // The kind these parameters are of.
  const TrackerKind& kind() const { return *kind_; }

  template <typename P>
  bool holds() const {
    return value_ != nullptr && value_->type() == std::type_index(typeid(P));
  }
  // The parameter set when it is a P, else null.
  template <typename P>
  const P* get_if() const {
    return holds<P>() ? &static_cast<const Value<P>&>(*value_).params : nullptr;
  }
  template <typename P>
  P* get_if() {
    return holds<P>() ? &static_cast<Value<P>&>(*value_).params : nullptr;
  }
  // The parameter set, which must be a P (std::bad_cast otherwise).
  template <typename P>
  const P& get() const {
    if (const P* params = get_if<P>()) return *params;
    throw std::bad_cast();
  }
  template <typename P>
  P& get() {
    if (P* params = get_if<P>()) return *params;
    throw std::bad_cast();
  }
  // Replaces the parameters with a default P and returns it.
  template <typename P>
  P& emplace() {
    *this = MarkerParams(P{});
    return get<P>();
  }

 private:
  struct Holder {
    virtual ~Holder() = default;
    virtual std::unique_ptr<Holder> clone() const = 0;
    virtual std::type_index type() const = 0;
  };
  template <typename P>
  struct Value final : Holder {
    explicit Value(P p) : params(std::move(p)) {}
    std::unique_ptr<Holder> clone() const override { return std::make_unique<Value>(params); }
    std::type_index type() const override { return typeid(P); }
    P params;
  };

  const TrackerKind* kind_;
  std::unique_ptr<Holder> value_;
};

// Everything needed to build the tracker of one marker.
struct MarkerSpec {
  std::string name{};     // Unique; prefixes the marker's CSV columns.
  MarkerParams params{};  // Colour by default.
};

// Builds the tracker for `spec.params`. Throws InputError naming the marker when its parameters
// fail their Check().
std::unique_ptr<Tracker> CreateTracker(const MarkerSpec& spec);

// The method names (the registry's, the only place they are spelled), in the order --help lists
// them: colour, sad, ssd, zncc.
std::vector<std::string> TrackerMethods();

// The name of the method `params` select ("colour", or the template's measure: "sad", ...).
std::string TrackerMethodName(const MarkerParams& params);

// The parameters of `method`: the first of `known` of the method's kind (else that kind's
// defaults) with the method selected (a template's measure). Throws InputError listing the
// methods when `method` is not one of them.
MarkerParams ParamsForMethod(const std::string& method, const std::vector<MarkerParams>& known);

// The method of a marker whose config names none: template matching (zncc) when it has a
// template, else colour.
const char* DefaultTrackerMethod(bool has_template);

// True for the methods that match a template (sad, ssd, zncc): they need a template rectangle or
// image, and a person selects the marker by dragging a box. False for colour and unknown names.
bool IsTemplateMethod(const std::string& method);

}  // namespace softsight
