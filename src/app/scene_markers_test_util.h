// The marker config a person would write for the renderer's default scene (red, blue and green
// discs, base to tip), as the YAML the commands read; shared by the app's tests (test code only).
#pragma once

#include <string>

namespace softsight::testing {

inline constexpr const char* kSceneMarkersYaml = R"(markers:
  - name: red
    hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}
  - name: blue
    hsv: {h: [100, 130], s: [80, 255], v: [40, 255]}
  - name: green
    hsv: {h: [45, 85], s: [80, 255], v: [40, 255]}
triple: [red, blue, green]
)";

// The same with a scale (0.2 mm per pixel), for the millimetre columns (arc length, distances).
inline const std::string kScaledSceneMarkersYaml =
    std::string(kSceneMarkersYaml) + "scale_mm_per_px: 0.2\n";

}  // namespace softsight::testing
