// A marker's template-matching settings, under its `template:` key. The method itself (sad, ssd,
// zncc) is the marker's `method:` key, read by config.cc; a marker with a `template:` key and no
// method defaults to zncc. Every key, its unit, range and doc is a row of TemplateParams' option
// table (src/track/template_options.cc; `softsight config --doc` prints it):
//
//   markers:
//     - name: blue
//       method: zncc               # sad | ssd | zncc
//       template:
//         frame: 0                 # reference frame the rectangle is cut from (default 0)
//         rect: [205, 186, 25, 25] # x, y, width, height in pixels (what the mouse drags)
//         # file: blue.png         # ... or a template image, relative to this config file
//         min_zncc: 0.8            # below: not found (all methods; SAD/SSD: shape check)
//         ...
//
// With only `rect` the template is cut from frame `frame`; with only `file` it is the image and
// the first frame is searched whole. With both (what the live window's `s` saves for a template
// selected live) the image is the template and `rect` (the image's size) is where it was
// selected on frame `frame`: tracking starts there on that frame, as it did live. With neither,
// the template is selected live (softsight's window) or the marker is not found.
#include <filesystem>
#include <system_error>

#include <opencv2/imgcodecs.hpp>

#include "config/config_sections.h"
#include "config/option_yaml.h"
#include "track/track_options.h"

namespace softsight {

void ReadTemplateParams(YamlMap& marker, TemplateParams* params) {
  const std::string file_before = params->image_file;
  ReadOptions(marker, TemplateParamsOptions(), params);
  std::string problem;
  if (!params->Check(&problem)) FailAtKey(marker, problem);  // before the image is read
  if (params->image_file != file_before && !params->image_file.empty()) {
    const std::string path = ResolveBesideFile(marker.file(), params->image_file);
    // A FIFO or device (/dev/stdin) would block imread for ever; a folder is no image either.
    std::error_code ignored;
    const std::filesystem::file_status status = std::filesystem::status(path, ignored);
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
      marker.fail("template.file", "'" + path + "' is not a regular file (a template is an "
                  "image file such as blue.png)");
    }
    params->image = cv::imread(path, cv::IMREAD_COLOR);
    if (params->image.empty()) {
      marker.fail("template.file", "cannot read image '" + path + "' (missing, or not an image)");
    }
  }
}

void WriteTemplateParams(const TemplateParams& params, YAML::Emitter& out) {
  // Only what differs from the defaults; nothing at all for a colour marker or a template still
  // to be selected live.
  WriteOptions(TemplateParamsOptions(), params, out);
}

}  // namespace softsight
