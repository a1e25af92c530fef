#include "softsight/core/format.h"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace softsight {
namespace {

TEST(Format, ShortNumberIsPrintfGWithTheGivenDigits) {
  EXPECT_EQ(ShortNumber(45.0), "45");
  EXPECT_EQ(ShortNumber(0.25), "0.25");
  EXPECT_EQ(ShortNumber(1e18), "1e+18");
  EXPECT_EQ(ShortNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(ShortNumber(36.4567, 3), "36.5");
  EXPECT_EQ(ShortNumber(2.0 / 3.0), "0.666667");
}

TEST(Format, FixedNumberKeepsItsDecimalsUpToAPointWhereFixedIsNoise) {
  EXPECT_EQ(FixedNumber(130.26, 1), "130.3");
  EXPECT_EQ(FixedNumber(2.0, 3), "2.000");
  EXPECT_EQ(FixedNumber(-0.004, 2), "-0.00");
  EXPECT_EQ(FixedNumber(1e20, 2), "1e+20");
  EXPECT_EQ(FixedNumber(std::nan(""), 2), "nan");
}

TEST(Format, RoundTripNumberReadsBackTheIdenticalDouble) {
  EXPECT_EQ(RoundTripNumber(0.1), "0.1");
  EXPECT_EQ(RoundTripNumber(1e-05), "1e-05");
  EXPECT_EQ(RoundTripNumber(12.0), "12");
  for (const double value : {0.1 + 0.2, 1.0 / 3.0, 6.02214076e23, -2.5e-300, 123456.789}) {
    EXPECT_EQ(std::stod(RoundTripNumber(value)), value) << RoundTripNumber(value);
  }
}

// Messages that name a Python type, a dtype or a board's size: the "a ellipsis".
TEST(Format, WithArticleFollowsHowTheWordIsSaid) {
  EXPECT_EQ(WithArticle("ellipsis"), "an ellipsis");
  EXPECT_EQ(WithArticle("int"), "an int");
  EXPECT_EQ(WithArticle("object"), "an object");
  EXPECT_EQ(WithArticle("list"), "a list");
  EXPECT_EQ(WithArticle("NoneType"), "a NoneType");
  EXPECT_EQ(WithArticle("int16 array"), "an int16 array");
  EXPECT_EQ(WithArticle("float32 array"), "a float32 array");
  EXPECT_EQ(WithArticle("uint16 array"), "a uint16 array");  // "you-int"
  EXPECT_EQ(WithArticle("8x6 board"), "an 8x6 board");
  EXPECT_EQ(WithArticle("9x6 board"), "a 9x6 board");
  EXPECT_EQ(WithArticle("11x8 board"), "an 11x8 board");   // eleven
  EXPECT_EQ(WithArticle("18x12 board"), "an 18x12 board");  // eighteen
  EXPECT_EQ(WithArticle("180x3 matrix"), "a 180x3 matrix");  // one hundred and eighty
  EXPECT_EQ(WithArticle("3x3 matrix"), "a 3x3 matrix");
  EXPECT_EQ(WithArticle("SVG file"), "an SVG file");        // ess-vee-gee
  EXPECT_EQ(WithArticle("PNG file"), "a PNG file");
  EXPECT_EQ(WithArticle("hour"), "an hour");
  EXPECT_EQ(WithArticle("hash"), "a hash");
  EXPECT_EQ(WithArticle("config_digest"), "a config_digest");
}

}  // namespace
}  // namespace softsight
