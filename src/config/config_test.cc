#include "softsight/config/config.h"

#include <array>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "config/config_test_util.h"
#include "core/test_util.h"
#include "softsight/core/error.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

const char* kValid = R"(markers:
  - name: red
    hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}
    roi: [150, 300, 40, 40]
  - name: blue
    hsv: {h: [100, 130], s: [80, 255], v: [40, 255]}
  - name: green
    hsv: {h: [45, 85], s: [80, 255], v: [40, 255]}
triple: [red, blue, green]
scale_mm_per_px: 0.2
)";

TEST(Config, LoadsTheDocumentedExample) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), kValid);
  const TrackingConfig config = LoadTrackingConfig(dir.file("markers.yaml"));
  ASSERT_EQ(config.markers.size(), 3u);
  EXPECT_EQ(config.markers[0].name, "red");
  EXPECT_EQ(TrackerMethodName(config.markers[0].params), "colour");
  EXPECT_EQ(config.markers[0].params.get<ColourParams>().h.lo, 170);
  EXPECT_EQ(config.markers[0].params.get<ColourParams>().h.hi, 10);
  ASSERT_TRUE(config.markers[0].params.get<ColourParams>().roi.has_value());
  EXPECT_EQ(*config.markers[0].params.get<ColourParams>().roi, cv::Rect(150, 300, 40, 40));
  EXPECT_FALSE(config.markers[1].params.get<ColourParams>().roi.has_value());
  EXPECT_EQ(config.measure.base, "red");
  EXPECT_EQ(config.measure.middle, "blue");
  EXPECT_EQ(config.measure.tip, "green");
  ASSERT_TRUE(config.measure.metric.scale_mm_per_px.has_value());
  EXPECT_DOUBLE_EQ(*config.measure.metric.scale_mm_per_px, 0.2);
}

TEST(Config, MethodOverrideAppliesToEveryMarkerAndUnknownMethodIsRejected) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), kValid);
  const TrackingConfig config = LoadTrackingConfig(dir.file("markers.yaml"), "zncc");
  for (const MarkerSpec& spec : config.markers) EXPECT_EQ(TrackerMethodName(spec.params), "zncc");
  EXPECT_THROW(LoadTrackingConfig(dir.file("markers.yaml"), "magic"), InputError);
}

TEST(Config, SavedConfigLoadsBackToTheSameValues) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), kValid);
  const TrackingConfig original = LoadTrackingConfig(dir.file("markers.yaml"));
  SaveTrackingConfig(original, dir.file("saved.yaml"));
  const TrackingConfig again = LoadTrackingConfig(dir.file("saved.yaml"));
  ASSERT_EQ(again.markers.size(), original.markers.size());
  for (size_t i = 0; i < again.markers.size(); ++i) {
    EXPECT_EQ(again.markers[i].name, original.markers[i].name);
    EXPECT_EQ(TrackerMethodName(again.markers[i].params),
              TrackerMethodName(original.markers[i].params));
    const ColourParams& a = again.markers[i].params.get<ColourParams>();
    const ColourParams& b = original.markers[i].params.get<ColourParams>();
    EXPECT_EQ(a.h.lo, b.h.lo);
    EXPECT_EQ(a.h.hi, b.h.hi);
    EXPECT_EQ(a.s.lo, b.s.lo);
    EXPECT_EQ(a.roi, b.roi);
  }
  EXPECT_EQ(again.measure.middle, "blue");
  EXPECT_EQ(again.measure.metric.scale_mm_per_px, original.measure.metric.scale_mm_per_px);
}

// A template marker's colour keys are its colour method's parameters: kept, saved, read back.
TEST(Config, ATemplateMarkersColourKeysAreKeptForTheColourMethod) {
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), R"(markers:
  - name: red
    method: zncc
    hsv: {h: [160, 5], s: [90, 255], v: [50, 255]}
    template: {rect: [10, 20, 16, 16]}
  - name: blue
    hsv: {h: [100, 130], s: [80, 255], v: [40, 255]}
)");
  const TrackingConfig original = LoadTrackingConfig(dir.file("markers.yaml"));
  ASSERT_EQ(original.params_aside.size(), 1u) << "a colour marker has none";
  ASSERT_EQ(original.params_aside.at("red").size(), 1u) << "its colour keys, no other kind's";
  const ColourParams& b = original.params_aside.at("red")[0].get<ColourParams>();
  EXPECT_EQ(b.h.lo, 160);
  EXPECT_EQ(b.v.lo, 50);
  SaveTrackingConfig(original, dir.file("saved.yaml"));
  const TrackingConfig again = LoadTrackingConfig(dir.file("saved.yaml"));
  EXPECT_EQ(TrackerMethodName(again.markers[0].params), "zncc");
  ASSERT_EQ(again.params_aside.count("red"), 1u);
  ASSERT_EQ(again.params_aside.at("red").size(), 1u);
  const ColourParams& a = again.params_aside.at("red")[0].get<ColourParams>();
  EXPECT_EQ((std::array<int, 6>{a.h.lo, a.h.hi, a.s.lo, a.s.hi, a.v.lo, a.v.hi}),
            (std::array<int, 6>{b.h.lo, b.h.hi, b.s.lo, b.s.hi, b.v.lo, b.v.hi}));
  // --method colour uses them.
  const TrackingConfig colour = LoadTrackingConfig(dir.file("saved.yaml"), "colour");
  EXPECT_EQ(colour.markers[0].params.get<ColourParams>().h.lo, 160);
}

