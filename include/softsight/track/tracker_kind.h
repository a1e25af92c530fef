// A kind of marker, as the library sees it: one descriptor per parameter set (ColourParams,
// TemplateParams, or a kind a program adds), registered once, so that everything that differs
// between kinds is asked of the descriptor and only the kind itself tells kinds apart. OpenCV's
// tracker factory is the model (a small interface, a name-to-factory table); the config, the
// session, the run loop, the live window and the program follow a registered kind.
//
// Adding a kind, inside the library or in a program of your own (examples/library/
// custom_kind.cc is a whole one; docs/architecture.md, "A new kind of marker", walks through it):
//   1. its parameter struct (plain fields with defaults) with Check(), and its option table
//      (softsight/core/option_table.h: key, unit, range, doc per field), which the config reads,
//      writes, range-checks and documents;
//   2. its Tracker (softsight/track/tracker.h): start(), update() -> Observation, reset();
//   3. a TrackerKind subclass answering what this header asks (the pure virtual functions; the
//      others have defaults that fit a kind with one method and no image file), registered with
//      RegisterTrackerKind<Params>() before a config names it. A config's `method:` then selects
//      it, CreateTracker builds its tracker, and a TrackingSession runs it.
// The built-in kinds are registered in src/track/tracker_registry.cc.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <typeindex>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/core/option_table.h"
#include "softsight/core/types.h"
#include "softsight/track/tracker.h"

namespace softsight {

// How a person points out a marker of a kind in the live window.
enum class MarkerSelection {
  kClickColour,  // A click on the marker picks its colour (and a search box around the click).
  kDragBox,      // A box dragged around the marker (a template is cut from it).
};

class TrackerKind {
 public:
  virtual ~TrackerKind() = default;

  // --- Identity -------------------------------------------------------------------------------
  // The kind's name in messages and docs ("colour", "template").
  virtual std::string name() const = 0;
  // The `method:` names that select this kind, in the order --help lists them. Unique across
  // kinds: a method names one kind.
  virtual std::vector<std::string> methods() const = 0;
  // The method `params` (of this kind) select. Default: the first of methods() (a kind with one).
  virtual std::string method_of(const MarkerParams& params) const {
    (void)params;
    return methods().front();
  }
  // Makes `params` (of this kind) select `method` (one of methods()). Default: nothing to change
  // (a kind with one method).
  virtual void select_method(MarkerParams& params, const std::string& method) const {
    (void)params;
    (void)method;
  }
  // Whether a marker's entry in a config file says this kind is meant when it names no method,
  // given which of its keys are present (`has_key`): a `template:` key means template matching.
  // The first kind that claims a marker is its default; else the first kind registered.
  virtual bool claims_unnamed(const std::function<bool(const std::string&)>& has_key) const {
    (void)has_key;
    return false;
  }

  // --- Parameters -----------------------------------------------------------------------------
  // A default parameter set of this kind.
  virtual MarkerParams defaults() const = 0;
  // Its settings, one row each (softsight/core/option_table.h): the config reads, writes, range-checks and
  // documents them (`softsight config --doc`), every key of every kind in a marker's entry.
  virtual const OptionTable<MarkerParams>& options() const = 0;
  // Keys a marker's entry may not give together, with why ({"hsv", "auto_colour"}: one replaces
  // the other). The config names the second key of a pair the file has both of.
  struct ExclusiveKeys {
    std::string first, second, problem;
  };
  virtual std::vector<ExclusiveKeys> exclusive_keys() const { return {}; }
  // The checks of the whole set (ranges and the rules across fields), as "key: problem".
  virtual bool check(const MarkerParams& params, std::string* problem) const = 0;
  // Builds the tracker (CreateTracker has checked the parameters).
  virtual std::unique_ptr<Tracker> create(const MarkerParams& params) const = 0;

  // --- An image the parameters may hold, read from a file the config names ----------------------
  // The key naming the file ("template.file") and its one-line doc; nullopt for kinds that hold
  // no image.
  struct ImageFileKey {
    std::string key, doc;
  };
  virtual std::optional<ImageFileKey> image_file() const { return std::nullopt; }
  // The pixels read from that file (null when there are none).
  virtual const cv::Mat* image(const MarkerParams& params) const {
    (void)params;
    return nullptr;
  }
  // Puts the pixels of `file` into `params`; returns "key: problem" when they do not fit the rest
  // of the parameters.
  virtual std::optional<std::string> set_image(MarkerParams& params, const cv::Mat& pixels,
                                               const std::string& file) const {
    (void)params;
    (void)pixels;
    (void)file;
    return std::nullopt;
  }
  // What a batch run misses to start the marker without a person (a template marker with neither
  // rect nor image: "has no template: give ..."), or nullopt.
  virtual std::optional<std::string> missing_for_batch(const MarkerParams& params) const {
    (void)params;
    return std::nullopt;
  }

  // --- What its tracker needs -------------------------------------------------------------------
  // True when its tracker needs colour frames (false: gray frames do).
  virtual bool needs_colour(const MarkerParams& params) const = 0;
  // About the marker's radius, from what the parameters say of its size (a roi or template
  // rectangle drawn around it, a search window); 0 when they say nothing.
  virtual double size_hint_px(const MarkerParams& params) const = 0;

  // --- The person: selection and drawing --------------------------------------------------------
  virtual MarkerSelection selection() const = 0;
  // A person selected the marker in `rect` of `frame`: `params` remember it, so a saved config
  // starts the marker there and then, as the selection did (a colour marker's roi from this
  // frame; a template's pixels cut from the frame, with where and when).
  virtual void remember_selection(MarkerParams& params, const Frame& frame,
                                  const cv::Rect& rect) const = 0;
  // A recording whose frame 0 shows the marker in `box`: `params` start it there on frame 0.
  virtual void start_in(MarkerParams& params, const cv::Rect& box) const = 0;
  // An edit made after frame `last_frame` of a recording: a start frame set later (in the
  // source's numbers) is already behind, so the marker starts with the next frame.
  virtual void start_by(MarkerParams& params, int64_t last_frame) const = 0;
  // The size of the box the overlay draws around the marker (a template's size); nullopt: none.
  virtual std::optional<cv::Size> drawn_box(const MarkerParams& params) const {
    (void)params;
    return std::nullopt;
  }
};

// Every registered kind, the built-in ones first (colour, template), in registration order.
const std::vector<const TrackerKind*>& TrackerKinds();

// Adds a kind. Its parameter type and method names must be new (std::logic_error otherwise).
// Kinds are registered before any is used (at start-up, or by a test before it reads a config):
// the registry is not locked against a registration while another thread reads it.
void RegisterTrackerKind(std::unique_ptr<TrackerKind> kind, std::type_index params_type);
template <typename P>
void RegisterTrackerKind(std::unique_ptr<TrackerKind> kind) {
  RegisterTrackerKind(std::move(kind), typeid(P));
}

// The kind `method` selects, or null.
const TrackerKind* KindOfMethod(const std::string& method);

// `table` (the rows of one parameter struct P) as rows of the MarkerParams holding a P: what a
// kind's options() returns.
template <typename P>
OptionTable<MarkerParams> KindOptions(const OptionTable<P>& table) {
  OptionTable<MarkerParams> rows;
  AppendOptions(&rows, "", [](MarkerParams& params) -> P& { return params.get<P>(); }, table);
  return rows;
}

}  // namespace softsight
