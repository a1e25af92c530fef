// A marker's colour-tracking keys (examples/markers.yaml documents them):
//   hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}   # h 0..179 (may wrap), s and v 0..255
//   auto_colour: [b, g, r]                            # instead of hsv: Otsu on colour distance
//   filter: {type: gaussian, ksize: 5}                # none | gaussian | median, odd ksize
//   morphology: {size: 3, shape: ellipse}             # rect | ellipse | cross, odd size
//   blob: {min_area: 12, max_area: 0, min_circularity: 0.5, min_area_fraction: 0.25,
//          max_area_factor: 4}
//   roi: [x, y, w, h]
//   window: 64
//   widen_steps: 2
//   acquire_downsample: 0
#include <string>
#include <vector>

#include "io/config_sections.h"

namespace softsight {
namespace {

const std::vector<std::string> kFilters = {"none", "gaussian", "median"};
const std::vector<std::string> kShapes = {"rect", "ellipse", "cross"};

const char* FilterName(ColourParams::Filter filter) {
  switch (filter) {
    case ColourParams::Filter::kGaussian: return "gaussian";
    case ColourParams::Filter::kMedian: return "median";
    case ColourParams::Filter::kNone: break;
  }
  return "none";
}

const char* ShapeName(ColourParams::Shape shape) {
  switch (shape) {
    case ColourParams::Shape::kRect: return "rect";
    case ColourParams::Shape::kCross: return "cross";
    case ColourParams::Shape::kEllipse: break;
  }
  return "ellipse";
}

// A [lo, hi] pair; only hue may wrap (lo > hi).
void ReadRange(YamlMap& hsv, const std::string& key, int max, bool may_wrap, HsvRange* range) {
  const auto values = hsv.integers(key, 2, 0, max);
  if (!values) return;
  if (!may_wrap && (*values)[0] > (*values)[1]) {
    hsv.fail(key, "lower bound " + std::to_string((*values)[0]) + " is above upper bound " +
                      std::to_string((*values)[1]));
  }
  *range = HsvRange{(*values)[0], (*values)[1]};
}

void RequireOdd(YamlMap& map, const std::string& key, int value, int min) {
  if (value % 2 == 0 || value < min) {
    map.fail(key, "value " + std::to_string(value) + " must be odd and at least " +
                      std::to_string(min));
  }
}

}  // namespace

void ReadColourParams(YamlMap& marker, ColourParams* params) {
  if (marker.has("hsv") && marker.has("auto_colour")) {
    marker.fail("auto_colour", "give either hsv ranges or auto_colour, not both");
  }
  if (marker.has("hsv")) {
    YamlMap hsv = marker.map("hsv");
    ReadRange(hsv, "h", 179, true, &params->h);
    ReadRange(hsv, "s", 255, false, &params->s);
    ReadRange(hsv, "v", 255, false, &params->v);
    hsv.finish();
  }
  if (const auto bgr = marker.integers("auto_colour", 3, 0, 255)) {
    params->auto_bgr = cv::Vec3b(static_cast<uchar>((*bgr)[0]), static_cast<uchar>((*bgr)[1]),
                                 static_cast<uchar>((*bgr)[2]));
  }
  if (marker.has("filter")) {
    YamlMap filter = marker.map("filter");
    if (const auto type = filter.choice("type", kFilters)) {
      params->filter = *type == "gaussian" ? ColourParams::Filter::kGaussian
                       : *type == "median" ? ColourParams::Filter::kMedian
                                           : ColourParams::Filter::kNone;
    }
    if (const auto ksize = filter.integer("ksize", 1, 31)) {
      RequireOdd(filter, "ksize", *ksize, 3);
      params->filter_ksize = *ksize;
    }
    filter.finish();
  }
  if (marker.has("morphology")) {
    YamlMap morphology = marker.map("morphology");
    if (const auto size = morphology.integer("size", 1, 31)) {
      RequireOdd(morphology, "size", *size, 1);
      params->morph_size = *size;
    }
    if (const auto shape = morphology.choice("shape", kShapes)) {
      params->morph_shape = *shape == "rect"    ? ColourParams::Shape::kRect
                            : *shape == "cross" ? ColourParams::Shape::kCross
                                                : ColourParams::Shape::kEllipse;
    }
    morphology.finish();
  }
  if (marker.has("blob")) {
    YamlMap blob = marker.map("blob");
    params->min_area_px = blob.number("min_area", 1, 1e9).value_or(params->min_area_px);
    params->max_area_px = blob.number("max_area", 0, 1e9).value_or(params->max_area_px);
    if (params->max_area_px > 0 && params->max_area_px < params->min_area_px) {
      blob.fail("max_area", "must be 0 (no limit) or at least min_area");
    }
    params->min_circularity =
        blob.number("min_circularity", 0, 1).value_or(params->min_circularity);
    params->min_area_fraction =
        blob.number("min_area_fraction", 0, 1).value_or(params->min_area_fraction);
    params->max_area_factor =
        blob.number("max_area_factor", 0, 1e6).value_or(params->max_area_factor);
    if (params->max_area_factor > 0 && params->max_area_factor < 1) {
      blob.fail("max_area_factor", "must be 0 (no limit) or at least 1");
    }
    blob.finish();
  }
  if (const auto roi = marker.integers("roi", 4, 0, 1 << 20)) {
    if ((*roi)[2] <= 0 || (*roi)[3] <= 0) {
      marker.fail("roi", "[x, y, w, h] needs a positive width and height");
    }
    params->roi = cv::Rect((*roi)[0], (*roi)[1], (*roi)[2], (*roi)[3]);
  }
  if (const auto window = marker.integer("window", 0, 4096)) {
    if (*window != 0 && *window < 8) {
      marker.fail("window", "must be 0 (search the whole frame) or at least 8 pixels");
    }
    params->window_px = *window;
  }
  params->widen_steps = marker.integer("widen_steps", 0, 8).value_or(params->widen_steps);
  if (const auto factor = marker.integer("acquire_downsample", 0, 8)) {
    if (*factor != 0 && *factor != 1 && *factor != 2 && *factor != 4 && *factor != 8) {
      marker.fail("acquire_downsample", "must be 0 (automatic), 1, 2, 4 or 8");
    }
    params->acquire_downsample = *factor;
  }
}

void WriteColourParams(const ColourParams& params, YAML::Emitter& out) {
  // Only what differs from the defaults, a section at a time: the file stays short and reads
  // back to the same values.
  const ColourParams d;
  auto range = [&](const HsvRange& r) {
    out << YAML::Flow << YAML::BeginSeq << r.lo << r.hi << YAML::EndSeq;
  };
  if (params.auto_bgr) {
    const cv::Vec3b c = *params.auto_bgr;
    out << YAML::Key << "auto_colour" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << static_cast<int>(c[0]) << static_cast<int>(c[1]) << static_cast<int>(c[2])
        << YAML::EndSeq;
  } else if (params.h.lo != d.h.lo || params.h.hi != d.h.hi || params.s.lo != d.s.lo ||
             params.s.hi != d.s.hi || params.v.lo != d.v.lo || params.v.hi != d.v.hi) {
    out << YAML::Key << "hsv" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "h" << YAML::Value;
    range(params.h);
    out << YAML::Key << "s" << YAML::Value;
    range(params.s);
    out << YAML::Key << "v" << YAML::Value;
    range(params.v);
    out << YAML::EndMap;
  }
  if (params.filter != d.filter || params.filter_ksize != d.filter_ksize) {
    out << YAML::Key << "filter" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
        << "type" << YAML::Value << FilterName(params.filter) << YAML::Key << "ksize"
        << YAML::Value << params.filter_ksize << YAML::EndMap;
  }
  if (params.morph_size != d.morph_size || params.morph_shape != d.morph_shape) {
    out << YAML::Key << "morphology" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
        << "size" << YAML::Value << params.morph_size << YAML::Key << "shape" << YAML::Value
        << ShapeName(params.morph_shape) << YAML::EndMap;
  }
  if (params.min_area_px != d.min_area_px || params.max_area_px != d.max_area_px ||
      params.min_circularity != d.min_circularity ||
      params.min_area_fraction != d.min_area_fraction ||
      params.max_area_factor != d.max_area_factor) {
    out << YAML::Key << "blob" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "min_area" << YAML::Value << params.min_area_px;
    out << YAML::Key << "max_area" << YAML::Value << params.max_area_px;
    out << YAML::Key << "min_circularity" << YAML::Value << params.min_circularity;
    out << YAML::Key << "min_area_fraction" << YAML::Value << params.min_area_fraction;
    out << YAML::Key << "max_area_factor" << YAML::Value << params.max_area_factor;
    out << YAML::EndMap;
  }
  if (params.roi) {
    out << YAML::Key << "roi" << YAML::Value << YAML::Flow << YAML::BeginSeq << params.roi->x
        << params.roi->y << params.roi->width << params.roi->height << YAML::EndSeq;
  }
  if (params.window_px != d.window_px) {
    out << YAML::Key << "window" << YAML::Value << params.window_px;
  }
  if (params.widen_steps != d.widen_steps) {
    out << YAML::Key << "widen_steps" << YAML::Value << params.widen_steps;
  }
  if (params.acquire_downsample != d.acquire_downsample) {
    out << YAML::Key << "acquire_downsample" << YAML::Value << params.acquire_downsample;
  }
}

}  // namespace softsight
