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

}  // namespace
}  // namespace softsight
