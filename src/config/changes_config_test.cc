// The `changes:` list a live recording's config keeps (ConfigChange): written and read back
// exactly, and refused with one line naming the entry when it is malformed.
#include <gtest/gtest.h>

#include "config/config_test_util.h"
#include "core/test_util.h"
#include "softsight/config/config.h"
#include "softsight/core/error.h"

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
  sad.method = "sad";
  sad.colour.h = {90, 140};
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
  EXPECT_EQ(back.changes[0].spec.method, "sad");
  EXPECT_EQ(back.changes[0].spec.colour.h.lo, 90);
  EXPECT_EQ(back.changes[0].spec.colour.h.hi, 140);
  EXPECT_EQ(back.changes[1].rect, cv::Rect(10, 20, 23, 22));
  EXPECT_EQ(back.markers[1].method, "colour");  // The start is unchanged.
}

TEST(ConfigChanges, MalformedEntriesAreOneLineNamingTheEntry) {
  TempDir dir;
  const auto message = [&](const std::string& changes) {
    testing::WriteTextFile(dir.file("c.yaml"), std::string(kMarkers) + "changes:\n" + changes);
    try {
      LoadTrackingConfig(dir.file("c.yaml"));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("  - {after_frame: 5, retrack: red}\n  - {after_frame: 2, retrack: red}\n")
                .find("changes[1].after_frame: changes must be in frame order"),
            std::string::npos);
  EXPECT_NE(message("  - {after_frame: 5, retrack: yellow}\n")
                .find("changes[0].retrack: 'yellow' is not the name of a marker"),
            std::string::npos);
  EXPECT_NE(message("  - {after_frame: 5, retrack: red, reset_tip_reference: true}\n")
                .find("each change is one of"),
            std::string::npos);
  EXPECT_NE(message("  - {after_frame: 5, reselect: {marker: red, rect: [1, 2, 0, 4]}}\n")
                .find("changes[0].reselect.rect"),
            std::string::npos);
  EXPECT_NE(message("  - {retrack: red}\n").find("every change needs its frame"),
            std::string::npos);
  EXPECT_NE(message("  - {after_frame: 1, respec: {name: red, method: nope}}\n")
                .find("changes[0].respec.method"),
            std::string::npos)
      << message("  - {after_frame: 1, respec: {name: red, method: nope}}\n");
  EXPECT_NE(message("  - {after_frame: 1, retrack: red, typo: 1}\n").find("typo"),
            std::string::npos);
  EXPECT_NE(message("  5\n").find("changes: expected a list"), std::string::npos);
}

}  // namespace
}  // namespace softsight
