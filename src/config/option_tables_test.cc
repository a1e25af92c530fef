// Every option of every table: YAML round trip, the same message from the file and from Check(),
// sane int ranges, and the example configs mentioning every key (option_table_test_util.h).
#include <cstdio>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "control/control_options.h"
#include "config/option_yaml.h"
#include "io/camera_options.h"
#include "softsight/config/config.h"
#include "geometry/measure_options.h"
#include "config/config_sections.h"
#include "config/kind_config_test_util.h"
#include "config/config_test_util.h"
#include "config/option_table_test_util.h"
#include "track/track_options.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;

std::string Example(const std::string& name) {
  return testing::ReadTextFile(std::string(SOFTSIGHT_TEST_SOURCE_DIR) + "/examples/" + name);
}

TEST(OptionTables, ColourParams) {
  testing::OptionTableSuite<ColourParams>{
      ColourParamsOptions(), "markers[0]",
      [](YamlMap& m, ColourParams* p) { ReadColourParams(m, p); },
      [](const ColourParams& p, YAML::Emitter& out) { WriteColourParams(p, out); },
      [](const ColourParams& p, std::string* e) { return p.Check(e); }}
      .Run();
}

TEST(OptionTables, TemplateParamsAndTheirFile) {
  testing::OptionTableSuite<TemplateSection>{
      TemplateSectionOptions(), "markers[0]",
      [](YamlMap& m, TemplateSection* p) { ReadTemplateParams(m, p); },
      [](const TemplateSection& p, YAML::Emitter& out) { WriteTemplateParams(p, out); },
      [](const TemplateSection& p, std::string* e) {
        // With a file, the reader also wants rect to be the image's size, which it alone knows
        // (the suite's image is 8x8): not combined here (TemplateConfig.ImageWithRect... tests it).
        return p.params.Check(e) && (p.file.empty() || !p.params.rect);
      }}
      .Run();
}

TEST(OptionTables, ControlConfig) {
  testing::OptionTableSuite<ControlConfig>{
      ControlConfigTable(), "control",
      [](YamlMap& m, ControlConfig* c) { ReadControlConfig(m, c); },
      [](const ControlConfig& c, YAML::Emitter& out) { WriteControlConfig(c, out); },
      [](const ControlConfig& c, std::string* e) { return c.Check(e); }}
      .Run();
}

TEST(OptionTables, MeasureOptions) {
  testing::OptionTableSuite<MeasureOptions>{
      MeasureOptionsTable(), "",
      [](YamlMap& m, MeasureOptions* o) { ReadMeasureOptions(m, o); },
      [](const MeasureOptions& o, YAML::Emitter& out) { WriteMeasureOptions(o, out); },
      [](const MeasureOptions& o, std::string* e) { return CheckMeasureOptionsOfAFile(o, e); }}
      .Run();
}

TEST(OptionTables, CameraSettings) {
  testing::OptionTableSuite<CameraSettings>{
      CameraSettingsTable(), "capture",
      [](YamlMap& m, CameraSettings* c) {
        ReadOptions(m, CameraSettingsTable(), c);
        m.finish();
        std::string problem;
        if (!c->Check(&problem)) FailAtKey(m, problem);
      },
      [](const CameraSettings& c, YAML::Emitter& out) {
        WriteOptions(CameraSettingsTable(), c, out);
      },
      [](const CameraSettings& c, std::string* e) { return c.Check(e); }}
      .Run();
}

TEST(OptionTables, TheCaptureSectionRoundTripsThroughAConfigFile) {
  TrackingConfig config;
  MarkerSpec red;
  red.name = "red";
  config.markers = {red};
  CameraSettings capture;
  capture.device = 2;
  capture.width = 1280;
  capture.height = 720;
  capture.fps = 60;
  capture.pixel_format = CameraSettings::PixelFormat::kYuyv;
  capture.exposure = 156;
  capture.white_balance_k = 4600;
  config.capture = capture;
  const testing::TempDir dir;
  const std::string file = dir.file("capture_round_trip.yaml");
  SaveTrackingConfig(config, file);
  const TrackingConfig again = LoadTrackingConfig(file);
  ASSERT_TRUE(again.capture);
  EXPECT_EQ(*again.capture, capture);
}

TEST(OptionTables, TheExamplesMentionEveryKey) {
  EXPECT_EQ(testing::KeysMissingFrom(CameraSettingsTable(), Example("markers.yaml")),
            std::vector<std::string>{});
  EXPECT_EQ(testing::KeysMissingFrom(ColourParamsOptions(), Example("markers.yaml")),
            std::vector<std::string>{});
  EXPECT_EQ(testing::KeysMissingFrom(TemplateSectionOptions(), Example("markers_template.yaml")),
            std::vector<std::string>{});
  EXPECT_EQ(testing::KeysMissingFrom(MeasureOptionsTable(), Example("markers.yaml")),
            std::vector<std::string>{});
  EXPECT_EQ(testing::KeysMissingFrom(ControlConfigTable(), Example("rig.yaml")),
            std::vector<std::string>{});
}

