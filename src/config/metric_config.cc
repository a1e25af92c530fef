// The config's metric keys: how pixels become millimetres. One of
//   scale_mm_per_px: 0.2                     # camera axis orthogonal to the actuator's plane
//   plane: plane.yaml                        # `softsight calibrate --plane` output (relative
//                                            # paths are relative to the config file)
//   plane_mm_from_image: [9 numbers]         # the same homography inline, row-major (what a
//                                            # saved config holds)
//   scale_from_points: {a: [x, y], b: [x, y], distance_mm: 50}   # two points a known distance
//                                            # apart in the (undistorted) image
#include <filesystem>
#include <string>

#include "geometry/measure_options.h"
#include "config/config_sections.h"
#include "config/option_yaml.h"
#include "softsight/calib/camera_calibration.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr const char* kKeys[] = {"scale_mm_per_px", "plane", "plane_mm_from_image",
                                 "scale_from_points"};


}  // namespace

namespace {

// The metric keys the table does not hold: one given at most, then `plane` (a file) and
// `scale_from_points` (the points a scale is measured from).
const char* ReadMetricKeysBesideTheTable(YamlMap& top, MetricModel* metric) {
  const char* given = nullptr;
  for (const char* key : kKeys) {
    if (!top.has(key)) continue;
    if (given != nullptr) {
      top.fail(key, std::string("give one metric key only, but ") + given + " is set too");
    }
    given = key;
  }
  if (const auto plane_file = top.string("plane")) {
    const std::string path = ResolveBesideFile(top.file(), *plane_file);
    try {
      metric->plane_mm_from_image = LoadPlaneCalibration(path).plane_mm_from_image;
    } catch (const InputError& e) {
      top.fail("plane", e.what());
    }
  }
  if (top.has("scale_from_points")) {
    YamlMap points = top.map("scale_from_points");
    const auto a = points.numbers("a", 2, -1e6, 1e6);
    const auto b = points.numbers("b", 2, -1e6, 1e6);
    const auto distance = points.number("distance_mm", 0.0, 1e9);
    if (!a) points.fail("a", "missing: the first point [x, y] in image pixels");
    if (!b) points.fail("b", "missing: the second point [x, y] in image pixels");
    if (!distance) points.fail("distance_mm", "missing: the true distance between a and b");
    points.finish();
    const MetricModel::ScalePoints given_points{{(*a)[0], (*a)[1]}, {(*b)[0], (*b)[1]}, *distance};
    try {
      metric->scale_mm_per_px = ScaleFromTwoPoints(given_points.a_px, given_points.b_px,
                                                   given_points.distance_mm, "two points");
      metric->scale_points = given_points;
    } catch (const InputError& e) {
      points.fail("a", e.what());
    }
  }
  return given;
}

// The points, not the number: reading them back recomputes the identical scale, and the file
// says how it was measured.
void WriteScalePoints(const MetricModel& metric, YAML::Emitter& out) {
  if (!metric.scale_points) return;
  const MetricModel::ScalePoints& p = *metric.scale_points;
  YAML::Node points(YAML::NodeType::Map);
  PutOptionValue(points, "a", OptionValue(std::vector<double>{p.a_px.x, p.a_px.y}));
  PutOptionValue(points, "b", OptionValue(std::vector<double>{p.b_px.x, p.b_px.y}));
  PutOptionValue(points, "distance_mm", OptionValue(p.distance_mm));
  points.SetStyle(YAML::EmitterStyle::Flow);
  out << YAML::Key << "scale_from_points" << YAML::Value << points;
}

}  // namespace

void ReadMetricModel(YamlMap& top, MetricModel* metric) {
  *metric = MetricModel{};
  const char* given = ReadMetricKeysBesideTheTable(top, metric);
  ReadOptions(top, MetricModelOptions(), metric);
  std::string error;
  if (!metric->Check(&error)) top.fail(given != nullptr ? given : "scale_mm_per_px", error);
}

void ReadMeasureOptions(YamlMap& top, MeasureOptions* measure) {
  *measure = MeasureOptions{};
  const char* given = ReadMetricKeysBesideTheTable(top, &measure->metric);
  ReadOptions(top, MeasureOptionsTable(), measure);  // triple, chain, tip_reference, metric
  std::string error;
  if (!measure->metric.Check(&error)) {
    top.fail(given != nullptr ? given : "scale_mm_per_px", error);
  }
  if (!CheckMeasureOptionsOfAFile(*measure, &error)) FailAtKey(top, error);
}

bool CheckMeasureOptionsOfAFile(const MeasureOptions& measure, std::string* error) {
  // A triple is optional (one or two markers only track), so the file's rules are Check()'s.
  return measure.Check(error);
}

void WriteMeasureOptions(const MeasureOptions& measure, YAML::Emitter& out) {
  WriteOptions(MeasureOptionsTable(), measure, out);
  WriteScalePoints(measure.metric, out);
}

void WriteMetricModel(const MetricModel& metric, YAML::Emitter& out) {
  WriteOptions(MetricModelOptions(), metric, out);
  WriteScalePoints(metric, out);
}

}  // namespace softsight
