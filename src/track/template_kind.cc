// The template kind: TemplateParams, the template tracker (sad, ssd, zncc), a marker a person
// drags a box around.
#include <algorithm>
#include <sstream>

#include "softsight/track/tracker_kind.h"
#include "track/template_tracker_impl.h"
#include "track/track_options.h"

namespace softsight {
namespace {

struct MeasureMethod {
  const char* name;
  MatchMeasure measure;
};
// In the order --help lists them.
const MeasureMethod kMeasures[] = {
    {"sad", MatchMeasure::kSad}, {"ssd", MatchMeasure::kSsd}, {"zncc", MatchMeasure::kZncc}};

class TemplateKind final : public TrackerKind {
 public:
  std::string name() const override { return "template"; }
  std::vector<std::string> methods() const override {
    std::vector<std::string> names;
    for (const MeasureMethod& m : kMeasures) names.emplace_back(m.name);
    return names;
  }
  std::string method_of(const MarkerParams& params) const override {
    const MatchMeasure measure = params.get<TemplateParams>().measure;
    for (const MeasureMethod& m : kMeasures) {
      if (m.measure == measure) return m.name;
    }
    return "zncc";  // Unreachable: every measure has its method.
  }
  void select_method(MarkerParams& params, const std::string& method) const override {
    for (const MeasureMethod& m : kMeasures) {
      if (method == m.name) params.get<TemplateParams>().measure = m.measure;
    }
  }
  // A marker with a `template:` key and no method is matched (zncc, the default measure).
  bool claims_unnamed(const std::function<bool(const std::string&)>& has_key) const override {
    return has_key("template");
  }

  MarkerParams defaults() const override { return TemplateParams{}; }
  const OptionTable<MarkerParams>& options() const override {
    static const OptionTable<MarkerParams> rows = KindOptions(TemplateParamsOptions());
    return rows;
  }
  bool check(const MarkerParams& params, std::string* problem) const override {
    return params.get<TemplateParams>().Check(problem);
  }
  std::unique_ptr<Tracker> create(const MarkerParams& params) const override {
    return CreateTemplateTracker(params.get<TemplateParams>());
  }

  std::optional<ImageFileKey> image_file() const override {
    return ImageFileKey{"template.file",
                        "template image, relative to the config file (with rect: selected there "
                        "live)"};
  }
  const cv::Mat* image(const MarkerParams& params) const override {
    const cv::Mat& image = params.get<TemplateParams>().image;
    return image.empty() ? nullptr : &image;
  }
  std::optional<std::string> set_image(MarkerParams& params, const cv::Mat& pixels,
                                       const std::string& file) const override {
    TemplateParams& templ = params.get<TemplateParams>();
    templ.image = pixels;
    if (templ.rect && templ.rect->size() != pixels.size()) {
      // With an image, rect says where it was selected: the image's own size.
      const cv::Rect& r = *templ.rect;
      std::ostringstream problem;  // (not operator+ on a literal: GCC 12's -Wrestrict)
      problem << "template.rect: [" << r.x << ", " << r.y << ", " << r.width << ", " << r.height
              << "] is not the size of the image '" << file << "' (" << pixels.cols << "x"
              << pixels.rows << " px)";
      return problem.str();
    }
    return std::nullopt;
  }
  std::optional<std::string> missing_for_batch(const MarkerParams& params) const override {
    const TemplateParams& templ = params.get<TemplateParams>();
    if (!templ.image.empty() || templ.rect) return std::nullopt;
    return "uses template matching (" + method_of(params) +
           ") but has no template: give `template: {frame: 0, rect: [x, y, w, h]}` or "
           "`template: {file: marker.png}`";
  }

  bool needs_colour(const MarkerParams& params) const override {
    return params.get<TemplateParams>().colour;
  }
  // A template's rectangle (or image) is drawn around the marker.
  double size_hint_px(const MarkerParams& params) const override {
    const std::optional<cv::Size> box = drawn_box(params);
    return box ? 0.5 * std::max(box->width, box->height) : 0.0;
  }

  MarkerSelection selection() const override { return MarkerSelection::kDragBox; }
  // The template's own pixels (a rectangle on the config's template frame would cut whatever is
  // there, not this marker), with where and on which frame they were selected.
  void remember_selection(MarkerParams& params, const Frame& frame,
                          const cv::Rect& rect) const override {
    TemplateParams& templ = params.get<TemplateParams>();
    // The template is cut from the box the tracker took (the box dragged, or that box widened
    // to hold the marker's surroundings): `track` then starts from the same pixels.
    TemplateParams cut = templ;
    cut.image = cv::Mat();
    template_internal::TemplateTracker tracker(cut);
    tracker.init(frame.image, rect);
    const cv::Rect box = tracker.selection_box().empty() ? rect : tracker.selection_box();
    templ.rect = box;
    templ.template_frame = static_cast<int>(std::max<int64_t>(0, frame.index));
    templ.image = frame.image(box & cv::Rect(0, 0, frame.image.cols, frame.image.rows)).clone();
  }
  // Cut from the recording's frame 0.
  void start_in(MarkerParams& params, const cv::Rect& box) const override {
    TemplateParams& templ = params.get<TemplateParams>();
    templ.rect = box;
    templ.template_frame = 0;
    templ.image = cv::Mat();
  }
  void start_by(MarkerParams& params, int64_t last_frame) const override {
    TemplateParams& templ = params.get<TemplateParams>();
    templ.template_frame = static_cast<int>(std::min<int64_t>(templ.template_frame, last_frame));
  }
  std::optional<cv::Size> drawn_box(const MarkerParams& params) const override {
    const TemplateParams& templ = params.get<TemplateParams>();
    if (!templ.image.empty()) return templ.image.size();
    if (templ.rect) return templ.rect->size();
    return std::nullopt;
  }
};

}  // namespace

std::unique_ptr<TrackerKind> MakeTemplateKind() { return std::make_unique<TemplateKind>(); }

}  // namespace softsight
