#include "app/synth_command.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <variant>

#include "app/commands.h"
#include "app/shared_flags.h"
#include "softsight/core/error.h"
#include "softsight/io/frame_writer.h"
#include "softsight/io/output_guard.h"
#include "softsight/io/truth_csv.h"
#include "softsight/sim/builtin_scenes.h"

namespace softsight {
namespace {

// Parses "x,y,w,h,first,last".
Occluder ParseOccluder(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) v.clear(), v.resize(7);
    } catch (const std::exception&) {
      v.resize(7);
      break;
    }
  }
  if (v.size() != 6 || v[4] != std::floor(v[4]) || v[5] != std::floor(v[5])) {
    throw InputError("--occlude '" + text +
                     "': expected x,y,w,h,first,last (pixels, then whole frame numbers)");
  }
  Occluder o;
  o.rect_px = cv::Rect2d(v[0], v[1], v[2], v[3]);
  o.first_frame = static_cast<int>(v[4]);
  o.last_frame = static_cast<int>(v[5]);
  return o;
}

cv::Size ParseSize(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X')) {
    throw InputError("--size '" + text + "': expected WIDTHxHEIGHT, e.g. 640x480");
  }
  return cv::Size(w, h);
}

}  // namespace

std::string FormatSynthSummary(const SynthSummary& s, const SynthOptions& options) {
  char line[512];
  std::snprintf(line, sizeof(line),
                "synth: %lld frames %dx%d of scene %s -> %s (%s)%s%s in %.1f s (render %.2f ms/frame)",
                static_cast<long long>(s.frames), s.size.width, s.size.height, s.scene.c_str(),
                options.out.c_str(), s.format.c_str(), options.truth_csv ? ", truth -> " : "",
                options.truth_csv ? options.truth_csv->c_str() : "", s.wall_s, s.render_ms_mean);
  return line;
}

