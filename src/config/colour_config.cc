// A marker's colour-tracking keys. Every key, its unit, range and doc is a row of ColourParams'
// option table (src/track/colour_options.cc; `softsight config --doc` prints it and
// examples/markers.yaml documents it):
//   hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}   # h 0..179 (may wrap), s and v 0..255
//   auto_colour: [b, g, r]                            # instead of hsv: a nominal colour
//   gray: [200, 255]                                  # instead of hsv: a gray-level range
//   centroid: soft                                    # soft | binary
//   ambiguity_margin: 0.2
//   adapt_rate: 0.05
//   filter: {type: gaussian, ksize: 5}
//   morphology: {size: 3, shape: ellipse}
//   blob: {min_area: 12, max_area: 0, min_circularity: 0.5, min_area_fraction: 0.25,
//          max_area_factor: 4}
//   roi: [x, y, w, h]
//   window: 64
//   widen_steps: 2
//   acquire_downsample: 0
#include "config/config_sections.h"
#include "config/option_yaml.h"
#include "track/track_options.h"

namespace softsight {

void ReadColourParams(YamlMap& marker, ColourParams* params) {
  // The file-level rule: hsv ranges would be silently ignored beside auto_colour.
  if (marker.has("hsv") && marker.has("auto_colour")) {
    marker.fail("auto_colour", "give either hsv ranges or auto_colour, not both");
  }
  if (marker.has("hsv") && marker.has("gray")) {
    marker.fail("gray", "give either hsv ranges or a gray range, not both");
  }
  ReadOptions(marker, ColourParamsOptions(), params);
  std::string problem;
  if (!params->Check(&problem)) FailAtKey(marker, problem);
}

void WriteColourParams(const ColourParams& params, YAML::Emitter& out) {
  // Only what differs from the defaults: the file stays short and reads back to the same values.
  WriteOptions(ColourParamsOptions(), params, out);
}

}  // namespace softsight
