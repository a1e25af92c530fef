// `softsight demo`: the whole job on a built-in scene whose truth is known exactly. Renders a
// bending actuator to a video, writes the config a person would write for it, tracks the video
// from the file, compares every number with the truth, and plots the run.
#include <filesystem>
#include <iostream>

#include <opencv2/imgproc.hpp>

#include "app/commands.h"
#include "app/scene_config.h"
#include "app/shared_flags.h"
#include "app/synth_command.h"
#include "app/track_command.h"
#include "app/truth_sink.h"
#include "softsight/core/error.h"
#include "softsight/config/config.h"
#include "softsight/io/plot.h"

namespace softsight {
namespace {

struct DemoOptions {
  std::string out_dir = "demo_out";
  int frames = 300;
  std::string scene = "bending";
  double noise_sigma = 2.0;
  bool quiet = false;
};

int RunDemo(const DemoOptions& options) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(options.out_dir, error);
  if (error) throw InputError(options.out_dir + ": cannot create folder (" + error.message() + ")");
  const fs::path dir(options.out_dir);

  SynthOptions synth;
  synth.scene.kind = ParseSceneKind(options.scene);
  synth.scene.frame_count = options.frames;
  synth.noise.sigma = options.noise_sigma;
  synth.out = (dir / "demo.avi").string();
  synth.truth_csv = (dir / "truth.csv").string();
  synth.quiet = true;
  std::cerr << "demo: rendering " << options.frames << " frames of the '" << options.scene
            << "' scene to " << synth.out << "\n";
  std::vector<SceneTruth> truths;
  RunSynth(synth, &truths);

  const std::string config_file = (dir / "markers.yaml").string();
  SaveTrackingConfig(ConfigForScene(synth.scene), config_file);

  TrackOptions track;
  track.config_file = config_file;
  track.source.input = synth.out;
  track.csv_file = (dir / "tracking.csv").string();
  track.quiet = options.quiet;
  std::cerr << "demo: tracking with " << config_file << "\n";
  // Scored against the renderer's truth of each frame as it is tracked.
  TruthScoreSink truth(truths, synth.scene.markers.size());
  const RunSummary summary = RunTrack(track, nullptr, {&truth});
  if (!options.quiet) std::cerr << summary.FullReport();
  const TruthScore score = truth.score();
  const std::string plot_file = (dir / "run.png").string();
  WritePlot(track.csv_file, plot_file, PlotOptions{});
  std::printf(
      "demo: against the exact truth over %lld frames: centroid error RMS %.3f px (max %.3f px), "
      "angle error RMS %.3f deg; %lld misses of %lld visible marker-frames, %lld false reports "
      "of %lld hidden\n",
      static_cast<long long>(score.frames), score.centroid_rms_px.value_or(0.0),
      score.centroid_max_px.value_or(0.0), score.angle_rms_deg.value_or(0.0),
      static_cast<long long>(score.misses), static_cast<long long>(score.visible),
      static_cast<long long>(score.false_reports), static_cast<long long>(score.hidden));
  std::printf("demo: wrote %s (video), %s (truth), %s (config), %s (CSV), %s (plot)\n",
              synth.out.c_str(), synth.truth_csv->c_str(), config_file.c_str(),
              track.csv_file.c_str(), plot_file.c_str());
  return 0;
}

const FlagTable<DemoOptions>& DemoFlags() {
  using A = DemoOptions;
  static const FlagTable<DemoOptions> table = {
      OutputFlag<A>(&A::out_dir, "out-dir", "Folder for the video, truth, config, CSV and plot")
          .ShowDefault(),
      FramesFlag<A>(&A::frames, "Frames to render").Check(CLI::Range(2, 100000)),
      SceneFlag<A>(&A::scene, "bending, wedge1 or wedge4"),
      NoiseFlag<A>(&A::noise_sigma).Check(CLI::Range(0.0, 50.0)),
      SwitchFlag<A>(kQuietFlag, &A::quiet).Help("No progress bar and no summary"),
  };
  return table;
}

}  // namespace

CommandRunner SetupDemoCommand(CLI::App& sub) {
  auto options = std::make_shared<DemoOptions>();
  sub.description(
      "The whole job on a built-in scene with exact ground truth: renders a soft bending\n"
      "actuator with red, blue and green markers to a video, writes the marker config,\n"
      "tracks the video, compares the result with the truth and plots it.\n"
      "Example: softsight demo --out-dir demo_out");
  AddFlags(sub, DemoFlags(), options.get());
  return [options] { return RunDemo(*options); };
}

}  // namespace softsight