TEST(OptionTables, ControlMessagesAreTheTablesToo) {
  // Issue 8: the reader said 0..100 and Check() said >= 0; now both say the table's range.
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: a\ncontrol:\n  controller:\n"
                                     "    kp_kpa_per_deg: 200\n"),
              HasSubstr("markers.yaml:5: control.controller.kp_kpa_per_deg: 200 must lie within "
                        "0..100"));
  ControlConfig c;
  c.controller.kp_kpa_per_deg = 200;
  std::string problem;
  EXPECT_FALSE(c.Check(&problem));
  EXPECT_EQ(problem, "controller.kp_kpa_per_deg: 200 must lie within 0..100");
}

TEST(OptionTables, MessageNamesFileLineAndFullKeyPath) {
  const std::string error = testing::ConfigErrorOf(
      "markers:\n  - name: red\n    blob:\n      min_area: 20\n      min_circularity: 1.5\n");
  EXPECT_THAT(error, HasSubstr("markers.yaml:5: markers[0].blob.min_circularity: 1.5 must lie "
                               "within 0..1"));
  ColourParams p;
  p.min_circularity = 1.5;
  std::string problem;
  EXPECT_FALSE(p.Check(&problem));
  EXPECT_EQ(problem, "blob.min_circularity: 1.5 must lie within 0..1");
}

TEST(OptionTables, CrossFieldRulesNameTheirKeyAndLine) {
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    blob: {min_area: 50,\n"
                                     "      max_area: 10}\n"),
              HasSubstr("markers.yaml:4: markers[0].blob.max_area: 10 must be 0 (no limit) or at "
                        "least blob.min_area (50)"));
}

TEST(OptionTables, UnknownAndDuplicateNestedKeysAreRejected) {
  EXPECT_THAT(testing::ConfigErrorOf(
                  "markers:\n  - name: red\n    template: {rect: [1, 2, 30, 30], colur: true}\n"),
              HasSubstr("markers[0].template.colur: unknown key"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    blob:\n      min_area: 3\n"
                                     "      min_area: 4\n"),
              HasSubstr("markers[0].blob.min_area: key given twice"));
}

TEST(OptionTables, ABadNameIsShownOnOneLine) {
  const std::string error = testing::ConfigErrorOf(
      "markers:\n  - name: red\n    filter: {type: \"gau\\x01ss\\nian\"}\n");
  EXPECT_THAT(error, HasSubstr("markers[0].filter.type: 'gau\\x01ss\\x0aian' is not one of: none, "
                               "gaussian, median"));
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

TEST(OptionTables, IntOverflowIsARangeError) {
  // Issue 10, item 6: this used to overflow a signed int inside the tracker.
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    template: {rect: [205, 186, 25, "
                                     "25], acquire_radius_px: 2147483647}\n"),
              HasSubstr("markers[0].template.acquire_radius_px: 2147483647 must lie within "
                        "0..16384"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: red\n    window: 99999999999999999999\n"),
              HasSubstr("markers[0].window: expected a whole number"));
}

TEST(OptionTables, GeneratedDocumentationIsAConfigThatReadsBackToTheDefaults) {
  testing::TempDir dir;
  const std::string file = dir.file("all_keys.yaml");
  const std::string doc = DocumentConfig();
  testing::WriteTextFile(file, doc);
  const TrackingConfig config = LoadTrackingConfig(file);
  ASSERT_EQ(config.markers.size(), 1u);
  const ColourParams colour_defaults;
  for (const auto& o : ColourParamsOptions()) {
    EXPECT_EQ(o.get(config.markers[0].params.get<ColourParams>()), o.get(colour_defaults))
        << o.key;
    EXPECT_THAT(doc, HasSubstr(o.key.substr(o.key.rfind('.') + 1) + ":")) << o.key;
  }
  // The marker is a colour marker; read as a template marker, its template keys are the defaults.
  const TrackingConfig as_template = LoadTrackingConfig(file, "zncc");
  const TemplateSection template_defaults;
  EXPECT_TRUE(as_template.template_files.empty());
  const TemplateSection read{as_template.markers[0].params.get<TemplateParams>(), ""};
  for (const auto& o : TemplateSectionOptions()) {
    EXPECT_EQ(o.get(read), o.get(template_defaults)) << o.key;
    EXPECT_THAT(doc, HasSubstr(o.key.substr(o.key.rfind('.') + 1) + ":")) << o.key;
  }
  ASSERT_TRUE(config.control);
  const ControlConfig control_defaults;
  for (const auto& o : ControlConfigTable()) {
    EXPECT_EQ(o.get(*config.control), o.get(control_defaults)) << o.key;
  }
  for (const auto& o : MeasureOptionsTable()) {
    EXPECT_THAT(doc, HasSubstr(o.key + ":")) << o.key;
  }
}

TEST(OptionTables, DescriptionListsEveryKeyWithItsDefault) {
  const std::string doc = DescribeOptions(ColourParamsOptions());
  EXPECT_THAT(doc, HasSubstr("blob:\n"));
  EXPECT_THAT(doc, HasSubstr("  min_circularity: 0.5"));
  EXPECT_THAT(doc, HasSubstr("0..1"));
  EXPECT_THAT(doc, HasSubstr("# roi:"));
  const std::string templ = DescribeOptions(TemplateParamsOptions());
  EXPECT_THAT(templ, HasSubstr("template:\n  frame: 0"));
}

}  // namespace
}  // namespace softsight
