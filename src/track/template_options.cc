// TemplateParams, registered once: key, unit, range and doc of every field (defaults: the struct).
#include "track/track_options.h"

namespace softsight {
namespace {

OptionTable<TemplateParams> MakeTemplateTable() {
  using P = TemplateParams;
  return {
      IntOption<P>("template.frame", &P::template_frame)
          .Range(0, 1e9)
          .Doc("reference frame: where rect is cut (or, with file, where tracking starts)"),
      CustomOption<P>(
          "template.rect", OptionKind::kInts,
          [](const P& p) -> std::optional<OptionValue> {
            if (!p.rect) return std::nullopt;
            return OptionValue(
                std::vector<int64_t>{p.rect->x, p.rect->y, p.rect->width, p.rect->height});
          },
          [](P& p, const std::optional<OptionValue>& v) {
            if (!v) {
              p.rect.reset();
              return;
            }
            const auto& r = std::get<std::vector<int64_t>>(*v);
            p.rect = cv::Rect(static_cast<int>(r[0]), static_cast<int>(r[1]),
                              static_cast<int>(r[2]), static_cast<int>(r[3]));
          },
          /*optional=*/true)
          .Count(4)
          .Range(0, 65535)
          .Unit("px")
          .Doc("[x, y, w, h] on the reference frame (what the mouse drags; with file: where it was)"),
      BoolOption<P>("template.colour", &P::colour)
          .Doc("match BGR, not gray (3x the work; tells look-alike markers apart)"),
      BoolOption<P>("template.contrast_gray", &P::contrast_gray)
          .Doc("gray: match BGR projected on the template's colour axis instead of luma"),
      BoolOption<P>("template.round", &P::round_mask)
          .Doc("match only the ellipse inscribed in the rectangle (false: the whole rectangle)"),
      EnumOption<P>("template.report", &P::report,
                    std::vector<std::pair<std::string, TemplateReport>>{
                        {"centre", TemplateReport::kCentre},
                        {"symmetry", TemplateReport::kSymmetry},
                        {"rect_centre", TemplateReport::kRectCentre}})
          .Doc("point reported: the marker's centre (blob centroid, else centre of symmetry), "
               "the centre of symmetry, or the rectangle's centre (the paper's)"),
      DoubleOption<P>("template.min_zncc", &P::min_zncc)
          .Range(-1, 1)
          .Doc("a best match below this ZNCC is not found (all methods)"),
      DoubleOption<P>("template.max_sad", &P::max_sad)
          .Above(0)
          .AtMost(255)
          .Unit("grey levels")
          .Doc("sad: mean |difference| per pixel and channel above this: not found"),
      DoubleOption<P>("template.max_ssd", &P::max_ssd)
          .Above(0)
          .AtMost(255)
          .Unit("grey levels")
          .Doc("ssd: RMS difference per pixel and channel above this: not found"),
      DoubleOption<P>("template.ambiguity_margin", &P::ambiguity_margin)
          .Range(0, 2)
          .Doc("a distinct second peak this close (ZNCC) to the best: ambiguous, not found (0: off)"),
      IntOption<P>("template.search_margin_px", &P::search_margin_px)
          .Range(1, 4096)
          .Unit("px")
          .Doc("window margin around the constant-velocity prediction"),
      IntOption<P>("template.acquire_radius_px", &P::acquire_radius_px)
          .Range(0, 16384)
          .Unit("px")
          .Doc("after a loss, look this far from the last position (0: the whole frame)"),
      IntOption<P>("template.pyramid_levels", &P::pyramid_levels)
          .Range(1, 6)
          .Doc("coarse-to-fine levels for acquisition (1: full resolution only)"),
      DoubleOption<P>("template.update_rate", &P::update_rate)
          .Range(0, 1)
          .Doc("template update per verified match, towards the patch there (0: fixed template)"),
      DoubleOption<P>("template.drift_min_zncc", &P::drift_min_zncc)
          .Range(-1, 1)
          .Doc("least ZNCC of the match with the first template at the current scale (drift guard)"),
      BoolOption<P>("template.scale_search", &P::scale_search)
          .Doc("follow the marker's size: the first template tried 5 % larger and smaller each frame"),
      BoolOption<P>("template.turn_search", &P::turn_search)
          .Doc("follow the marker's turning: the first template tried 5 deg turned either way each frame"),
  };
}

}  // namespace

const OptionTable<TemplateParams>& TemplateParamsOptions() {
  static const OptionTable<TemplateParams> table = MakeTemplateTable();
  return table;
}

}  // namespace softsight
