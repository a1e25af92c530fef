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

#include "io/config_sections.h"
#include "softsight/calib/camera_calibration.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr const char* kKeys[] = {"scale_mm_per_px", "plane", "plane_mm_from_image",
                                 "scale_from_points"};


}  // namespace

void ReadMetricModel(YamlMap& top, MetricModel* metric) {
  *metric = MetricModel{};
  const char* given = nullptr;
  for (const char* key : kKeys) {
    if (!top.has(key)) continue;
    if (given != nullptr) {
      top.fail(key, std::string("give one metric key only, but ") + given + " is set too");
    }
    given = key;
  }

  if (const auto scale = top.number("scale_mm_per_px", 1e-9, 1e6)) {
    metric->scale_mm_per_px = *scale;
  }
  if (const auto plane_file = top.string("plane")) {
    const std::string path = ResolveBesideFile(top.file(), *plane_file);
    try {
      metric->plane_mm_from_image = LoadPlaneCalibration(path).plane_mm_from_image;
    } catch (const InputError& e) {
      top.fail("plane", e.what());
    }
  }
  if (const auto h = top.numbers("plane_mm_from_image", 9, -1e12, 1e12)) {
    cv::Matx33d m;
    for (int i = 0; i < 9; ++i) m.val[i] = (*h)[i];
    metric->plane_mm_from_image = m;
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

  std::string error;
  if (!metric->Check(&error)) top.fail(given != nullptr ? given : "scale_mm_per_px", error);
}

void WriteMetricModel(const MetricModel& metric, YAML::Emitter& out) {
  if (metric.scale_points) {
    // The points, not the number: reading them back recomputes the identical scale, and the
    // file says how it was measured.
    const MetricModel::ScalePoints& p = *metric.scale_points;
    out << YAML::Key << "scale_from_points" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "a" << YAML::Value << YAML::Flow << YAML::BeginSeq << p.a_px.x << p.a_px.y
        << YAML::EndSeq;
    out << YAML::Key << "b" << YAML::Value << YAML::Flow << YAML::BeginSeq << p.b_px.x << p.b_px.y
        << YAML::EndSeq;
    out << YAML::Key << "distance_mm" << YAML::Value << p.distance_mm;
    out << YAML::EndMap;
  } else if (metric.scale_mm_per_px) {
    out << YAML::Key << "scale_mm_per_px" << YAML::Value << *metric.scale_mm_per_px;
  }
  if (metric.plane_mm_from_image) {
    out << YAML::Key << "plane_mm_from_image" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (int i = 0; i < 9; ++i) out << metric.plane_mm_from_image->val[i];
    out << YAML::EndSeq;
  }
}

}  // namespace softsight
