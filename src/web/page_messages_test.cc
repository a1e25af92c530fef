#include "web/page_messages.h"

#include <gtest/gtest.h>

namespace softsight {
namespace {

PageLimits FileLimits() {
  PageLimits limits;
  limits.frame_size = cv::Size(640, 480);
  limits.length = 300;
  limits.seekable = true;
  limits.markers = 3;
  return limits;
}

// The command, or a test failure naming the error.
PageCommand Parse(const std::string& text, const PageLimits& limits = FileLimits()) {
  std::string error;
  const std::optional<PageCommand> command = ParsePageCommand(text, limits, &error);
  EXPECT_TRUE(command.has_value()) << text << ": " << error;
  return command.value_or(PageCommand{});
}

// The error for a refused message (empty, and a test failure, when it was taken).
std::string Refusal(const std::string& text, const PageLimits& limits = FileLimits()) {
  std::string error;
  const std::optional<PageCommand> command = ParsePageCommand(text, limits, &error);
  EXPECT_FALSE(command.has_value()) << text << " was taken";
  EXPECT_FALSE(error.empty()) << text;
  return error;
}

TEST(PageMessagesTest, EachTypeIsReadWithItsFields) {
  using Kind = PageCommand::Kind;
  EXPECT_EQ(Parse(R"({"type":"play"})").kind, Kind::kPlay);
  EXPECT_EQ(Parse(R"({"type":"pause"})").kind, Kind::kPause);
  EXPECT_EQ(Parse(R"({"type":"step","delta":-1})").delta, -1);
  EXPECT_EQ(Parse(R"({"type":"seek","position":299})").position, 299);
  EXPECT_DOUBLE_EQ(Parse(R"({"type":"speed","value":0.25})").speed, 0.25);
  const PageCommand pick = Parse(R"({"type":"pick","x":219.5,"y":321})");
  EXPECT_EQ(pick.kind, Kind::kPick);
  EXPECT_EQ(pick.point_px, cv::Point2d(219.5, 321));
  EXPECT_EQ(Parse(R"({"type":"select","x":10,"y":20,"w":30,"h":40})").box_px, cv::Rect(10, 20, 30, 40));
  EXPECT_EQ(Parse(R"({"type":"marker","index":2})").marker, 2);
  EXPECT_EQ(Parse(R"({"type":"save","name":"markers.web.yaml"})").name, "markers.web.yaml");
  EXPECT_DOUBLE_EQ(Parse(R"({"type":"ping","t":1700000000000.5})").page_time_ms, 1700000000000.5);
  EXPECT_EQ(Parse(R"({"type":"undo"})").kind, Kind::kUndo);
  EXPECT_EQ(Parse(R"({"type":"method"})").kind, Kind::kMethod);
  EXPECT_FALSE(ChangesTheRun(Kind::kPing));
  EXPECT_FALSE(ChangesTheRun(Kind::kTakeControl));
  EXPECT_TRUE(ChangesTheRun(Kind::kPick));
}

TEST(PageMessagesTest, MalformedMessagesAreRefused) {
  EXPECT_NE(Refusal("not json").find("not a JSON object"), std::string::npos);
  Refusal("[1, 2]");
  Refusal(R"({"type":)");
  EXPECT_NE(Refusal(R"({"kind":"play"})").find("no \"type\""), std::string::npos);
  EXPECT_NE(Refusal(R"({"type":"format_disk"})").find("unknown message type"), std::string::npos);
  EXPECT_NE(Refusal(R"({"type":"play","force":true})").find("unknown field \"force\""),
            std::string::npos);
  EXPECT_NE(Refusal(R"({"type":"seek"})").find("missing field \"position\""), std::string::npos);
  EXPECT_NE(Refusal(R"({"type":"seek","position":"12"})").find("must be a number"),
            std::string::npos);
  Refusal(R"({"type":5})");
}

TEST(PageMessagesTest, OversizedMessagesAreRefusedUnread) {
  const std::string big = R"({"type":"save","name":")" + std::string(5000, 'a') + R"(.yaml"})";
  EXPECT_NE(Refusal(big).find("bytes refused"), std::string::npos);
}

TEST(PageMessagesTest, NumbersOutsideTheRunAreRefused) {
  EXPECT_NE(Refusal(R"({"type":"seek","position":300})").find("outside [0, 299]"), std::string::npos);
  Refusal(R"({"type":"seek","position":-1})");
  Refusal(R"({"type":"seek","position":1.5})");
  Refusal(R"({"type":"step","delta":0})");
  Refusal(R"({"type":"step","delta":5})");
  Refusal(R"({"type":"speed","value":0})");
  Refusal(R"({"type":"speed","value":40})");
  Refusal(R"({"type":"pick","x":640,"y":10})");
  Refusal(R"({"type":"pick","x":-1,"y":10})");
  Refusal(R"({"type":"pick","x":1e400,"y":10})");  // Out of range for a double: not a number.
  Refusal(R"({"type":"select","x":630,"y":10,"w":20,"h":20})");  // Past the right edge.
  Refusal(R"({"type":"select","x":10,"y":10,"w":2,"h":20})");    // Too small to hold a marker.
  Refusal(R"({"type":"marker","index":3})");
  // Before the first frame nothing can be picked.
  PageLimits none = FileLimits();
  none.frame_size = {};
  EXPECT_NE(Refusal(R"({"type":"pick","x":1,"y":1})", none).find("no frame yet"), std::string::npos);
}

TEST(PageMessagesTest, ACameraCannotStepOrSeek) {
  PageLimits camera = FileLimits();
  camera.seekable = false;
  camera.length.reset();
  EXPECT_NE(Refusal(R"({"type":"seek","position":3})", camera).find("camera"), std::string::npos);
  Refusal(R"({"type":"step","delta":1})", camera);
  Parse(R"({"type":"pause"})", camera);
}

TEST(PageMessagesTest, ConfigNamesArePlainNamesInTheFolder) {
  std::string error;
  EXPECT_TRUE(ValidConfigName("markers.web.yaml", &error));
  EXPECT_TRUE(ValidConfigName("run_2-b.yaml", &error));
  for (const char* bad : {"../markers.yaml", "/etc/x.yaml", "a/b.yaml", ".hidden.yaml", "x.yml",
                          ".yaml", "", "a\\b.yaml", "a b.yaml", "..", "markers.yaml\n"}) {
    EXPECT_FALSE(ValidConfigName(bad, &error)) << bad;
  }
  EXPECT_FALSE(ValidConfigName(std::string(70, 'a') + ".yaml", &error));
  Refusal(R"({"type":"save","name":"../../etc/passwd.yaml"})");
  Refusal(R"({"type":"save","name":7})");
}

PageLimits RigLimits() {
  PageLimits limits = FileLimits();
  limits.seekable = false;
  limits.length.reset();
  limits.rig = true;
  return limits;
}

TEST(PageMessagesTest, TheRigsMessagesAreReadWithTheirFields) {
  using Kind = PageCommand::Kind;
  EXPECT_DOUBLE_EQ(Parse(R"({"type":"rig_run","target_deg":120.5})", RigLimits()).target_deg, 120.5);
  EXPECT_DOUBLE_EQ(Parse(R"({"type":"rig_run","target_deg":0})", RigLimits()).target_deg, 0.0);
  EXPECT_DOUBLE_EQ(Parse(R"({"type":"rig_run","target_deg":180})", RigLimits()).target_deg, 180.0);
  EXPECT_EQ(Parse(R"({"type":"rig_stop"})", RigLimits()).kind, Kind::kRigStop);
  const PageCommand profile =
      Parse(R"({"type":"rig_profile","text":"step 140\nhold 1\nramp 120 2\n"})", RigLimits());
  EXPECT_EQ(profile.kind, Kind::kRigProfile);
  EXPECT_DOUBLE_EQ(profile.profile.duration_s(), 3.0);
  EXPECT_DOUBLE_EQ(profile.profile.lowest_deg(), 120.0);
  // Only the controlling page runs the rig; any page may STOP it.
  EXPECT_TRUE(ChangesTheRun(Kind::kRigRun));
  EXPECT_TRUE(ChangesTheRun(Kind::kRigProfile));
  EXPECT_FALSE(ChangesTheRun(Kind::kRigStop));
}

TEST(PageMessagesTest, HostileRigMessagesAreRefusedNamingWhy) {
  const PageLimits rig = RigLimits();
  EXPECT_NE(Refusal(R"({"type":"rig_run","target_deg":181})", rig).find("outside [0, 180]"),
            std::string::npos);
  Refusal(R"({"type":"rig_run","target_deg":-1})", rig);
  Refusal(R"({"type":"rig_run","target_deg":"120"})", rig);
  Refusal(R"({"type":"rig_run","target_deg":null})", rig);
  Refusal(R"({"type":"rig_run","target_deg":1e400})", rig);
  Refusal(R"({"type":"rig_run"})", rig);
  Refusal(R"({"type":"rig_run","target_deg":120,"pressure_kpa":900})", rig);
  Refusal(R"({"type":"rig_stop","now":true})", rig);
  Refusal(R"({"type":"rig_profile","text":7})", rig);
  EXPECT_NE(Refusal(R"({"type":"rig_profile","text":"step 250\n"})", rig).find("0..180"),
            std::string::npos);
  Refusal(R"({"type":"rig_profile","text":"hold 1e9\n"})", rig);  // Longer than a week.
  Refusal(R"({"type":"rig_profile","text":"format c:\n"})", rig);
  Refusal(R"({"type":"rig_profile","text":"sine 120 10 1000 1\n"})", rig);  // Above 100 Hz.
  const std::string oversized =
      R"({"type":"rig_profile","text":")" + std::string(5000, '#') + R"("})";
  EXPECT_NE(Refusal(oversized, rig).find("bytes refused"), std::string::npos);
  // Without a rig there is nothing to run or stop.
  for (const char* text : {R"({"type":"rig_run","target_deg":120})", R"({"type":"rig_stop"})",
                           R"({"type":"rig_profile","text":"step 120\n"})"}) {
    EXPECT_NE(Refusal(text).find("no rig"), std::string::npos) << text;
  }
}

TEST(PageMessagesTest, WithARigPauseIsRefusedTheLoopNeedsEveryFrame) {
  EXPECT_NE(Refusal(R"({"type":"pause"})", RigLimits()).find("STOP"), std::string::npos);
  PageLimits seekable_rig = RigLimits();  // Even were its frames a file's.
  seekable_rig.seekable = true;
  seekable_rig.length = 300;
  Refusal(R"({"type":"seek","position":3})", seekable_rig);
  Refusal(R"({"type":"step","delta":-1})", seekable_rig);
  Parse(R"({"type":"play"})", RigLimits());
}

TEST(PageMessagesTest, TuningMessagesAreCheckedLikeTheTrackbars) {
  using Kind = PageCommand::Kind;
  const PageCommand hsv = Parse(R"({"type":"hsv","index":1,"value":179})");
  EXPECT_EQ(hsv.kind, Kind::kHsv);
  EXPECT_EQ(hsv.hsv_index, 1);
  EXPECT_EQ(hsv.hsv_value, 179);
  EXPECT_EQ(Parse(R"({"type":"hsv","index":5,"value":255})").hsv_value, 255);
  EXPECT_NE(Refusal(R"({"type":"hsv","index":0,"value":180})").find("outside [0, 179]"),
            std::string::npos);  // Hue is 0..179.
  Refusal(R"({"type":"hsv","index":6,"value":0})");
  Refusal(R"({"type":"hsv","index":-1,"value":0})");
  Refusal(R"({"type":"hsv","index":2,"value":256})");
  Refusal(R"({"type":"hsv","index":2,"value":12.5})");
  Refusal(R"({"type":"hsv","index":"0","value":1})");
  Refusal(R"({"type":"hsv","index":0})");
  EXPECT_TRUE(Parse(R"({"type":"mask_view","on":true})").on);
  EXPECT_FALSE(Parse(R"({"type":"mask_view","on":false})").on);
  Refusal(R"({"type":"mask_view","on":1})");
  Refusal(R"({"type":"mask_view"})");
  EXPECT_TRUE(ChangesTheRun(Kind::kHsv));
  EXPECT_TRUE(ChangesTheRun(Kind::kMaskView));
}

TEST(PageMessagesTest, ConfigsAreLoadedOnlyByAPlainNameInTheFolder) {
  using Kind = PageCommand::Kind;
  EXPECT_EQ(Parse(R"({"type":"load","name":"markers.web.yaml"})").name, "markers.web.yaml");
  for (const char* bad : {R"({"type":"load","name":"../cfg.yaml"})", R"({"type":"load","name":"/etc/x.yaml"})",
                          R"({"type":"load","name":"a/b.yaml"})", R"({"type":"load","name":".x.yaml"})",
                          R"({"type":"load","name":"x.txt"})", R"({"type":"load","name":7})",
                          R"({"type":"load"})"}) {
    EXPECT_EQ(Refusal(bad).rfind("load", 0), 0u) << bad;
  }
  EXPECT_EQ(Parse(R"({"type":"list_configs"})").kind, Kind::kListConfigs);
  EXPECT_TRUE(ChangesTheRun(Kind::kLoad));
  EXPECT_FALSE(ChangesTheRun(Kind::kListConfigs));  // Reading the folder's names changes nothing.
}

TEST(PageMessagesTest, TheMaskViewsClickAndTheMmScaleAreReadAndChecked) {
  using Kind = PageCommand::Kind;
  const PageCommand grow = Parse(R"({"type":"range","x":12.5,"y":479,"grow":true})");
  EXPECT_EQ(grow.kind, Kind::kRange);
  EXPECT_EQ(grow.point_px, cv::Point2d(12.5, 479));
  EXPECT_TRUE(grow.grow);
  EXPECT_FALSE(Parse(R"({"type":"range","x":0,"y":0,"grow":false})").grow);
  EXPECT_NE(Refusal(R"({"type":"range","x":640,"y":0,"grow":true})").find("outside [0, 639]"),
            std::string::npos);
  EXPECT_NE(Refusal(R"({"type":"range","x":1,"y":1,"grow":1})").find("true or false"), std::string::npos);
  PageLimits before_first_frame = FileLimits();
  before_first_frame.frame_size = cv::Size();
  EXPECT_NE(Refusal(R"({"type":"range","x":1,"y":1,"grow":true})", before_first_frame).find("no frame"),
            std::string::npos);

  const PageCommand scale = Parse(R"({"type":"scale","ax":100,"ay":440,"bx":500.5,"by":440,"mm":100})");
  EXPECT_EQ(scale.kind, Kind::kScale);
  EXPECT_EQ(scale.point_px, cv::Point2d(100, 440));
  EXPECT_EQ(scale.point_b_px, cv::Point2d(500.5, 440));
  EXPECT_DOUBLE_EQ(scale.distance_mm, 100);
  EXPECT_TRUE(ChangesTheRun(Kind::kScale));
  EXPECT_TRUE(ChangesTheRun(Kind::kRange));
  EXPECT_NE(Refusal(R"({"type":"scale","ax":100,"ay":440,"bx":500,"by":440,"mm":0})").find("above 0"),
            std::string::npos);
  Refusal(R"({"type":"scale","ax":100,"ay":440,"bx":500,"by":440,"mm":-5})");
  Refusal(R"({"type":"scale","ax":100,"ay":440,"bx":500,"by":440,"mm":2e6})");
  Refusal(R"({"type":"scale","ax":100,"ay":440,"bx":500,"by":480,"mm":10})");
  EXPECT_NE(Refusal(R"({"type":"scale","ax":100,"ay":440,"bx":500,"by":440})").find("missing field \"mm\""),
            std::string::npos);
  Refusal(R"({"type":"scale","ax":100,"ay":440,"bx":500,"by":440,"mm":"100"})");
}

}  // namespace
}  // namespace softsight
