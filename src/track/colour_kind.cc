// The colour kind: ColourParams, the colour tracker, a marker a person clicks on.
#include <algorithm>

#include "softsight/track/tracker_kind.h"
#include "track/colour_tracker_impl.h"
#include "track/track_options.h"

namespace softsight {
namespace {

class ColourKind final : public TrackerKind {
 public:
  std::string name() const override { return "colour"; }
  std::vector<std::string> methods() const override { return {"colour"}; }
  std::string method_of(const MarkerParams& /*params*/) const override { return "colour"; }
  void select_method(MarkerParams& /*params*/, const std::string& /*method*/) const override {}

  MarkerParams defaults() const override { return ColourParams{}; }
  const OptionTable<MarkerParams>& options() const override {
    static const OptionTable<MarkerParams> rows = KindOptions(ColourParamsOptions());
    return rows;
  }
  std::vector<ExclusiveKeys> exclusive_keys() const override {
    // Either would be silently ignored beside the other.
    return {{"hsv", "auto_colour", "give either hsv ranges or auto_colour, not both"},
            {"hsv", "gray", "give either hsv ranges or a gray range, not both"}};
  }
  bool check(const MarkerParams& params, std::string* problem) const override {
    return params.get<ColourParams>().Check(problem);
  }
  std::unique_ptr<Tracker> create(const MarkerParams& params) const override {
    return std::make_unique<ColourTracker>(params.get<ColourParams>());
  }

  bool needs_colour(const MarkerParams& params) const override {
    return params.get<ColourParams>().NeedsColour();
  }
  // A roi is drawn around the marker; the tracking window is at least 4 marker radii (its
  // documented minimum).
  double size_hint_px(const MarkerParams& params) const override {
    const ColourParams& colour = params.get<ColourParams>();
    if (colour.roi) return 0.5 * std::max(colour.roi->width, colour.roi->height);
    return colour.window_px > 0 ? 0.25 * colour.window_px : 0.0;
  }

  MarkerSelection selection() const override { return MarkerSelection::kClickColour; }
  // The roi holds from this frame on: at frame 0 the marker was elsewhere.
  void remember_selection(MarkerParams& params, const Frame& frame,
                          const cv::Rect& rect) const override {
    ColourParams& colour = params.get<ColourParams>();
    colour.roi = rect;
    colour.roi_frame = static_cast<int>(std::max<int64_t>(0, frame.index));
  }
  void start_in(MarkerParams& params, const cv::Rect& box) const override {
    ColourParams& colour = params.get<ColourParams>();
    colour.roi = box;
    colour.roi_frame = 0;
  }
  void start_by(MarkerParams& params, int64_t last_frame) const override {
    ColourParams& colour = params.get<ColourParams>();
    colour.roi_frame = static_cast<int>(std::min<int64_t>(colour.roi_frame, last_frame));
  }
};

}  // namespace

std::unique_ptr<TrackerKind> MakeColourKind() { return std::make_unique<ColourKind>(); }

}  // namespace softsight
