#include "softsight/config/config.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>

#include "config/config_sections.h"
#include "config/option_yaml.h"
#include "config/yaml_map.h"
#include "control/control_options.h"
#include "geometry/measure_options.h"
#include "io/camera_options.h"
#include "softsight/core/error.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {
namespace {

// The `changes:` list of a live recording's config (ConfigChange): each entry an `after_frame`
// and exactly one of `respec:` (a marker as under `markers:`), `reselect: {marker, rect}`,
// `retrack: <marker>` or `reset_tip_reference: true`, in frame order, naming known markers.
std::vector<ConfigChange> ReadChanges(const YAML::Node& list, const std::string& file,
                                      const std::set<std::string>& names,
                                      const std::optional<std::string>& method_override,
                                      std::vector<std::string>* files_read) {
  if (!list.IsSequence()) {
    throw InputError(file + ": changes: expected a list (written by live recordings)");
  }
  std::vector<ConfigChange> changes;
  for (size_t i = 0; i < list.size(); ++i) {
    YamlMap entry(list[i], file, "changes[" + std::to_string(i) + "]");
    ConfigChange change;
    change.after_frame = entry.integer("after_frame", 0, 1 << 30).value_or(-1);
    if (change.after_frame < 0) entry.fail("after_frame", "every change needs its frame");
    if (!changes.empty() && change.after_frame < changes.back().after_frame) {
      entry.fail("after_frame", "changes must be in frame order");
    }
    const int kinds = entry.has("respec") + entry.has("reselect") + entry.has("retrack") +
                      entry.has("reset_tip_reference");
    if (kinds != 1) {
      entry.fail("after_frame",
                 "each change is one of respec, reselect, retrack or reset_tip_reference");
    }
    if (entry.has("respec")) {
      change.kind = ConfigChange::Kind::kRespec;
      YamlMap marker = entry.map("respec");
      change.spec = ReadMarker(marker, method_override, &change.template_file);
      change.marker = change.spec.name;
      if (!change.template_file.empty()) {
        files_read->push_back(ResolveBesideFile(file, change.template_file));
      }
    } else if (entry.has("reselect")) {
      change.kind = ConfigChange::Kind::kReselect;
      YamlMap reselect = entry.map("reselect");
      change.marker = reselect.string("marker").value_or("");
      const auto rect = reselect.integers("rect", 4, 0, 1 << 20);
      if (!rect || (*rect)[2] <= 0 || (*rect)[3] <= 0) {
        reselect.fail("rect", "expected [x, y, width, height] with a positive size");
      }
      change.rect = cv::Rect((*rect)[0], (*rect)[1], (*rect)[2], (*rect)[3]);
      reselect.finish();
    } else if (entry.has("retrack")) {
      change.kind = ConfigChange::Kind::kRetrack;
      change.marker = entry.string("retrack").value_or("");
    } else {
      change.kind = ConfigChange::Kind::kResetTipReference;
      if (!entry.boolean("reset_tip_reference").value_or(false)) {
        entry.fail("reset_tip_reference", "only `true` is a change");
      }
    }
    if (names.count(change.marker) == 0 && change.kind != ConfigChange::Kind::kResetTipReference) {
      entry.fail(change.kind == ConfigChange::Kind::kRetrack ? "retrack" : "after_frame",
                 "'" + change.marker + "' is not the name of a marker in this file");
    }
    entry.finish();
    changes.push_back(std::move(change));
  }
  return changes;
}

void CheckMethodOverride(const std::optional<std::string>& method_override) {
  if (method_override) {
    const std::vector<std::string> methods = TrackerMethods();
    if (std::find(methods.begin(), methods.end(), *method_override) == methods.end()) {
      std::string list;
      for (const std::string& m : methods) list += (list.empty() ? "" : ", ") + m;
      throw InputError("--method " + *method_override + ": unknown method (choose " + list + ")");
    }
  }
}

TrackingConfig ReadTrackingConfigNode(const YAML::Node& root, const std::string& file,
                                      const std::optional<std::string>& method_override) {
  CheckMethodOverride(method_override);
  if (!root.IsDefined() || root.IsNull()) throw InputError(file + ": config file is empty");
  YamlMap top(root, file, "");
  TrackingConfig config;
  config.source_file = file;

  const YAML::Node markers = top.node("markers");
  if (!markers.IsDefined() || !markers.IsSequence() || markers.size() == 0) {
    top.fail("markers", "expected a list of markers, each with at least a name");
  }
  std::set<std::string> names;
  for (size_t i = 0; i < markers.size(); ++i) {
    YamlMap marker(markers[i], file, "markers[" + std::to_string(i) + "]");
    std::string image_file;
    std::vector<MarkerParams> aside;
    MarkerSpec spec = ReadMarker(marker, method_override, &image_file, &aside);
    if (!names.insert(spec.name).second) {
      marker.fail("name", "marker name '" + spec.name + "' is used twice");
    }
    if (!image_file.empty()) config.template_files[spec.name] = image_file;
    if (!aside.empty()) config.params_aside[spec.name] = std::move(aside);
    config.markers.push_back(std::move(spec));
  }

  auto check_names = [&](const std::string& key, const std::vector<std::string>& list) {
    for (const std::string& name : list) {
      if (names.count(name) == 0) {
        top.fail(key, "'" + name + "' is not the name of a marker in this file");
      }
    }
  };
  ReadMeasureOptions(top, &config.measure);  // triple, chain, tip_reference, metric keys
  if (!config.measure.base.empty()) {
    check_names("triple", {config.measure.base, config.measure.middle, config.measure.tip});
  }
  check_names("chain", config.measure.chain);
  config.files_read.push_back(file);
  if (const auto plane = top.string("plane")) config.files_read.push_back(ResolveBesideFile(file, *plane));
  for (const auto& [name, image_file] : config.template_files) {
    config.files_read.push_back(ResolveBesideFile(file, image_file));
  }
  if (const auto camera = top.string("camera")) {
    config.camera_file = *camera;
    config.files_read.push_back(ResolveBesideFile(file, *camera));
    try {
      config.camera = LoadCameraIntrinsics(ResolveBesideFile(file, *camera));
    } catch (const InputError& e) {
      top.fail("camera", e.what());
    }
  }
  if (top.has("control")) {
    YamlMap control = top.map("control");
    config.control.emplace();
    ReadControlConfig(control, &*config.control);
  }
  if (top.has("capture")) {
    // Every key, unit and range is a row of CameraSettingsTable() (io/camera_settings.cc).
    YamlMap capture = top.map("capture");
    config.capture.emplace();
    ReadOptions(capture, CameraSettingsTable(), &*config.capture);
    capture.finish();
    std::string problem;
    if (!config.capture->Check(&problem)) FailAtKey(capture, problem);
  }
  if (top.has("recording")) {
    YamlMap recording = top.map("recording");
    RecordingOrigin origin;
    origin.first_frame = recording.integer("first_frame", 0, 1 << 30).value_or(0);
    origin.first_time_s = recording.number("first_time_s", 0.0, 1e9).value_or(0.0);
    recording.finish();
    config.recording = origin;
  }
  if (top.has("changes")) {
    config.changes =
        ReadChanges(top.node("changes"), file, names, method_override, &config.files_read);
  }
  top.finish();
  return config;
}

}  // namespace

