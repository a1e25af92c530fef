// A marker's keys of one kind of marker (softsight/track/tracker_kind.h): every key, its unit, range
// and doc is a row of the kind's option table (the colour kind's in src/track/colour_options.cc,
// the template kind's in src/track/template_options.cc; `softsight config --doc` prints them and
// examples/markers.yaml documents them), plus, for a kind that holds an image, the key naming
// the image file. Nothing here names a kind: a new kind's keys are read, written, checked and
// documented as these are.
//
//   markers:
//     - name: red
//       hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}   # colour kind: h 0..179 (may wrap)
//       blob: {min_area: 12}
//     - name: blue
//       method: zncc                                      # sad | ssd | zncc: the template kind
//       template:
//         frame: 0                 # reference frame the rectangle is cut from (default 0)
//         rect: [205, 186, 25, 25] # x, y, width, height in pixels (what the mouse drags)
//         # file: blue.png         # ... or a template image, relative to this config file
//
// A template with only `rect` is cut from frame `frame`; with only `file` it is the image and
// the first frame is searched whole. With both (what the live window's `s` saves for a template
// selected live) the image is the template and `rect` (the image's size) is where it was
// selected on frame `frame`: tracking starts there on that frame, as it did live.
#include <filesystem>
#include <map>
#include <mutex>
#include <system_error>

#include <opencv2/imgcodecs.hpp>

#include "config/config_sections.h"
#include "config/option_yaml.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {

const OptionTable<KindSection>& KindSectionOptions(const TrackerKind& kind) {
  static std::mutex mutex;  // Config files may be read in several threads (track_many).
  static std::map<const TrackerKind*, OptionTable<KindSection>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  auto [it, added] = tables.try_emplace(&kind);
  if (added) {
    AppendOptions(&it->second, "", &KindSection::params, kind.options());
    if (const std::optional<TrackerKind::ImageFileKey> image = kind.image_file()) {
      it->second.push_back(StringOption<KindSection>(image->key, &KindSection::image_file)
                               .Doc(image->doc));
    }
  }
  return it->second;
}

KindSection KindDefaults(const TrackerKind& kind) { return {kind.defaults(), ""}; }

void ReadKindParams(YamlMap& marker, KindSection* section) {
  const TrackerKind& kind = section->params.kind();
  for (const TrackerKind::ExclusiveKeys& pair : kind.exclusive_keys()) {
    if (marker.has(pair.first) && marker.has(pair.second)) marker.fail(pair.second, pair.problem);
  }
  const std::string file_before = section->image_file;
  ReadOptions(marker, KindSectionOptions(kind), section);
  std::string problem;
  if (!kind.check(section->params, &problem)) FailAtKey(marker, problem);  // Before the image.
  if (section->image_file == file_before || section->image_file.empty()) return;
  const std::string key = kind.image_file()->key;
  const std::string path = ResolveBesideFile(marker.file(), section->image_file);
  // A FIFO or device (/dev/stdin) would block imread for ever; a folder is no image either.
  std::error_code ignored;
  const std::filesystem::file_status status = std::filesystem::status(path, ignored);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    marker.fail(key, "'" + path + "' is not a regular file (an image file such as blue.png)");
  }
  const cv::Mat pixels = cv::imread(path, cv::IMREAD_COLOR);
  if (pixels.empty()) marker.fail(key, "cannot read image '" + path + "' (missing, or not an image)");
  if (const auto misfit = kind.set_image(section->params, pixels, section->image_file)) {
    FailAtKey(marker, *misfit);
  }
}

void WriteKindParams(const KindSection& section, YAML::Emitter& out) {
  // Only what differs from the kind's defaults: the file stays short and reads back to the same
  // values (nothing at all for a template still to be selected live).
  const TrackerKind& kind = section.params.kind();
  WriteOptions(KindSectionOptions(kind), section, out, KindDefaults(kind));
}

std::string DescribeKindKeys(const TrackerKind& kind, int indent) {
  return DescribeOptions(KindSectionOptions(kind), indent, KindDefaults(kind));
}

}  // namespace softsight
