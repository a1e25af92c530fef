#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "config/config_sections.h"
#include "core/test_util.h"
#include "softsight/calib/camera_calibration.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Each test reads its config in a folder of its own, removed when the test ends.
class MetricConfigTest : public ::testing::Test {
 protected:
  // Reads the metric keys of `yaml` as if it were the config file `name` in dir_.
  MetricModel Read(const std::string& yaml, const std::string& name = "config.yaml") {
    const std::string file = dir_.file(name);
    std::ofstream(file) << yaml;
    YamlMap top(LoadYamlFile(file), file, "");
    MetricModel metric;
    ReadMetricModel(top, &metric);
    return metric;
  }

  std::string ErrorOf(const std::string& yaml) {
    try {
      Read(yaml);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }

  const testing::TempDir dir_;
};

TEST_F(MetricConfigTest, NoKeysMeansNoMetric) { EXPECT_TRUE(Read("other: 1\n").empty()); }

TEST_F(MetricConfigTest, ScaleKey) {
  const MetricModel m = Read("scale_mm_per_px: 0.2\n");
  ASSERT_TRUE(m.scale_mm_per_px.has_value());
  EXPECT_DOUBLE_EQ(*m.scale_mm_per_px, 0.2);
  EXPECT_FALSE(m.plane_mm_from_image.has_value());
}

TEST_F(MetricConfigTest, PlaneFileIsReadBesideTheConfig) {
  PlaneCalibration plane;
  plane.plane_mm_from_image = cv::Matx33d(0.2, 0.01, -3, 0.002, 0.21, 4, 1e-5, 2e-5, 1);
  fs::create_directories(dir_.path() / "sub");
  SavePlaneCalibration(plane, (dir_.path() / "sub" / "plane.yaml").string());
  const MetricModel m = Read("plane: sub/plane.yaml\n");
  ASSERT_TRUE(m.plane_mm_from_image.has_value());
  for (int i = 0; i < 9; ++i) {
    EXPECT_DOUBLE_EQ(m.plane_mm_from_image->val[i], plane.plane_mm_from_image.val[i]);
  }
}

TEST_F(MetricConfigTest, MissingPlaneFileNamesConfigLineAndKey) {
  const std::string error = ErrorOf("a: 1\nplane: nowhere.yaml\n");
  EXPECT_THAT(error, HasSubstr("config.yaml:2:"));
  EXPECT_THAT(error, HasSubstr("plane"));
  EXPECT_THAT(error, HasSubstr("nowhere.yaml"));
}

TEST_F(MetricConfigTest, ScaleFromTwoPoints) {
  const MetricModel m = Read("scale_from_points: {a: [10, 10], b: [310, 410], distance_mm: 100}\n");
  ASSERT_TRUE(m.scale_mm_per_px.has_value());
  EXPECT_DOUBLE_EQ(*m.scale_mm_per_px, 0.2);
  ASSERT_TRUE(m.scale_points.has_value());  // Remembered, so a saved config writes the points.
  EXPECT_EQ(m.scale_points->b_px, cv::Point2d(310, 410));
  EXPECT_EQ(m.scale_points->distance_mm, 100.0);
  EXPECT_THAT(ErrorOf("scale_from_points: {a: [10, 10], b: [10, 10], distance_mm: 100}\n"),
              HasSubstr("scale_from_points.a"));
  EXPECT_THAT(ErrorOf("scale_from_points: {a: [10, 10], distance_mm: 100}\n"),
              HasSubstr("scale_from_points.b: missing"));
  EXPECT_THAT(ErrorOf("scale_from_points: {a: [10, 10], b: [1, 1], distance_mm: 5, c: 1}\n"),
              HasSubstr("scale_from_points.c: unknown key"));
}

TEST_F(MetricConfigTest, BadValuesAndConflictsAreErrors) {
  EXPECT_THAT(ErrorOf("scale_mm_per_px: 0\n"), HasSubstr("config.yaml:1: scale_mm_per_px"));
  EXPECT_THAT(ErrorOf("scale_mm_per_px: fast\n"), HasSubstr("expected a number"));
  EXPECT_THAT(ErrorOf("scale_mm_per_px: 0.2\nplane_mm_from_image: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"),
              HasSubstr("give one metric key only"));
  EXPECT_THAT(ErrorOf("plane_mm_from_image: [1, 2, 3, 2, 4, 6, 0, 0, 1]\n"),
              HasSubstr("singular"));
  EXPECT_THAT(ErrorOf("plane_mm_from_image: [1, 2, 3]\n"), HasSubstr("list of 9 numbers"));
}

TEST_F(MetricConfigTest, ScalePointsAreWrittenAsPointsAndReadBackToTheSameScale) {
  MetricModel original;
  original.scale_points = MetricModel::ScalePoints{{101.25, 40.0 / 3}, {250.5, 77.125}, 50};
  original.scale_mm_per_px = ScaleFromTwoPoints(original.scale_points->a_px,
                                                original.scale_points->b_px, 50);
  YAML::Emitter out;
  out << YAML::BeginMap;
  WriteMetricModel(original, out);
  out << YAML::EndMap;
  const std::string yaml = out.c_str();
  EXPECT_THAT(yaml, HasSubstr("scale_from_points"));
  EXPECT_THAT(yaml, ::testing::Not(HasSubstr("scale_mm_per_px")));
  const MetricModel again = Read(yaml + "\n");
  EXPECT_EQ(again.scale_mm_per_px, original.scale_mm_per_px);
  ASSERT_TRUE(again.scale_points.has_value());
  EXPECT_EQ(again.scale_points->a_px, original.scale_points->a_px);
  EXPECT_EQ(again.scale_points->b_px, original.scale_points->b_px);
}

TEST_F(MetricConfigTest, WrittenModelReadsBackExactly) {
  for (const bool plane : {false, true}) {
    MetricModel original;
    if (plane) {
      original.plane_mm_from_image =
          cv::Matx33d(0.2 / 3, 0.01, -3.25, 0.002, 0.21, 4.0 / 7, 1.0 / 3e5, 2e-5, 1);
    } else {
      original.scale_mm_per_px = 1.0 / 7.0;
    }
    YAML::Emitter out;
    out << YAML::BeginMap;
    WriteMetricModel(original, out);
    out << YAML::Key << "other" << YAML::Value << 1;
    out << YAML::EndMap;
    const MetricModel again = Read(std::string(out.c_str()) + "\n");
    EXPECT_EQ(again.scale_mm_per_px, original.scale_mm_per_px);
    ASSERT_EQ(again.plane_mm_from_image.has_value(), plane);
    if (plane) {
      for (int i = 0; i < 9; ++i) {
        EXPECT_EQ(again.plane_mm_from_image->val[i], original.plane_mm_from_image->val[i]);
      }
    }
  }
}

}  // namespace
}  // namespace softsight
