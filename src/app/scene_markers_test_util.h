// The marker config a person would write for the renderer's default scene (red, blue and green
// discs, base to tip), as the YAML the commands read; shared by the app's tests (test code only).
#pragma once

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

}  // namespace softsight::testing
