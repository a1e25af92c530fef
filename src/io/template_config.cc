// A marker's template-matching settings, under its `template:` key. The method itself (sad, ssd,
// zncc) is the marker's `method:` key, read by config.cc; a marker with a `template:` key and no
// method defaults to zncc.
//
//   markers:
//     - name: blue
//       method: zncc               # sad | ssd | zncc
//       template:
//         frame: 0                 # reference frame the rectangle is cut from (default 0)
//         rect: [205, 186, 25, 25] # x, y, width, height in pixels (what the mouse drags)
//         # file: blue.png         # ... or a template image, relative to this config file
//         colour: false            # match BGR, not gray (3x the work; tells the discs apart)
//         contrast_gray: true      # gray: match BGR projected on the template's colour axis
//         round: false             # match only the ellipse inscribed in the rectangle
//         centre_on_symmetry: false  # report the template's centre of symmetry (disc centre)
//         min_zncc: 0.8            # below: not found (all methods; SAD/SSD: shape check)
//         max_sad: 20              # sad: mean |difference| per pixel and channel above: lost
//         max_ssd: 25              # ssd: RMS difference per pixel and channel above: lost
//         search_margin_px: 8      # window margin around the constant-velocity prediction
//         acquire_radius_px: 64    # after a loss, look this far from the last position (0: all)
//         pyramid_levels: 3        # coarse-to-fine levels for acquisition
//         update_rate: 0           # slow template update per frame (0: off)
//         drift_min_zncc: 0.9      # drift guard of the update
//
// `rect` and `file` are exclusive; with neither, the template is selected live (softsight's
// window) or the marker is not found. Units, defaults and trade-offs of every key are those of
// the TemplateParams field of the same name (softsight/track/template_tracker.h).
#include <filesystem>
#include <limits>

#include <opencv2/imgcodecs.hpp>

#include "io/config_sections.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr int kMaxInt = std::numeric_limits<int>::max();


}  // namespace

void ReadTemplateParams(YamlMap& marker, TemplateParams* params) {
  if (!marker.has("template")) return;
  YamlMap t = marker.map("template");
  if (const auto frame = t.integer("frame", 0, kMaxInt)) params->template_frame = *frame;
  if (const auto rect = t.integers("rect", 4, 0, kMaxInt)) {
    params->rect = cv::Rect((*rect)[0], (*rect)[1], (*rect)[2], (*rect)[3]);
  }
  if (const auto file = t.string("file")) {
    if (params->rect) t.fail("file", "give either rect or file, not both");
    const std::string path = ResolveBesideFile(t.file(), *file);
    params->image = cv::imread(path, cv::IMREAD_COLOR);
    if (params->image.empty()) {
      t.fail("file", "cannot read image '" + path + "' (missing, or not an image)");
    }
    params->image_file = *file;
  }
  if (const auto colour = t.boolean("colour")) params->colour = *colour;
  if (const auto v = t.boolean("contrast_gray")) params->contrast_gray = *v;
  if (const auto round = t.boolean("round")) params->round_mask = *round;
  if (const auto v = t.boolean("centre_on_symmetry")) params->centre_on_symmetry = *v;
  if (const auto v = t.number("min_zncc", -1.0, 1.0)) params->min_zncc = *v;
  if (const auto v = t.number("max_sad", 1e-9, 255.0)) params->max_sad = *v;
  if (const auto v = t.number("max_ssd", 1e-9, 255.0)) params->max_ssd = *v;
  if (const auto v = t.integer("search_margin_px", 1, 4096)) params->search_margin_px = *v;
  if (const auto v = t.integer("acquire_radius_px", 0, kMaxInt)) params->acquire_radius_px = *v;
  if (const auto v = t.integer("pyramid_levels", 1, 6)) params->pyramid_levels = *v;
  if (const auto v = t.number("update_rate", 0.0, 0.999)) params->update_rate = *v;
  if (const auto v = t.number("drift_min_zncc", -1.0, 1.0)) params->drift_min_zncc = *v;
  t.finish();  // config.cc runs TemplateParams::Check() with the marker's name.
}

void WriteTemplateParams(const TemplateParams& params, YAML::Emitter& out) {
  const TemplateParams defaults;
  const bool any = params.rect || !params.image_file.empty() ||
                   params.template_frame != defaults.template_frame ||
                   params.colour != defaults.colour || params.round_mask != defaults.round_mask ||
                   params.contrast_gray != defaults.contrast_gray ||
                   params.centre_on_symmetry != defaults.centre_on_symmetry ||
                   params.min_zncc != defaults.min_zncc || params.max_sad != defaults.max_sad ||
                   params.max_ssd != defaults.max_ssd ||
                   params.search_margin_px != defaults.search_margin_px ||
                   params.acquire_radius_px != defaults.acquire_radius_px ||
                   params.pyramid_levels != defaults.pyramid_levels ||
                   params.update_rate != defaults.update_rate ||
                   params.drift_min_zncc != defaults.drift_min_zncc;
  if (!any) return;  // A colour marker, or a template still to be selected live.
  out << YAML::Key << "template" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "frame" << YAML::Value << params.template_frame;
  if (params.rect) {
    out << YAML::Key << "rect" << YAML::Value << YAML::Flow << YAML::BeginSeq << params.rect->x
        << params.rect->y << params.rect->width << params.rect->height << YAML::EndSeq;
  } else if (!params.image_file.empty()) {
    out << YAML::Key << "file" << YAML::Value << params.image_file;
  }
  out << YAML::Key << "colour" << YAML::Value << params.colour;
  out << YAML::Key << "contrast_gray" << YAML::Value << params.contrast_gray;
  out << YAML::Key << "round" << YAML::Value << params.round_mask;
  out << YAML::Key << "centre_on_symmetry" << YAML::Value << params.centre_on_symmetry;
  out << YAML::Key << "min_zncc" << YAML::Value << params.min_zncc;
  out << YAML::Key << "max_sad" << YAML::Value << params.max_sad;
  out << YAML::Key << "max_ssd" << YAML::Value << params.max_ssd;
  out << YAML::Key << "search_margin_px" << YAML::Value << params.search_margin_px;
  out << YAML::Key << "acquire_radius_px" << YAML::Value << params.acquire_radius_px;
  out << YAML::Key << "pyramid_levels" << YAML::Value << params.pyramid_levels;
  out << YAML::Key << "update_rate" << YAML::Value << params.update_rate;
  out << YAML::Key << "drift_min_zncc" << YAML::Value << params.drift_min_zncc;
  out << YAML::EndMap;
}

}  // namespace softsight
