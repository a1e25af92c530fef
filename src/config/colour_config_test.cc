#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "config/config_sections.h"
#include "config/kind_config_test_util.h"
#include "config/yaml_map.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {
namespace {

ColourParams ReadFile(const std::string& path) {
  YamlMap marker(LoadYamlFile(path), path, "markers[0]");
  ColourParams params;
  ReadColourParams(marker, &params);
  marker.finish();
  return params;
}

// Each test writes its files in a folder of its own, removed when the test ends.
class ColourConfig : public ::testing::Test {
 protected:
  std::string WriteTemp(const std::string& name, const std::string& text) const {
    const std::string path = dir_.file(name);
    std::ofstream(path) << text;
    return path;
  }

  // The InputError message of reading `text`, or "" when it reads fine.
  std::string ErrorOf(const std::string& text) const {
    const std::string path = WriteTemp("bad_colour.yaml", text);
    try {
      ReadFile(path);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  const testing::TempDir dir_;
};

TEST_F(ColourConfig, ReadsEveryKey) {
  const std::string path = WriteTemp("colour.yaml",
                                     "hsv: {h: [170, 10], s: [80, 255], v: [40, 250]}\n"
                                     "filter: {type: median, ksize: 5}\n"
                                     "morphology: {size: 5, shape: cross}\n"
                                     "blob: {min_area: 20, max_area: 900, min_circularity: 0.6,\n"
                                     "       min_area_fraction: 0.3, max_area_factor: 3}\n"
                                     "roi: [150, 300, 40, 41]\n"
                                     "window: 48\n"
                                     "widen_steps: 3\n"
                                     "acquire_downsample: 2\n");
  const ColourParams p = ReadFile(path);
  EXPECT_EQ(p.h.lo, 170);
  EXPECT_EQ(p.h.hi, 10);
  EXPECT_EQ(p.s.lo, 80);
  EXPECT_EQ(p.v.hi, 250);
  EXPECT_FALSE(p.auto_bgr);
  EXPECT_EQ(p.filter, ColourParams::Filter::kMedian);
  EXPECT_EQ(p.filter_ksize, 5);
  EXPECT_EQ(p.morph_size, 5);
  EXPECT_EQ(p.morph_shape, ColourParams::Shape::kCross);
  EXPECT_EQ(p.min_area_px, 20);
  EXPECT_EQ(p.max_area_px, 900);
  EXPECT_DOUBLE_EQ(p.min_circularity, 0.6);
  EXPECT_DOUBLE_EQ(p.min_area_fraction, 0.3);
  EXPECT_DOUBLE_EQ(p.max_area_factor, 3);
  ASSERT_TRUE(p.roi);
  EXPECT_EQ(*p.roi, cv::Rect(150, 300, 40, 41));
  EXPECT_EQ(p.window_px, 48);
  EXPECT_EQ(p.widen_steps, 3);
  EXPECT_EQ(p.acquire_downsample, 2);
  std::string problem;
  EXPECT_TRUE(p.Check(&problem)) << problem;
}

TEST_F(ColourConfig, AutoColourAndDefaults) {
  const ColourParams p = ReadFile(WriteTemp("auto.yaml", "auto_colour: [40, 40, 220]\n"));
  ASSERT_TRUE(p.auto_bgr);
  EXPECT_EQ(*p.auto_bgr, cv::Vec3b(40, 40, 220));
  const ColourParams d;
  EXPECT_EQ(p.window_px, d.window_px);
  EXPECT_EQ(p.filter, d.filter);
  EXPECT_FALSE(p.roi);
}

TEST_F(ColourConfig, HueOutsideRangeNamesFileLineAndKey) {
  const std::string error = ErrorOf("name: red\nhsv: {h: [200, 10], s: [80, 255]}\n");
  EXPECT_NE(error.find("bad_colour.yaml:2:"), std::string::npos) << error;
  EXPECT_NE(error.find("markers[0].hsv.h"), std::string::npos) << error;
  EXPECT_NE(error.find("200"), std::string::npos) << error;
}

TEST_F(ColourConfig, BadValuesAreErrorsNamingTheKey) {
  struct Case {
    const char* yaml;
    const char* key;
  };
  const Case cases[] = {
      {"hsv: {s: [200, 100]}\n", "hsv.s"},
      {"hsv: {hue: [0, 10]}\n", "hsv.hue"},  // Unknown key.
      {"filter: {type: gaussian, ksize: 4}\n", "filter.ksize"},
      {"filter: {type: bilateral}\n", "filter.type"},
      {"morphology: {size: 2}\n", "morphology.size"},
      {"morphology: {shape: star}\n", "morphology.shape"},
      {"blob: {min_circularity: 1.5}\n", "blob.min_circularity"},
      {"blob: {min_area: 50, max_area: 10}\n", "blob.max_area"},
      {"roi: [1, 2, 3]\n", "roi"},
      {"roi: [1, 2, 0, 5]\n", "roi"},
      {"window: 3\n", "window"},
      {"acquire_downsample: 3\n", "acquire_downsample"},
      {"auto_colour: [1, 2, 300]\n", "auto_colour"},
      {"hsv: {h: [0, 10]}\nauto_colour: [1, 2, 3]\n", "auto_colour"},
      {"window: big\n", "window"},
  };
  for (const Case& c : cases) {
    const std::string error = ErrorOf(c.yaml);
    EXPECT_NE(error.find(std::string("markers[0].") + c.key), std::string::npos)
        << c.yaml << " -> '" << error << "'";
  }
}

TEST_F(ColourConfig, WrittenParamsReadBackEqual) {
  ColourParams p;
  p.h = {170, 10};
  p.s = {90, 250};
  p.v = {30, 255};
  p.filter = ColourParams::Filter::kGaussian;
  p.filter_ksize = 7;
  p.morph_size = 5;
  p.morph_shape = ColourParams::Shape::kRect;
  p.min_area_px = 15.5;
  p.min_circularity = 0.65;
  p.min_area_fraction = 0.2;
  p.max_area_factor = 0;
  p.roi = cv::Rect(1, 2, 30, 40);
  p.window_px = 0;
  p.widen_steps = 1;
  p.acquire_downsample = 4;
  YAML::Emitter out;
  out << YAML::BeginMap;
  WriteColourParams(p, out);
  out << YAML::EndMap;
  const std::string path = WriteTemp("roundtrip.yaml", out.c_str());
  const ColourParams q = ReadFile(path);
  EXPECT_EQ(q.h.lo, p.h.lo);
  EXPECT_EQ(q.h.hi, p.h.hi);
  EXPECT_EQ(q.s.lo, p.s.lo);
  EXPECT_EQ(q.s.hi, p.s.hi);
  EXPECT_EQ(q.v.lo, p.v.lo);
  EXPECT_EQ(q.filter, p.filter);
  EXPECT_EQ(q.filter_ksize, p.filter_ksize);
  EXPECT_EQ(q.morph_size, p.morph_size);
  EXPECT_EQ(q.morph_shape, p.morph_shape);
  EXPECT_EQ(q.min_area_px, p.min_area_px);
  EXPECT_EQ(q.max_area_px, p.max_area_px);
  EXPECT_EQ(q.min_circularity, p.min_circularity);
  EXPECT_EQ(q.min_area_fraction, p.min_area_fraction);
  EXPECT_EQ(q.max_area_factor, p.max_area_factor);
  EXPECT_EQ(q.roi, p.roi);
  EXPECT_EQ(q.window_px, p.window_px);
  EXPECT_EQ(q.widen_steps, p.widen_steps);
  EXPECT_EQ(q.acquire_downsample, p.acquire_downsample);

  // Defaults write nothing and read back as defaults; auto_colour round-trips too.
  ColourParams a;
  a.auto_bgr = cv::Vec3b(1, 2, 3);
  YAML::Emitter out2;
  out2 << YAML::BeginMap;
  WriteColourParams(a, out2);
  out2 << YAML::EndMap;
  const ColourParams b = ReadFile(WriteTemp("roundtrip2.yaml", out2.c_str()));
  ASSERT_TRUE(b.auto_bgr);
  EXPECT_EQ(*b.auto_bgr, *a.auto_bgr);
  EXPECT_EQ(b.window_px, a.window_px);
}

}  // namespace
}  // namespace softsight