MarkerSpec ReadMarker(YamlMap& marker, const std::optional<std::string>& method_override,
                      std::string* image_file, std::vector<MarkerParams>* aside) {
  MarkerSpec spec;
  spec.name = marker.string("name").value_or("");
  if (spec.name.empty()) marker.fail("name", "every marker needs a name");
  // Every CSV column of the marker starts with its name: a huge name is a huge header.
  constexpr size_t kMaxNameLength = 64;
  if (spec.name.size() > kMaxNameLength) {
    marker.fail("name", "a name of " + std::to_string(spec.name.size()) + " characters; at most " +
                            std::to_string(kMaxNameLength) + " (it prefixes CSV columns)");
  }
  for (char c : spec.name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) {
      // Escaped: the name may hold a line break or any byte, and the message is one line.
      // (Appended, not "'" + ...: GCC 12 warns falsely about operator+ of a literal there.)
      std::string message = "'";
      message += EscapeForMessage(spec.name);
      message += "' must use letters, digits, '_' or '-' (it prefixes CSV columns)";
      marker.fail("name", message);
    }
  }
  // Unnamed, the method is the default one of the first kind the entry's keys claim (a
  // `template:` key: zncc), else of the first kind.
  const auto has_key = [&marker](const std::string& key) { return marker.has(key); };
  const TrackerKind* unnamed = TrackerKinds().front();
  for (const TrackerKind* kind : TrackerKinds()) {
    if (kind->claims_unnamed(has_key)) {
      unnamed = kind;
      break;
    }
  }
  std::string method =
      marker.choice("method", TrackerMethods()).value_or(unnamed->method_of(unnamed->defaults()));
  if (method_override) method = *method_override;
  const TrackerKind* chosen = KindOfMethod(method);  // Known: choice() and the override checked.
  // Every kind's keys are read and checked (a typo or a bad value in any is an error), and the
  // marker is the chosen method's parameters.
  std::vector<KindSection> sections;
  for (const TrackerKind* kind : TrackerKinds()) {
    KindSection section{kind->defaults(), ""};
    ReadKindParams(marker, &section);
    sections.push_back(std::move(section));
  }
  marker.finish();
  for (KindSection& section : sections) {
    const TrackerKind& kind = section.params.kind();
    if (&kind == chosen) {
      spec.params = std::move(section.params);
      kind.select_method(spec.params, method);
      *image_file = section.image_file;
    } else if (aside != nullptr && OptionsToYaml(KindSectionOptions(kind), section,
                                                 {kind.defaults(), ""}).size() > 0) {
      // Range-checked key by key above; the rules across fields are checked when it is used.
      aside->push_back(std::move(section.params));
    }
  }
  std::string problem;
  if (!chosen->check(spec.params, &problem)) {
    throw InputError(marker.file() + ": marker '" + spec.name + "': " + problem);
  }
  return spec;
}

