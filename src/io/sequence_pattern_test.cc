#include "io/sequence_pattern.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "softsight/core/error.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;

TEST(ParseSequencePattern, AcceptsOnePlainOrZeroPaddedNumber) {
  SequencePattern p = ParseSequencePattern("frames/f%04d.png");
  EXPECT_EQ(p.prefix, "frames/f");
  EXPECT_EQ(p.suffix, ".png");
  EXPECT_EQ(p.width, 4);
  EXPECT_EQ(p.Format(7), "frames/f0007.png");
  EXPECT_EQ(p.Format(123456), "frames/f123456.png");
  p = ParseSequencePattern("%d.jpg");
  EXPECT_EQ(p.width, 0);
  EXPECT_EQ(p.Format(0), "0.jpg");
  EXPECT_EQ(p.Format(42), "42.jpg");
  // "%%" is a literal percent sign, as in printf.
  p = ParseSequencePattern("run_100%%_%03d.png");
  EXPECT_EQ(p.Format(5), "run_100%_005.png");
}

TEST(ParseSequencePattern, RejectsEveryOtherConversionWithOneLineNamingThePattern) {
  for (const char* bad : {"frames/%s.png", "%n.png", "%5d.png", "%x.png", "%04s.png", "%ld.png",
                          "%0d.png", "%00d.png", "%019d.png", "%d_%d.png", "plain.png", "%",
                          "f%", "f%0", "%*d.png", "%1$d.png", "dir%d/f.png", "%.3d.png"}) {
    try {
      ParseSequencePattern(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_THAT(message, HasSubstr(bad));
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

TEST(SequencePattern, MatchesOnlyTheSpellingFormatWrites) {
  const SequencePattern padded{"f", ".png", 3};
  EXPECT_EQ(padded.Match("f007.png"), 7);
  EXPECT_EQ(padded.Match("f1234.png"), 1234);
  EXPECT_EQ(padded.Match("f07.png"), std::nullopt);
  EXPECT_EQ(padded.Match("f0007.png"), std::nullopt);
  EXPECT_EQ(padded.Match("f00a.png"), std::nullopt);
  EXPECT_EQ(padded.Match("g007.png"), std::nullopt);
  EXPECT_EQ(padded.Match("f007.jpg"), std::nullopt);
  EXPECT_EQ(padded.Match("f.png"), std::nullopt);
  const SequencePattern plain{"", ".png", 0};
  EXPECT_EQ(plain.Match("0.png"), 0);
  EXPECT_EQ(plain.Match("19.png"), 19);
  EXPECT_EQ(plain.Match("019.png"), std::nullopt);
  EXPECT_EQ(plain.Match("1234567890123456789.png"), std::nullopt) << "over 18 digits";
  for (int64_t i : {int64_t{0}, int64_t{1}, int64_t{9}, int64_t{10}, int64_t{999}, int64_t{1000},
                    int64_t{123456789012345678}}) {
    EXPECT_EQ(padded.Match(padded.Format(i)), i);
    EXPECT_EQ(plain.Match(plain.Format(i)), i);
  }
}

}  // namespace
}  // namespace softsight
