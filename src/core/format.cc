#include "softsight/core/format.h"

#include <algorithm>
#include <charconv>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string_view>

namespace softsight {
namespace {

bool StartsWith(std::string_view text, std::string_view prefix) {
  return text.substr(0, prefix.size()) == prefix;
}

// Whether `noun` is said starting with a vowel sound (then "an").
bool SaidWithAVowel(const std::string& noun) {
  if (noun.empty()) return false;
  const auto is_digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  if (is_digit(noun[0])) {
    // Eight, eighty, eight hundred...; eleven and eighteen (and their thousands, millions).
    const size_t digits = std::find_if_not(noun.begin(), noun.end(), is_digit) - noun.begin();
    if (noun[0] == '8') return true;
    return (StartsWith(noun, "11") || StartsWith(noun, "18")) && digits % 3 == 2;
  }
  // An initialism is said letter by letter: "an SVG", "an HSV range", "a PNG".
  size_t capitals = 0;
  while (capitals < noun.size() && std::isupper(static_cast<unsigned char>(noun[capitals]))) {
    ++capitals;
  }
  if (capitals >= 2 && (capitals == noun.size() || !std::isalpha(static_cast<unsigned char>(
                                                       noun[capitals])))) {
    return std::string_view("AEFHILMNORSX").find(noun[0]) != std::string_view::npos;
  }
  std::string word;
  for (const char c : noun) word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // Written with a vowel, said with a consonant ("a uint8", "a unicode", "a one"), and the
  // other way round ("an hour").
  for (const char* prefix : {"uint", "uni", "use", "usu", "uti", "utf", "ure", "uri", "eu", "one",
                             "once"}) {
    if (StartsWith(word, prefix)) return false;
  }
  for (const char* prefix : {"hour", "honest", "honour", "honor", "heir"}) {
    if (StartsWith(word, prefix)) return true;
  }
  return std::string_view("aeiou").find(word[0]) != std::string_view::npos;
}

}  // namespace

std::string ShortNumber(double value, int significant) {
  char text[48];
  std::snprintf(text, sizeof(text), "%.*g", std::clamp(significant, 1, 17), value);
  return text;
}

std::string FixedNumber(double value, int decimals) {
  if (!(std::abs(value) < 1e15)) return ShortNumber(value);
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", std::clamp(decimals, 0, 9), value);
  return text;
}

std::string RoundTripNumber(double value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

std::string WithArticle(const std::string& noun) {
  return (SaidWithAVowel(noun) ? "an " : "a ") + noun;
}

}  // namespace softsight