void WriteMarker(const MarkerSpec& spec, const std::string& image_file, YAML::Emitter& out,
                 const std::vector<MarkerParams>* aside) {
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << spec.name;
  out << YAML::Key << "method" << YAML::Value << TrackerMethodName(spec.params);
  // Kind by kind, in the registry's order: the marker's own keys, and those set aside.
  for (const TrackerKind* kind : TrackerKinds()) {
    if (&spec.params.kind() == kind) {
      WriteKindParams({spec.params, image_file}, out);
    } else if (aside != nullptr) {
      for (const MarkerParams& params : *aside) {
        if (&params.kind() == kind) WriteKindParams({params, ""}, out);
      }
    }
  }
  out << YAML::EndMap;
}

TrackingConfig LoadTrackingConfig(const std::string& file,
                                  const std::optional<std::string>& method_override) {
  CheckMethodOverride(method_override);  // Before the file: a bad --method is named first.
  return ReadTrackingConfig(LoadYamlFile(file), file, method_override);
}

TrackingConfig ReadTrackingConfig(const YAML::Node& root, const std::string& file,
                                  const std::optional<std::string>& method_override) {
  try {
    return ReadTrackingConfigNode(root, file, method_override);
  } catch (const YAML::Exception& e) {
    RethrowYamlError(file, e);
  }
}

std::vector<PathRole> ConfigInputs(const TrackingConfig& config) {
  std::vector<PathRole> inputs;
  for (size_t i = 0; i < config.files_read.size(); ++i) {
    inputs.push_back({i == 0 ? "the config" : "a file the config names:", config.files_read[i]});
  }
  return inputs;
}

