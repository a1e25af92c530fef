// `softsight synth`: render a synthetic actuator scene to a video (or an image sequence) and write
// its exact ground truth to a CSV.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "softsight/sim/plate_scene.h"
#include "softsight/sim/scene.h"

namespace softsight {

struct SynthOptions {
  SceneOptions scene;
  // When set, the plate scene is rendered instead of `scene` (its size, frames, fps and seed
  // come from here; `scene` and `occluders` are not used).
  std::optional<PlateSceneOptions> plate;
  NoiseOptions noise;
  RenderOptions render;
  std::vector<Occluder> occluders;
  // Output, chosen by its name:
  //   *.avi, *.mkv   HuffYUV, lossless (what FFmpeg-based readers decode bit-exactly);
  //   *.mp4          MPEG-4 part 2, lossy (for sharing, not for accuracy tests);
  //   a printf pattern such as frames/%04d.png: one image per frame (PNG is lossless).
  std::string out;
  // Overrides the codec of a video: hfyu (HuffYUV, lossless), ffv1 (lossless, smaller, slower),
  // mjpg (Motion JPEG, lossy), mp4v (lossy). Empty: chosen by the extension as above.
  std::string codec;
  std::optional<std::string> truth_csv;
  bool quiet = false;  // No summary line.
};

struct SynthSummary {
  int64_t frames = 0;
  cv::Size size;
  std::string scene;        // "bending", "wedge1", "wedge4", "plate".
  std::string format;       // "HuffYUV video (lossless)", "PNG images", ...
  double render_ms_mean = 0.0;
  double wall_s = 0.0;
};

// Renders and writes every frame. Throws InputError (one line naming the option or file) for
// bad options or an unwritable output, before any frame is written when it can tell.
// `truths` (optional) receives every frame's truth, in order.
SynthSummary RunSynth(const SynthOptions& options, std::vector<SceneTruth>* truths = nullptr);

// The truth CSV (`--truth`) is io/truth_csv.h's: TruthColumns, read back by ReadTruthCsv.

// One line for a person.
std::string FormatSynthSummary(const SynthSummary& summary, const SynthOptions& options);

}  // namespace softsight
