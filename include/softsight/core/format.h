// Numbers as text, one way each: in messages, in measured figures, and in files that must read
// back the identical value. Every module formats through these (no local snprintf helpers).
// And a name with its article, for messages that put "a" before a word they did not choose.
#pragma once

#include <string>

namespace softsight {

// A number as messages show it: the shortest of fixed and exponent form with `significant`
// digits (1..17; default 6: "45", "0.25", "1e+18", "inf").
std::string ShortNumber(double value, int significant = 6);
// A measured figure with `decimals` digits after the point ("130.3"; "nan", "inf" as they are;
// beyond 1e15 the short form, where a fixed one is long noise).
std::string FixedNumber(double value, int decimals);
// The shortest text that reads back to the identical double ("0.1", "1e-05"; "nan", "inf"): for
// configs, command lines and anything parsed again.
std::string RoundTripNumber(double value);

// `noun` after "a" or "an", as it is spoken: "an ellipsis", "a list", "an int16 array", "a uint8
// array", "an 8x6 board", "an 11x8 board", "an SVG file", "an hour". For messages that name
// something the program did not choose the word for (a Python type, a dtype, a board's size).
std::string WithArticle(const std::string& noun);

}  // namespace softsight
