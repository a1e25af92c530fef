// Template-matching tracking (paper section 2.2): SAD, SSD and ZNCC, gray or colour.
#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "softsight/core/types.h"

namespace softsight {

enum class MatchMeasure { kSad, kSsd, kZncc };

struct TemplateParams {
  MatchMeasure measure = MatchMeasure::kZncc;
  bool colour = false;               // Match on BGR instead of gray (3x the work).
  // Where the template comes from: a rectangle on a reference frame, or an image file (loaded by
  // the caller into `image`). When `image` is empty the tracker takes it from init()'s hint.
  int template_frame = 0;
  std::optional<cv::Rect> rect;
  cv::Mat image;

  // Returns true when every field is usable; otherwise false with `error` naming the field.
  bool Check(std::string* error) const;
};

}  // namespace softsight
