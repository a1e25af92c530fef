// A marker's template-matching settings, under its `template:` key. The method itself (sad, ssd,
// zncc) is the marker's `method:` key, read by config.cc; a marker with a `template:` key and no
// method defaults to zncc. Every key, its unit, range and doc is a row of TemplateParams' option
// table (src/track/template_options.cc; `softsight config --doc` prints it), but for `file`,
// which is a row of TemplateSectionOptions() here:
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
#include <sstream>
#include <system_error>

#include <opencv2/imgcodecs.hpp>

#include "config/config_sections.h"
#include "config/option_yaml.h"
#include "track/track_options.h"

namespace softsight {

const OptionTable<TemplateSection>& TemplateSectionOptions() {
  static const OptionTable<TemplateSection> table = [] {
    OptionTable<TemplateSection> t;
    AppendOptions(&t, "", &TemplateSection::params, TemplateParamsOptions());
    t.push_back(StringOption<TemplateSection>("template.file", &TemplateSection::file)
                    .Doc("template image, relative to the config file (with rect: selected there "
                         "live)"));
    return t;
  }();
  return table;
}

void ReadTemplateParams(YamlMap& marker, TemplateSection* section) {
  const std::string file_before = section->file;
  ReadOptions(marker, TemplateSectionOptions(), section);
  TemplateParams* params = &section->params;
  std::string problem;
  if (!params->Check(&problem)) FailAtKey(marker, problem);  // before the image is read
  if (section->file != file_before && !section->file.empty()) {
    const std::string path = ResolveBesideFile(marker.file(), section->file);
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
    if (params->rect && params->rect->size() != params->image.size()) {
      // With an image, rect says where it was selected: the image's own size.
      const cv::Rect& r = *params->rect;
      std::ostringstream problem_text;  // (not operator+ on a literal: GCC 12's -Wrestrict)
      problem_text << "[" << r.x << ", " << r.y << ", " << r.width << ", " << r.height
                   << "] is not the size of the image '" << section->file << "' ("
                   << params->image.cols << "x" << params->image.rows << " px)";
      marker.fail("template.rect", problem_text.str());
    }
  }
}

void WriteTemplateParams(const TemplateSection& section, YAML::Emitter& out) {
  // Only what differs from the defaults; nothing at all for a template still to be selected live.
  WriteOptions(TemplateSectionOptions(), section, out);
}

}  // namespace softsight
