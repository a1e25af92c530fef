#include "softsight/core/format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace softsight {

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

}  // namespace softsight