SynthSummary RunSynth(const SynthOptions& options, std::vector<SceneTruth>* truths) {
  const auto start = std::chrono::steady_clock::now();
  const int frames = options.plate ? options.plate->frame_count : options.scene.frame_count;
  if (frames < 1) throw InputError("--frames: must be at least 1, got " + std::to_string(frames));
  // Everything is checked before any file is created.
  std::optional<SyntheticScene> scene;
  std::optional<PlateScene> plate;
  std::vector<std::string> marker_names;
  if (options.plate) {
    plate.emplace(*options.plate, options.noise, options.render);
    for (int i = 0; i < options.plate->dot_count; ++i) marker_names.push_back("dot" + std::to_string(i));
  } else {
    scene.emplace(options.scene, options.noise, options.render, options.occluders);
    for (const SceneMarker& m : options.scene.markers) marker_names.push_back(m.name);
  }
  const cv::Size size = plate ? options.plate->size : options.scene.size;
  const double fps = plate ? options.plate->fps : options.scene.fps;
  const int frame_count = plate ? plate->frame_count() : scene->frame_count();
  if (options.out.empty()) throw InputError("--out: give the output video or image pattern");
  // Both outputs are checked (writable, not one file) before either is created.
  CheckOutputsAreNotInputs({{"--out", options.out}, {"--truth", options.truth_csv.value_or("")}},
                           {});
  FrameWriter sink({options.out, options.codec, fps});
  sink.open(size);  // Fails here, before the truth file is created.
  // The truth CSV's columns and writer are the ones `evaluate --truth` reads back with
  // (io/truth_csv.h); each row is written whole as its frame is rendered.
  std::optional<TruthCsvWriter> truth_csv;
  if (options.truth_csv) truth_csv.emplace(*options.truth_csv, TruthColumns(marker_names));

  SynthSummary summary;
  summary.size = size;
  summary.scene = plate ? "plate" : SceneKindName(options.scene.kind);
  summary.format = sink.format();
  cv::Mat image;
  double render_ms = 0.0;
  for (int i = 0; i < frame_count; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const SceneTruth truth = plate ? plate->render(i, image) : scene->render(i, image);
    render_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    sink.write(image, i);
    if (truths != nullptr) truths->push_back(truth);
    if (truth_csv) truth_csv->write(truth);
    ++summary.frames;
  }
  sink.close();
  summary.render_ms_mean = render_ms / std::max<int64_t>(1, summary.frames);
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

namespace {

// What synth's flags set until it runs.
struct SynthArgs {
  SynthOptions options;
  std::string scene_name = "bending";
  std::string size = "640x480";       // WIDTHxHEIGHT
  std::vector<std::string> occlusions;  // x,y,w,h,first,last each
};

const FlagTable<SynthArgs>& SynthFlags() {
  using A = SynthArgs;
  // A field of the scene (or of the noise): one accessor per row, spelled once.
  auto scene = [](auto SceneOptions::*field) {
    return [field](A& a) -> auto& { return a.options.scene.*field; };
  };
  auto noise = [](auto NoiseOptions::*field) {
    return [field](A& a) -> auto& { return a.options.noise.*field; };
  };
  static const FlagTable<SynthArgs> table = {
      SceneFlag<A>(&A::scene_name,
                   "bending: a silicone band bending from straight to --max-bend degrees; "
                   "wedge1 / wedge4: the paper's triangle actuators (1 segment opening 20 degrees, "
                   "4 segments opening 80); bench: bending on a textured bench with look-alike "
                   "blobs of every marker colour; plate: a gray view of a plate with 5 white dots "
                   "that tilts to 50 degrees and grows 1x to 2x (dot0..dot4)"),
      OutputFlag<A>([](A& a) -> auto& { return a.options.out; }, "out",
                    "Video (.avi/.mkv: lossless HuffYUV; .mp4: lossy) or image pattern "
                    "(frames/%04d.png)")
          .Required(),
      ValueFlag<A>("--truth", [](A& a) -> auto& { return a.options.truth_csv; })
          .Help("Ground-truth CSV (one row per frame)"),
      FramesFlag<A>(scene(&SceneOptions::frame_count), "Number of frames"),
      ValueFlag<A>("--size", &A::size).Help("Image size WIDTHxHEIGHT").ShowDefault(),
      ValueFlag<A>("--fps", scene(&SceneOptions::fps))
          .Help("Frame rate (sets time_s and the video's rate)")
          .ShowDefault(),
      ValueFlag<A>("--max-bend", scene(&SceneOptions::max_bend_deg))
          .Help("bending: total turning of the centre line at full bend, degrees (<= 330)")
          .ShowDefault(),
      SwitchFlag<A>("--oscillate", scene(&SceneOptions::oscillate))
          .Help("Bend and unbend instead of one sweep"),
      ValueFlag<A>("--cycles", scene(&SceneOptions::oscillate_cycles))
          .Help("With --oscillate: bend-unbend cycles")
          .ShowDefault(),
      ValueFlag<A>("--length", scene(&SceneOptions::length_px))
          .Help("Body length along its centre line, pixels")
          .ShowDefault(),
      ValueFlag<A>("--width", scene(&SceneOptions::width_px))
          .Help("Body width, pixels")
          .ShowDefault(),
      ValueFlag<A>("--marker-radius", scene(&SceneOptions::marker_radius_px))
          .Help("Marker disc radius, pixels")
          .ShowDefault(),
      SeedFlag<A>(scene(&SceneOptions::seed), "Background texture (and noise) seed"),
      NoiseFlag<A>(noise(&NoiseOptions::sigma)),
      BlurFlag<A>(noise(&NoiseOptions::blur_sigma_px)),
      ValueFlag<A>("--gain-start", noise(&NoiseOptions::gain_start))
          .Help("Illumination gain at the first frame")
          .ShowDefault(),
      ValueFlag<A>("--gain-end", noise(&NoiseOptions::gain_end))
          .Help("Illumination gain at the last frame (linear ramp)")
          .ShowDefault(),
      ValueFlag<A>("--occlude", &A::occlusions)
          .Help("x,y,w,h,first,last: a grey rectangle over everything during frames "
                "first..last (repeatable)"),
      ValueFlag<A>("--supersample", [](A& a) -> auto& { return a.options.render.supersample; })
          .Help("Anti-aliasing sub-samples per pixel side (truth is exact at this resolution)")
          .ShowDefault(),
      ValueFlag<A>("--codec", [](A& a) -> auto& { return a.options.codec; })
          .Help("Video codec override: ffv1, hfyu, mjpg or mp4v"),
      SwitchFlag<A>(kQuietFlag, [](A& a) -> auto& { return a.options.quiet; })
          .Help("No summary line"),
  };
  return table;
}

}  // namespace

CommandRunner SetupSynthCommand(CLI::App& sub) {
  auto args = std::make_shared<SynthArgs>();
  sub.description(
      "Render a synthetic soft actuator carrying red, blue and green disc markers on a textured\n"
      "background, with exact ground truth: every marker's centroid (of its visible area), the\n"
      "bend and the paper's measurements, per frame. Use it to try `softsight track` or to check\n"
      "accuracy. Example:\n"
      "  softsight synth --scene bending --frames 300 --out demo.avi --truth truth.csv");
  AddFlags(sub, SynthFlags(), args.get());
  // The run's parts, each keeping `args` alive.
  const std::shared_ptr<SynthOptions> options(args, &args->options);
  const std::shared_ptr<std::string> scene_name(args, &args->scene_name);
  const std::shared_ptr<std::string> size(args, &args->size);
  const std::shared_ptr<std::vector<std::string>> occlusions(args, &args->occlusions);
  return [options, scene_name, size, occlusions] {
    options->scene.size = ParseSize(*size);
    options->plate.reset();
    // Names every built-in scene when the name is none of them.
    if (std::holds_alternative<PlateSceneOptions>(ParseBuiltinScene(*scene_name))) {
      PlateSceneOptions& plate = options->plate.emplace();
      plate.size = options->scene.size;
      plate.frame_count = options->scene.frame_count;
      plate.fps = options->scene.fps;
      plate.seed = options->scene.seed;
    } else {
      SetActuatorScene(*scene_name, &options->scene);
    }
    options->noise.seed = options->scene.seed;
    options->occluders.clear();
    for (const std::string& text : *occlusions) options->occluders.push_back(ParseOccluder(text));
    const SynthSummary summary = RunSynth(*options);
    if (!options->quiet) std::cerr << FormatSynthSummary(summary, *options) << "\n";
    return 0;
  };
}

}  // namespace softsight