TEST(Config, UnknownKeyIsNamedWithFileAndLine) {
  const std::string error = testing::ConfigErrorOf(std::string(kValid) + "scale_mm_per_pix: 0.3\n");
  EXPECT_THAT(error, HasSubstr("markers.yaml:11:"));
  EXPECT_THAT(error, HasSubstr("scale_mm_per_pix"));
  EXPECT_THAT(error, HasSubstr("unknown key"));
}

TEST(Config, UnknownKeyInsideAMarkerIsNamedWithItsPath) {
  const std::string error = testing::ConfigErrorOf(R"(markers:
  - name: red
    colour_of_marker: red
)");
  EXPECT_THAT(error, HasSubstr("markers[0].colour_of_marker"));
  EXPECT_THAT(error, HasSubstr(":3:"));
}

TEST(Config, WrongTypeIsNamed) {
  std::string text = kValid;
  text.replace(text.find("0.2"), 3, "lots");
  const std::string error = testing::ConfigErrorOf(text);
  EXPECT_THAT(error, HasSubstr("scale_mm_per_px"));
  EXPECT_THAT(error, HasSubstr("'lots'"));
}

// A quoted number is a string in YAML: the writer typed it as text (a Python str, a tool that
// quotes everything), and reading it as a number would hide that.
TEST(Config, AQuotedNumberOrBooleanIsRefusedAsAString) {
  std::string text = kValid;
  text.replace(text.find("0.2"), 3, "\"0.2\"");
  const std::string error = testing::ConfigErrorOf(text);
  EXPECT_THAT(error, HasSubstr("scale_mm_per_px: expected a number, got the string '0.2' (quoted)"));
  EXPECT_EQ(testing::ConfigErrorOf(kValid), "");  // The same value unquoted loads.
  std::string flag = kValid;  // A quoted true is text too.
  flag.replace(flag.find("    roi:"), 0, "    template: {round: 'true'}\n");
  EXPECT_THAT(testing::ConfigErrorOf(flag),
              HasSubstr("expected true or false, got the string 'true' (quoted)"));
}

TEST(Config, HueOutsideRangeIsNamed) {
  std::string text = kValid;
  text.replace(text.find("[100, 130]"), 10, "[100, 200]");
  const std::string error = testing::ConfigErrorOf(text);
  EXPECT_THAT(error, HasSubstr("markers[1]"));
  EXPECT_THAT(error, HasSubstr("200"));
}

TEST(Config, TripleNamingAnUnknownMarkerIsRejected) {
  std::string text = kValid;
  text.replace(text.find("[red, blue, green]"), 18, "[red, blue, yellow]");
  const std::string error = testing::ConfigErrorOf(text);
  EXPECT_THAT(error, HasSubstr("triple"));
  EXPECT_THAT(error, HasSubstr("yellow"));
}

TEST(Config, StructuralMistakesAreRejected) {
  EXPECT_THAT(testing::ConfigErrorOf(""), HasSubstr("empty"));
  EXPECT_THAT(testing::ConfigErrorOf("markers: []\n"), HasSubstr("markers"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: a\n  - name: a\n"), HasSubstr("used twice"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - hsv: {h: [1, 2]}\n"), HasSubstr("name"));
  EXPECT_THAT(testing::ConfigErrorOf("markers:\n  - name: a b\n"), HasSubstr("letters"));
  std::string same_twice = kValid;
  same_twice.replace(same_twice.find("[red, blue, green]"), 18, "[red, red, green]");
  EXPECT_THAT(testing::ConfigErrorOf(same_twice), HasSubstr("different"));
  EXPECT_THAT(testing::ConfigErrorOf(std::string(kValid) + "triple: [green, blue, red]\n"),
              HasSubstr("given twice"));
}