void SaveTrackingConfig(const TrackingConfig& config, const std::string& file) {
  YAML::Emitter out;
  out << YAML::Comment("softsight tracking config (see examples/markers.yaml for every key)");
  out << YAML::BeginMap;
  out << YAML::Key << "markers" << YAML::Value << YAML::BeginSeq;
  for (const MarkerSpec& spec : config.markers) {
    const auto file = config.template_files.find(spec.name);
    const auto aside = config.params_aside.find(spec.name);
    WriteMarker(spec, file == config.template_files.end() ? "" : file->second, out,
                aside == config.params_aside.end() ? nullptr : &aside->second);
  }
  out << YAML::EndSeq;
  WriteMeasureOptions(config.measure, out);
  if (config.camera_file) out << YAML::Key << "camera" << YAML::Value << *config.camera_file;
  if (config.capture && !(*config.capture == CameraSettings{})) {
    out << YAML::Key << "capture" << YAML::Value << YAML::BeginMap;
    WriteOptions(CameraSettingsTable(), *config.capture, out);
    out << YAML::EndMap;
  }
  if (config.recording) {
    out << YAML::Key << "recording" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "first_frame" << YAML::Value << config.recording->first_frame;
    out << YAML::Key << "first_time_s" << YAML::Value << YAML::Precision(17)
        << config.recording->first_time_s;
    out << YAML::EndMap;
  }
  if (!config.changes.empty()) {
    out << YAML::Key << "changes" << YAML::Value << YAML::BeginSeq;
    for (const ConfigChange& change : config.changes) {
      out << YAML::BeginMap << YAML::Key << "after_frame" << YAML::Value << change.after_frame;
      switch (change.kind) {
        case ConfigChange::Kind::kRespec:
          out << YAML::Key << "respec" << YAML::Value;
          WriteMarker(change.spec, change.template_file, out);
          break;
        case ConfigChange::Kind::kReselect:
          out << YAML::Key << "reselect" << YAML::Value << YAML::Flow << YAML::BeginMap
              << YAML::Key << "marker" << YAML::Value << change.marker << YAML::Key << "rect"
              << YAML::Value << YAML::Flow << YAML::BeginSeq << change.rect.x << change.rect.y
              << change.rect.width << change.rect.height << YAML::EndSeq << YAML::EndMap;
          break;
        case ConfigChange::Kind::kRetrack:
          out << YAML::Key << "retrack" << YAML::Value << change.marker;
          break;
        case ConfigChange::Kind::kResetTipReference:
          out << YAML::Key << "reset_tip_reference" << YAML::Value << true;
          break;
      }
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  if (config.control) {
    out << YAML::Key << "control" << YAML::Value << YAML::BeginMap;
    WriteControlConfig(*config.control, out);
    out << YAML::EndMap;
  }
  out << YAML::EndMap;

  // Whole or not at all: a config that cannot be written completely leaves the old one.
  WriteWholeFileOrThrow(file, std::string(out.c_str()) + "\n");
}

std::string DocumentConfig() {
  std::string methods;
  for (const std::string& m : TrackerMethods()) methods += (methods.empty() ? "" : " | ") + m;
  std::string doc =
      "# softsight tracking config: every key with its default, unit and range, generated from\n"
      "# the option tables (softsight config --doc). Keys shown commented out are unset by\n"
      "# default. examples/markers.yaml and examples/rig.yaml show them in use.\n"
      "markers:                                  # one entry per marker\n"
      "  - name: red                             # required: letters, digits, '_' or '-'; prefixes "
      "its CSV columns\n"
      "    method: colour                        # " + methods +
      " (default: colour, or zncc with a template key)\n";
  for (const TrackerKind* kind : TrackerKinds()) {
    std::string kind_methods;
    for (const std::string& m : kind->methods()) kind_methods += (kind_methods.empty() ? "" : ", ") + m;
    doc += "    # ---- " + kind->name() + " (method " + kind_methods + ")\n";
    doc += DescribeKindKeys(*kind, 4);
  }
  doc += "# ---- measurements (triple and chain name markers above)\n";
  doc += DescribeOptions(MeasureOptionsTable(), 0);
  doc +=
      "# plane: plane.yaml                        # instead of scale_mm_per_px: `softsight "
      "calibrate --plane` output\n"
      "# scale_from_points: {a: [x, y], b: [x, y], distance_mm: 50}   # px, px, mm: two points a "
      "known distance apart\n"
      "# camera: camera.yaml                       # lens model from `softsight calibrate`\n"
      "control:                                   # closed loop (softsight control, rig)\n";
  doc += DescribeOptions(ControlConfigTable(), 2);
  return doc;
}

}  // namespace softsight
