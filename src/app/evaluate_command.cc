// `softsight evaluate`: every tracking method over the same rendered frames, against the exact
// truth. See evaluate_command.h for how each method is set up and docs/evaluation.md for the
// metrics.
#include "app/evaluate_command.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "app/cli_checks.h"
#include "app/commands.h"
#include "app/progress.h"
#include "app/scene_config.h"
#include "app/shared_flags.h"
#include "app/truth_sink.h"
#include "softsight/config/config.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/io/truth_csv.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/sim/builtin_scenes.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"

namespace softsight {
namespace {

const std::vector<std::string> kModes = {"gray", "colour"};

// Side of the dragged template square, in marker radii.
constexpr double kTemplateSideRadii = 2.6;
// Frames are rendered once and kept in memory up to this size; longer runs re-render them for
// every method (rendering is deterministic, noise included, so every method sees the same frames).
constexpr size_t kFrameCacheBytes = size_t{512} << 20;

std::string JoinNames(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

void CheckNames(const std::vector<std::string>& names, const std::vector<std::string>& allowed,
                const std::string& option) {
  for (size_t i = 0; i < names.size(); ++i) {
    if (std::find(allowed.begin(), allowed.end(), names[i]) == allowed.end()) {
      throw InputError(option + ": unknown value '" + names[i] + "' (choose " +
                       JoinNames(allowed) + ")");
    }
    if (std::find(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(i), names[i]) !=
        names.begin() + static_cast<std::ptrdiff_t>(i)) {
      throw InputError(option + ": '" + names[i] + "' is given twice");
    }
  }
}


std::string FormatOptional(const std::optional<double>& value, int decimals) {
  return value ? FixedNumber(*value, decimals) : std::string("n/a");
}

// One evaluated configuration: a method and, for templates, a mode.
struct Run {
  std::string method;
  std::optional<std::string> mode;
};

// The template rectangle a person drags on frame 0: an odd square centred on the pixel nearest
// the marker's centre, so the template's centre is that pixel's centre.
cv::Rect DraggedRect(const cv::Point2d& centre_px, double radius_px) {
  int side = static_cast<int>(std::lround(kTemplateSideRadii * radius_px));
  if (side % 2 == 0) ++side;
  const int cx = static_cast<int>(std::lround(centre_px.x));
  const int cy = static_cast<int>(std::lround(centre_px.y));
  return cv::Rect(cx - side / 2, cy - side / 2, side, side);
}

// The rendered frames as a source: from memory when they fit, else rendered again (rendering is
// deterministic, noise included, so every method sees the same frames).
class RenderedFrames : public FrameSource {
 public:
  RenderedFrames(SyntheticScene& scene, const std::vector<SceneTruth>& truths,
                 const std::vector<cv::Mat>& cached)
      : scene_(scene), truths_(truths), cached_(cached) {}
  bool read(Frame& frame) override {
    if (next_ >= truths_.size()) return false;
    if (!cached_.empty()) {
      frame.image = cached_[next_];
    } else {
      scene_.render(static_cast<int>(next_), frame.image);
    }
    frame.index = static_cast<int64_t>(next_);
    frame.time_s = truths_[next_].time_s;
    ++next_;
    return true;
  }
  std::string description() const override { return "rendered scene"; }
  std::optional<int64_t> frame_count() const override {
    return static_cast<int64_t>(truths_.size());
  }
  std::optional<double> fps() const override { return scene_.options().fps; }

 private:
  SyntheticScene& scene_;
  const std::vector<SceneTruth>& truths_;
  const std::vector<cv::Mat>& cached_;
  size_t next_ = 0;
};

// One bar over the rendering and every method's run.
class SharedProgress : public FrameSink {
 public:
  SharedProgress(ProgressBar& bar, int64_t& done) : bar_(bar), done_(done) {}
  void consume(const Frame&, const FrameResult&) override { bar_.update(++done_); }

 private:
  ProgressBar& bar_;
  int64_t& done_;
};

MethodResult ResultOf(const Run& run, const TruthScore& score, const RunSummary& summary) {
  MethodResult out;
  out.method = run.method;
  out.mode = run.mode;
  out.visible = score.visible;
  out.found_visible = score.found_visible;
  out.misses = score.misses;
  out.hidden = score.hidden;
  out.false_reports = score.false_reports;
  out.centroid_rms_px = score.centroid_rms_px;
  out.centroid_max_px = score.centroid_max_px;
  out.centroid_p95_px = score.centroid_p95_px;
  out.wrong_finds = score.wrong_finds;
  out.with_sigma = score.with_sigma;
  out.within_3_sigma = score.within_3_sigma;
  out.beyond_5_sigma = score.beyond_5_sigma;
  out.precision_rms_px = score.precision_rms_px;
  out.precision_max_px = score.precision_max_px;
  out.angle_rms_deg = score.angle_rms_deg;
  out.angle_frames = score.angle_frames;
  out.proc_ms_median = summary.proc_ms_median;
  out.proc_ms_p99 = summary.proc_ms_p99;
  return out;
}

std::string Conditions(const EvaluateOptions& options) {
  const SceneOptions& scene = options.scene;
  const NoiseOptions& noise = options.noise;
  std::ostringstream text;
  text << "Scene " << SceneKindName(scene.kind) << " " << scene.size.width << "x"
       << scene.size.height << ", " << scene.frame_count << " frames, markers of radius "
       << scene.marker_radius_px << " px; noise sigma " << noise.sigma << ", blur sigma "
       << noise.blur_sigma_px << " px, gain " << noise.gain_start << " -> " << noise.gain_end
       << ", seeds " << scene.seed << "/" << noise.seed
       << (options.occluders.empty() ? "" : ", with occluders")
       << (options.rect_centre ? "; templates report the rectangle's centre" : "")
       << (options.square_mask ? "; square template masks" : "") << ".";
  return text.str();
}

}  // namespace

TrackingConfig EvaluateMethodConfig(const std::string& method,
                                    const std::optional<std::string>& mode,
                                    const EvaluateOptions& options, const SceneTruth& first) {
  TrackingConfig config;
  const SceneOptions& scene = options.scene;
  for (size_t i = 0; i < scene.markers.size(); ++i) {
    MarkerSpec spec;
    spec.name = scene.markers[i].name;
    ColourParams colour;
    TemplateParams templ;
    if (!IsTemplateMethod(method)) {
      colour = ThresholdsFor(scene.markers[i].bgr);
      if (options.noise.sigma > 0) {
        colour.filter = ColourParams::Filter::kGaussian;
        colour.filter_ksize = 5;
      }
    } else {
      const std::optional<cv::Point2d>& centre = first.markers[i].centroid_px;
      if (!centre || first.markers[i].visible_fraction < kMustFindVisibleFraction) {
        throw InputError("marker '" + spec.name +
                         "' is hidden on frame 0: no template can be dragged around it");
      }
      templ.colour = mode == std::optional<std::string>("colour");
      templ.template_frame = 0;
      templ.rect = DraggedRect(*centre, scene.marker_radius_px);
      if (options.rect_centre) templ.report = TemplateReport::kRectCentre;
      if (options.square_mask) templ.round_mask = false;
    }
    spec.params = ParamsForMethod(method, {colour, templ});
    config.markers.push_back(spec);
  }
  config.measure = SceneMeasureOptions(scene);
  return config;
}

std::string MethodResult::label() const { return mode ? method + " " + *mode : method; }

void EvaluateOptions::Check() const {
  if (scene.frame_count < 1) {
    throw InputError("--frames must be at least 1, got " + std::to_string(scene.frame_count));
  }
  if (methods.empty()) throw InputError("--methods: no method given");
  CheckNames(methods, TrackerMethods(), "--methods");
  CheckNames(modes, kModes, "--modes");
  const bool templates = std::any_of(methods.begin(), methods.end(), IsTemplateMethod);
  if (templates && modes.empty()) {
    throw InputError("--modes: no mode given for the template methods (choose gray, colour)");
  }
  std::string error;
  if (!scene.Check(&error)) throw InputError("scene: " + error);
  if (!noise.Check(&error)) throw InputError("noise: " + error);
}

void ParseGainRamp(const std::string& text, NoiseOptions* noise) {
  const auto fail = [&text]() {
    return InputError(
        "--gain-ramp: expected START,END (two positive gains such as 0.6,1.4), got '" + text +
        "'");
  };
  const size_t comma = text.find(',');
  if (comma == std::string::npos) throw fail();
  double values[2];
  const std::string parts[2] = {text.substr(0, comma), text.substr(comma + 1)};
  for (int i = 0; i < 2; ++i) {
    const char* begin = parts[i].c_str();
    char* end = nullptr;
    errno = 0;
    values[i] = std::strtod(begin, &end);
    if (parts[i].empty() || end == begin || *end != '\0' || errno != 0 ||
        !std::isfinite(values[i]) || values[i] <= 0) {
      throw fail();
    }
  }
  noise->gain_start = values[0];
  noise->gain_end = values[1];
}

EvaluateReport RunEvaluate(const EvaluateOptions& options) {
  options.Check();
  std::vector<Run> runs;
  for (const std::string& method : options.methods) {
    if (!IsTemplateMethod(method)) {
      runs.push_back({method, std::nullopt});
    } else {
      for (const std::string& mode : options.modes) runs.push_back({method, mode});
    }
  }

  if (options.csv_file && !std::ofstream(*options.csv_file, std::ios::app)) {
    // Said before the work rather than after it.
    throw InputError(*options.csv_file +
                     ": cannot write the CSV (check the folder and permissions)");
  }
  SyntheticScene scene(options.scene, options.noise, RenderOptions{}, options.occluders);
  const int frames = scene.frame_count();
  const size_t frame_bytes = static_cast<size_t>(options.scene.size.area()) * 3;
  const bool cache = frame_bytes * static_cast<size_t>(frames) <= kFrameCacheBytes;

  ProgressBar progress("evaluate", static_cast<int64_t>(frames) * (1 + runs.size()),
                       !options.quiet);
  int64_t done = 0;
  std::vector<SceneTruth> truths;
  std::vector<cv::Mat> images;
  truths.reserve(static_cast<size_t>(frames));
  cv::Mat buffer;
  for (int i = 0; i < frames; ++i) {
    truths.push_back(scene.render(i, buffer));
    if (cache) images.push_back(buffer.clone());
    progress.update(++done);
  }

  EvaluateReport report;
  report.conditions = Conditions(options);
  report.frames = frames;
  for (const Run& run : runs) {
    TrackingSession session(EvaluateMethodConfig(run.method, run.mode, options, truths.front()));
    RenderedFrames source(scene, truths, images);
    TruthScoreSink score(truths, options.scene.markers.size());
    SharedProgress shared(progress, done);
    const RunSummary summary = RunPipeline(source, session, {&score, &shared});
    if (!summary.ok()) throw InputError(run.method + ": " + summary.error);
    report.methods.push_back(ResultOf(run, score.score(), summary));
  }
  progress.finish();
  if (options.csv_file) WriteEvaluateCsv(report, *options.csv_file);
  return report;
}

std::string FormatEvaluateMarkdown(const EvaluateReport& report) {
  std::ostringstream out;
  out << report.conditions << "\n\n"
      << "| method | centroid RMS (px) | centroid p95 (px) | centroid max (px) | "
         "precision RMS (px) | precision max (px) | misses / visible | wrong (> 3 px) | "
         "false / hidden | within 3 sigma / beyond 5 | angle RMS (deg) | median (ms) | p99 (ms) |\n"
      << "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  for (const MethodResult& m : report.methods) {
    out << "| " << m.label() << " | " << FormatOptional(m.centroid_rms_px, 3) << " | "
        << FormatOptional(m.centroid_p95_px, 3) << " | " << FormatOptional(m.centroid_max_px, 3)
        << " | " << FormatOptional(m.precision_rms_px, 3) << " | "
        << FormatOptional(m.precision_max_px, 3) << " | " << m.misses << " / " << m.visible
        << " | " << m.wrong_finds << " | " << m.false_reports << " / " << m.hidden << " | "
        << (m.with_sigma > 0 ? FixedNumber(100.0 * m.within_3_sigma / m.with_sigma, 1) + " % / " +
                                   std::to_string(m.beyond_5_sigma)
                             : std::string("-"))
        << " | " << FormatOptional(m.angle_rms_deg, 3) << " | " << FixedNumber(m.proc_ms_median, 3)
        << " | " << FixedNumber(m.proc_ms_p99, 3) << " |\n";
  }
  out << "\nCentroid: |tracked - true| over found, visible (>= 50%) marker-frames. Precision: the "
         "same after removing each marker's constant offset measured on its first found frame "
         "(frame 0). Wrong: found farther than 3 px from the truth. Sigma: the share of found "
         "positions whose error along both axes is within 3 of their reported sigma_px, and the "
         "count beyond 5. Times: tracking + measurement of all markers per frame.\n";
  return out.str();
}

void WriteEvaluateCsv(const EvaluateReport& report, const std::string& file) {
  std::ofstream out(file);
  if (!out) throw InputError(file + ": cannot write the CSV (check the folder and permissions)");
  out << "method,mode,frames,visible,found,misses,hidden,false_reports,centroid_rms_px,"
         "centroid_max_px,precision_rms_px,precision_max_px,angle_rms_deg,angle_frames,"
         "proc_ms_median,proc_ms_p99,centroid_p95_px,wrong_finds,with_sigma,within_3_sigma,"
         "beyond_5_sigma\n";
  const auto field = [](const std::optional<double>& value) {
    return value ? FixedNumber(*value, 6) : std::string();
  };
  for (const MethodResult& m : report.methods) {
    out << m.method << "," << m.mode.value_or("") << "," << report.frames << "," << m.visible
        << "," << m.found_visible << "," << m.misses << "," << m.hidden << "," << m.false_reports
        << "," << field(m.centroid_rms_px) << "," << field(m.centroid_max_px) << ","
        << field(m.precision_rms_px) << "," << field(m.precision_max_px) << ","
        << field(m.angle_rms_deg) << "," << m.angle_frames << ","
        << FixedNumber(m.proc_ms_median, 6) << "," << FixedNumber(m.proc_ms_p99, 6) << ","
        << field(m.centroid_p95_px) << "," << m.wrong_finds << "," << m.with_sigma << ","
        << m.within_3_sigma << "," << m.beyond_5_sigma << "\n";
  }
  out.flush();
  if (!out) throw InputError(file + ": writing the CSV failed (disk full?)");
}

namespace {

// The truth of a user's recording by source frame index, for the markers it shares with the
// config (in config order).
struct TruthTable {
  std::vector<size_t> config_index;        // Of each scored marker, in the config.
  std::vector<std::string> names;          // The scored markers.
  std::vector<std::string> unmatched;      // Config markers the truth has no columns for.
  std::map<int64_t, SceneTruth> by_frame;
};

TruthTable ReadTruthTable(const std::string& file, const TrackingConfig& config) {
  std::vector<std::string> names;
  for (const MarkerSpec& spec : config.markers) names.push_back(spec.name);
  TruthCsv read = ReadTruthCsv(file, names);  // The columns `synth --truth` writes.
  TruthTable truth;
  truth.config_index = std::move(read.wanted_index);
  truth.names = std::move(read.markers);
  truth.unmatched = std::move(read.missing);
  for (SceneTruth& frame : read.frames) {
    const int64_t index = frame.frame_index;
    truth.by_frame.emplace(index, std::move(frame));
  }
  return truth;
}

// Scores each processed frame that has a truth row, with the scored markers only.
class TruthTableSink : public FrameSink {
 public:
  explicit TruthTableSink(const TruthTable& truth) : truth_(truth), scorer_(truth.names.size()) {}
  void consume(const Frame& frame, const FrameResult& result) override {
    const auto it = truth_.by_frame.find(frame.index);
    if (it == truth_.by_frame.end()) {
      ++unscored_;
      return;
    }
    scored_.frame_index = result.frame_index;
    scored_.time_s = result.time_s;
    scored_.measurement = result.measurement;
    scored_.markers.resize(truth_.config_index.size());
    for (size_t k = 0; k < truth_.config_index.size(); ++k) {
      scored_.markers[k] = result.markers[truth_.config_index[k]];
    }
    scorer_.add(it->second, scored_);
  }
  TruthScore score() const { return scorer_.score(); }
  int64_t unscored() const { return unscored_; }

