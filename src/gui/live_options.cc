#include "gui/live_options.h"

#include <cmath>

namespace softsight {

bool LiveOptions::Check(std::string* error) const {
  if (select_box_px < 4 || select_box_px > 1000) {
    *error = "select_box_px must be in 4..1000, got " + std::to_string(select_box_px);
    return false;
  }
  if (click_slop_px < 0 || click_slop_px > 100) {
    *error = "click_slop_px must be in 0..100, got " + std::to_string(click_slop_px);
    return false;
  }
  if (record_fps && !(*record_fps > 0 && *record_fps <= 100000)) {
    *error = "record_fps must be in (0, 100000], got " + std::to_string(*record_fps);
    return false;
  }
  if (scale_distance_mm && !(std::isfinite(*scale_distance_mm) && *scale_distance_mm > 0 &&
                            *scale_distance_mm <= 1e6)) {
    *error = "scale_distance_mm must be in (0, 1e6] mm, got " + std::to_string(*scale_distance_mm);
    return false;
  }
  if (record_prefix.empty()) {
    *error = "record_prefix must not be empty";
    return false;
  }
  return chart.Check(error) && picker.Check(error) && overlay.Check(error);
}

}  // namespace softsight
