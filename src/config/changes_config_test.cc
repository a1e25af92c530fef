// The `changes:` list a live recording's config keeps (ConfigChange): written and read back
// exactly, and refused with one line naming the entry when it is malformed.
#include <gtest/gtest.h>

#include "config/config_test_util.h"
#include "core/test_util.h"
#include "softsight/config/config.h"
#include "softsight/core/error.h"
#include "softsight/track/template_tracker.h"

namespace softsight {
namespace {

using testing::TempDir;

const char* kMarkers = R"(markers:
  - name: red
    hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}
  - name: blue
    hsv: {h: [100, 130], s: [80, 255], v: [40, 255]}
)";

TEST(ConfigChanges, EveryKindIsWrittenAndReadBackInOrder) {
  TempDir dir;
  testing::WriteTextFile(dir.file("m.yaml"), kMarkers);
  TrackingConfig config = LoadTrackingConfig(dir.file("m.yaml"));
  MarkerSpec sad = config.markers[1];
  TemplateParams templ;
  templ.rect = cv::Rect(40, 50, 23, 22);
  templ.min_zncc = 0.7;
  sad.params = ParamsForMethod("sad", {templ});
  config.changes = {ConfigChange::Respec(sad), ConfigChange::Reselect("blue", {10, 20, 23, 22}),
                    ConfigChange::Retrack("red"), ConfigChange::ResetTipReference()};
  config.changes[0].after_frame = 3;
  config.changes[1].after_frame = 3;
  config.changes[2].after_frame = 7;
  config.changes[3].after_frame = 12;
  SaveTrackingConfig(config, dir.file("saved.yaml"));
  const TrackingConfig back = LoadTrackingConfig(dir.file("saved.yaml"));
  ASSERT_EQ(back.changes.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(back.changes[i].kind, config.changes[i].kind) << i;
    EXPECT_EQ(back.changes[i].after_frame, config.changes[i].after_frame) << i;
    EXPECT_EQ(back.changes[i].marker, config.changes[i].marker) << i;
  }
  EXPECT_EQ(TrackerMethodName(back.changes[0].spec.params), "sad");
  const TemplateParams& back_templ = back.changes[0].spec.params.get<TemplateParams>();
  EXPECT_EQ(back_templ.rect, cv::Rect(40, 50, 23, 22));
  EXPECT_DOUBLE_EQ(back_templ.min_zncc, 0.7);
  EXPECT_EQ(back.changes[1].rect, cv::Rect(10, 20, 23, 22));
  EXPECT_EQ(TrackerMethodName(back.markers[1].params), "colour");  // The start is unchanged.
}

TEST(ConfigChanges, MalformedEntriesAreOneLineNamingTheEntry) {
  const std::pair<const char*, const char*> cases[] = {
      {"  - {after_frame: 5, retrack: red}\n  - {after_frame: 2, retrack: red}\n",
       "changes[1].after_frame: changes must be in frame order"},
      {"  - {after_frame: 5, retrack: yellow}\n",
       "changes[0].retrack: 'yellow' is not the name of a marker"},
      {"  - {after_frame: 5, retrack: red, reset_tip_reference: true}\n", "each change is one of"},
      {"  - {after_frame: 5, reselect: {marker: red, rect: [1, 2, 0, 4]}}\n",
       "changes[0].reselect.rect"},
      {"  - {retrack: red}\n", "every change needs its frame"},
      {"  - {after_frame: 1, respec: {name: red, method: nope}}\n", "changes[0].respec.method"},
      {"  - {after_frame: 1, retrack: red, typo: 1}\n", "typo"},
      {"  5\n", "changes: expected a list"},
  };
  for (const auto& [changes, expected] : cases) {
    const std::string message =
        testing::ConfigErrorOf(std::string(kMarkers) + "changes:\n" + changes);
    EXPECT_NE(message.find(expected), std::string::npos) << changes << " gave: " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
  }
}

}  // namespace
}  // namespace softsight
