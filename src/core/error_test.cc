#include "softsight/core/error.h"

#include <gtest/gtest.h>

namespace softsight {
namespace {

TEST(EscapeForMessage, KeepsPrintableTextAndUtf8AndEscapesTheRest) {
  EXPECT_EQ(EscapeForMessage("markers.yaml:3: hue 200"), "markers.yaml:3: hue 200");
  EXPECT_EQ(EscapeForMessage("gr\xc3\xbcn \xe2\x86\x92 ok"), "gr\xc3\xbcn \xe2\x86\x92 ok");
  EXPECT_EQ(EscapeForMessage(std::string("a\nb\rc\x1b[2J\x7f\0d", 12)),
            "a\\nb\\x0dc\\x1b[2J\\x7f\\x00d");
  // Invalid UTF-8: a lone continuation byte, a truncated sequence, an overlong encoding.
  EXPECT_EQ(EscapeForMessage("\x80 \xc3 \xc0\xaf \xed\xa0\x80"),
            "\\x80 \\xc3 \\xc0\\xaf \\xed\\xa0\\x80");
  EXPECT_EQ(EscapeForMessage(std::string(1000, 'x'), 10), "xxxxxxxxxx...");
}

}  // namespace

// Every InputError is one line, whoever threw it: a config value "a\nb" reaches a library caller
// as the text a\nb, not as two lines (the config fuzz target traps on a raw newline).
TEST(InputError, IsOneLineWhateverItWasGiven) {
  EXPECT_STREQ(InputError("m.yaml:3: method: 'a\nb' is not one of: colour").what(),
               "m.yaml:3: method: 'a\\nb' is not one of: colour");
  EXPECT_STREQ(InputError(std::string("x\x01\ry")).what(), "x\\x01\\x0dy");
  // Already escaped text is left as it is.
  EXPECT_STREQ(InputError("a\\nb").what(), "a\\nb");
  EXPECT_STREQ(InputError("45 kPa, \xc2\xb0").what(), "45 kPa, \xc2\xb0");
}

}  // namespace softsight