TEST(Config, InvalidYamlReportsTheLine) {
  const std::string error = testing::ConfigErrorOf("markers:\n  - name: red\n    hsv: {h: [1, 2\n");
  EXPECT_THAT(error, HasSubstr("markers.yaml:"));
  EXPECT_THAT(error, HasSubstr("invalid YAML"));
}

// The shipped examples are documentation: they must stay loadable.
TEST(Config, ShippedMarkerExamplesLoad) {
  const std::string dir = testing::SourceDir() + "/examples/";
  const TrackingConfig config = LoadTrackingConfig(dir + "markers.yaml");
  EXPECT_EQ(config.markers.size(), 3u);
  EXPECT_EQ(config.measure.middle, "blue");
  EXPECT_TRUE(config.measure.metric.scale_mm_per_px.has_value());
  const TrackingConfig templates = LoadTrackingConfig(dir + "markers_template.yaml");
  ASSERT_EQ(templates.markers.size(), 5u);
  EXPECT_EQ(templates.markers[0].params.get<TemplateParams>().rect, cv::Rect(388, 367, 25, 25));
  EXPECT_EQ(TrackerMethodName(templates.markers[4].params), "zncc");
}

TEST(Config, ShippedRigExampleLoadsWithItsControlSection) {
  const TrackingConfig config = LoadTrackingConfig(testing::SourceDir() + "/examples/rig.yaml");
  EXPECT_TRUE(config.control.has_value());
  EXPECT_FALSE(config.markers.empty());
}

TEST(Config, ControlSectionIsCheckedToo) {
  const std::string error = testing::ConfigErrorOf(std::string(kValid) + "control:\n  gainz: 3\n");
  EXPECT_THAT(error, HasSubstr("control.gainz"));
}

TEST(Config, MissingFileIsNamed) {
  try {
    LoadTrackingConfig("/no/such/markers.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/no/such/markers.yaml"));
  }
}

TEST(Config, NonScalarKeyIsOneErrorNamingFileAndLine) {
  // A complex key (`? [a, b]`) at the top level and inside a marker: yaml-cpp would throw
  // TypedBadConversion when the key is read as a name.
  std::string message = testing::ConfigErrorOf(std::string(kValid) + "? [a, b]\n: 1\n");
  EXPECT_THAT(message, HasSubstr("markers.yaml:11:"));
  EXPECT_THAT(message, HasSubstr("a key must be a plain name"));
  message = testing::ConfigErrorOf(
      "markers:\n  - name: red\n    ? {x: 1}\n    : 2\n    hsv: {h: [0, 10]}\n");
  EXPECT_THAT(message, HasSubstr("markers.yaml:3:"));
  EXPECT_THAT(message, HasSubstr("markers[0]"));
}

TEST(Config, DeeplyNestedYamlSaysSo) {
  const std::string message = testing::ConfigErrorOf(std::string(5000, '['));
  EXPECT_THAT(message, HasSubstr("markers.yaml"));
  EXPECT_THAT(message, HasSubstr("nested too deeply"));
}

TEST(Config, RandomBytesGiveOneEscapedLine) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 50; ++trial) {
    std::string bytes(300, '\0');
    for (char& c : bytes) c = static_cast<char>(random() & 0xFF);
    const std::string message = testing::ConfigErrorOf(bytes);
    ASSERT_FALSE(message.empty()) << "random bytes were accepted as a config";
    EXPECT_THAT(message, HasSubstr("markers.yaml"));
    for (char c : message) {
      ASSERT_FALSE(static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
          << "raw control character in: " << EscapeForMessage(message);
    }
  }
}

TEST(Config, DeviceInsteadOfAFileIsRefusedWithoutReadingIt) {
  try {
    LoadTrackingConfig("/dev/zero");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/dev/zero: not a regular file"));
  }
  TempDir dir;
  testing::WriteTextFile(dir.file("markers.yaml"), std::string(kValid) + "camera: /dev/zero\n");
  try {
    LoadTrackingConfig(dir.file("markers.yaml"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("not a regular file"));
  }
}

TEST(Config, UnknownKeySpanningLinesIsQuotedOnOneLine) {
  // Found by the config fuzzer: a quoted key running over several lines came back raw.
  const std::string message =
      testing::ConfigErrorOf("markers:\n  - name: red\n    'hsv: {h: [0, 10]}\n  - x\n\nkey': 1\n");
  ASSERT_FALSE(message.empty());
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

}  // namespace
}  // namespace softsight