 private:
  const TruthTable& truth_;
  TruthScorer scorer_;
  FrameResult scored_;
  int64_t unscored_ = 0;
};

std::string BaseName(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

EvaluateReport RunVideoEvaluate(const VideoEvaluateOptions& options) {
  const TrackingConfig config = LoadTrackingConfig(options.config_file);
  const TruthTable truth = ReadTruthTable(options.truth_csv, config);
  std::unique_ptr<FrameSource> source = OpenFrameSource(options.source);
  if (options.csv_file) {
    std::vector<PathRole> inputs = {{"--truth", options.truth_csv}, {"--config", options.config_file}};
    for (size_t i = 0; i < config.files_read.size(); ++i) {
      inputs.push_back({"a file the config names:", config.files_read[i]});
    }
    for (const std::string& file : source->files()) inputs.push_back({"--input", file});
    CheckOutputsAreNotInputs({{"--csv", *options.csv_file}}, inputs);
  }
  if (source->is_live()) throw InputError("evaluate --input needs a recording, not a camera");
  TrackingSession session(config);
  TruthTableSink score(truth);
  ProgressSink progress("evaluate", !options.quiet);
  const RunSummary summary = RunPipeline(*source, session, {&score, &progress});
  if (!summary.ok()) throw InputError(summary.error);
  if (summary.frames == score.unscored()) {
    throw InputError(options.truth_csv + ": none of its frame numbers is a frame of " +
                     source->description() + " (" + std::to_string(summary.frames) +
                     " frames; `frame` is the source's frame index, as in track's CSV)");
  }
  Run run;
  run.method = BaseName(options.config_file);
  EvaluateReport report;
  report.frames = summary.frames - score.unscored();
  report.methods.push_back(ResultOf(run, score.score(), summary));
  std::ostringstream conditions;
  conditions << source->description() << ": " << summary.frames << " frames, "
             << report.frames << " of them scored against " << options.truth_csv
             << "; markers matched by name: " << JoinNames(truth.names);
  if (!truth.unmatched.empty()) {
    conditions << "; not in the truth (not scored): " << JoinNames(truth.unmatched);
  }
  conditions << ".";
  report.conditions = conditions.str();
  if (options.csv_file) WriteEvaluateCsv(report, *options.csv_file);
  return report;
}

namespace {

// What evaluate's flags set until it runs: the built-in comparison's options, or a recording's.
struct EvaluateArgs {
  EvaluateOptions options;
  std::string scene_name = "bending";
  std::string gain_ramp;  // START,END
  VideoEvaluateOptions video;
};

const FlagTable<EvaluateArgs>& EvaluateFlags() {
  using A = EvaluateArgs;
  static const FlagTable<EvaluateArgs> table = {
      SceneFlag<A>(&A::scene_name,
                   "bending, wedge1, wedge4 or bench (textured, with look-alike blobs)"),
      FramesFlag<A>([](A& a) -> auto& { return a.options.scene.frame_count; },
                    "Frames to render and track"),
      NoiseFlag<A>([](A& a) -> auto& { return a.options.noise.sigma; }),
      BlurFlag<A>([](A& a) -> auto& { return a.options.noise.blur_sigma_px; }),
      ValueFlag<A>("--gain-ramp", &A::gain_ramp)
          .Help("Illumination gain START,END, ramping linearly over the sequence (e.g. 0.6,1.4)"),
      ValueFlag<A>("--methods", [](A& a) -> auto& { return a.options.methods; })
          .Help("Methods, comma separated: " + JoinNames(TrackerMethods()))
          .Finish([](CLI::Option* o) { o->delimiter(','); })
          .ShowDefault(),
      ValueFlag<A>("--modes", [](A& a) -> auto& { return a.options.modes; })
          .Help("Template matching modes, comma separated: gray,colour")
          .Finish([](CLI::Option* o) { o->delimiter(','); })
          .ShowDefault(),
      SwitchFlag<A>("--rect-centre", [](A& a) -> auto& { return a.options.rect_centre; })
          .Help("Template trackers report the dragged rectangle's centre (the paper's position) "
                "instead of the marker's centre of symmetry"),
      SwitchFlag<A>("--square-mask", [](A& a) -> auto& { return a.options.square_mask; })
          .Help("Template trackers match the whole template square, not the disc inscribed in "
                "it"),
      OutputFlag<A>([](A& a) -> auto& { return a.options.csv_file; }, "csv",
                    "Also write the table as CSV to this file"),
      SeedFlag<A>([](A& a) -> auto& { return a.options.scene.seed; },
                  "Background texture and noise seed (as `softsight synth --seed`: same frames)"),
      SwitchFlag<A>(kQuietFlag, [](A& a) -> auto& { return a.options.quiet; })
          .Help("No progress line"),
      ValueFlag<A>(kInputFlag, [](A& a) -> auto& { return a.video.source.input; })
          .Help("Your recording (video, image sequence or synth:NAME) to score instead of the "
                "built-in comparison; needs --truth and --config"),
      ValueFlag<A>("--truth", [](A& a) -> auto& { return a.video.truth_csv; })
          .Help("With --input: the truth CSV (frame, <name>_x, <name>_y[, <name>_visible]; "
                "`softsight synth --truth` writes one)"),
      ValueFlag<A>(kConfigFlag, [](A& a) -> auto& { return a.video.config_file; })
          .Help("With --input: the marker config to score"),
      SequenceFpsFlag<A>([](A& a) -> auto& { return a.video.source.sequence_fps; },
                         "With --input: an image sequence's frame rate"),
  };
  return table;
}

}  // namespace

CommandRunner SetupEvaluateCommand(CLI::App& sub) {
  auto args = std::make_shared<EvaluateArgs>();
  sub.description(
      "Compare the tracking methods on a rendered scene with exact ground truth: the colour\n"
      "tracker and the SAD, SSD and ZNCC template trackers (gray and colour) run over the same\n"
      "frames, set up as a person would (HSV thresholds around each marker's hue; a template\n"
      "dragged around each marker on frame 0). Prints a Markdown table: centroid error (absolute,\n"
      "and with the template's constant placement offset removed), misses, false reports, angle\n"
      "error and time per frame. No video file is written. See docs/evaluation.md.\n"
      "With --input, --truth and --config it scores your own recording instead: the config's\n"
      "markers against the truth CSV's (matched by name: <name>_x, <name>_y and optionally\n"
      "<name>_visible per frame number), with the same figures (RMS, p95, max, misses, wrong\n"
      "finds farther than 3 px, false reports while hidden).\n"
      "Examples:\n"
      "  softsight evaluate --noise 5 --csv noise5.csv\n"
      "  softsight synth --frames 100 --out run.avi --truth truth.csv\n"
      "  softsight evaluate --input run.avi --truth truth.csv --config markers.yaml");
  AddFlags(sub, EvaluateFlags(), args.get());
  // The run's parts, each keeping `args` alive.
  const std::shared_ptr<EvaluateOptions> options(args, &args->options);
  const std::shared_ptr<std::string> scene_name(args, &args->scene_name);
  const std::shared_ptr<std::string> gain_ramp(args, &args->gain_ramp);
  const std::shared_ptr<VideoEvaluateOptions> video(args, &args->video);
  return [options, scene_name, gain_ramp, video, &sub] {
    if (!video->source.input.empty() || !video->truth_csv.empty() || !video->config_file.empty()) {
      if (video->source.input.empty() || video->truth_csv.empty() || video->config_file.empty()) {
        throw InputError("scoring a recording needs all three of --input VIDEO, --truth TRUTH.csv "
                         "and --config CFG");
      }
      for (const char* builtin : {"--scene", "--frames", "--noise", "--blur", "--gain-ramp",
                                  "--methods", "--modes", "--rect-centre", "--square-mask",
                                  "--seed"}) {
        if (sub.count(builtin) > 0) {
          throw InputError(std::string(builtin) +
                           " sets up the built-in comparison; it does not apply to --input");
        }
      }
      VideoEvaluateOptions run = *video;
      run.csv_file = options->csv_file;
      run.quiet = options->quiet;
      std::cout << FormatEvaluateMarkdown(RunVideoEvaluate(run));
      return 0;
    }
    EvaluateOptions run = *options;
    SetActuatorScene(*scene_name, &run.scene);
    run.noise.seed = run.scene.seed;  // As `softsight synth` does, so both render the same frames.
    if (!gain_ramp->empty()) ParseGainRamp(*gain_ramp, &run.noise);
    std::cout << FormatEvaluateMarkdown(RunEvaluate(run));
    return 0;
  };
}

}  // namespace softsight
