// `softsight init` and `softsight pick`: see init_command.h.
#include "app/init_command.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "app/cli_checks.h"
#include "app/commands.h"
#include "app/shared_flags.h"
#include "gui/live_options.h"
#include "softsight/core/error.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sink.h"
#include "softsight/pipeline/tracking_session.h"
#include "softsight/track/colour_tracker.h"

namespace softsight {
namespace {

std::vector<double> ParseNumbers(const std::string& text, size_t count, const std::string& option,
                                 const char* form) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string part;
  while (std::getline(stream, part, ',')) {
    const char* begin = part.c_str();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(begin, &end);
    if (part.empty() || end == begin || *end != '\0' || errno != 0 || !std::isfinite(v)) {
      values.clear();
      break;
    }
    values.push_back(v);
  }
  if (values.size() != count || (!text.empty() && text.back() == ',')) {
    throw InputError(option + " '" + text + "': expected " + form);
  }
  return values;
}

std::string Range(const HsvRange& r) {
  return "[" + std::to_string(r.lo) + ", " + std::to_string(r.hi) + "]";
}

std::string Describe(const ColourParams& c) {
  if (c.gray) return "gray " + Range(*c.gray);
  return "h " + Range(c.h) + " s " + Range(c.s) + " v " + Range(c.v);
}

std::string PictureBeside(const std::string& config_file) {
  const size_t dot = config_file.rfind('.');
  const size_t slash = config_file.rfind('/');
  const bool has_extension = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return (has_extension ? config_file.substr(0, dot) : config_file) + ".png";
}

// Before anything is written: no output may be a file the input reads (a video, or any file of
// an image sequence), the base config, or another output.
void CheckOutputs(const std::vector<PathRole>& outputs, const FrameSourceSpec& source,
                  const std::optional<std::string>& base_config = std::nullopt) {
  std::vector<PathRole> inputs;
  for (const std::string& file : OpenFrameSource(source)->files()) {
    inputs.push_back({"--input", file});
  }
  if (base_config) inputs.push_back({"--config", *base_config});
  CheckOutputsAreNotInputs(outputs, inputs);
}

// The measurement of markers given in body order (MeasureOptions::AlongBody).
MeasureOptions BodyMeasure(const std::vector<MarkerSpec>& markers) {
  std::vector<std::string> names;
  for (const MarkerSpec& m : markers) names.push_back(m.name);
  return MeasureOptions::AlongBody(names);
}

// Frames after the analysed one that init watches to see which end of the body stays put.
constexpr int64_t kMotionFrames = 90;
// An end counts as fixed when it moved less than this fraction of the other end's motion, which
// must be at least kMinMotionPx.
constexpr double kFixedEndRatio = 0.5;
constexpr double kMinMotionPx = 3.0;

// The base of an actuator is clamped: over the frames that follow, it moves least. Returns true
// when the last marker of the finding's order is the one that stays put (turn the order round),
// false when the first is, nothing when the video does not show it; `note` says what was seen.
// How far the two ends of the finding's order move from where init found them, over a run.
class EndMotionSink : public FrameSink {
 public:
  explicit EndMotionSink(const MarkerFinding& finding) : finding_(finding) {}
  void consume(const Frame& frame, const FrameResult& result) override {
    (void)frame;
    ++frames_;
    const size_t last = finding_.markers.size() - 1;
    const Observation& first = result.markers.front().observation;
    const Observation& end = result.markers[last].observation;
    if (!first.found() || !end.found()) return;
    ++both_;
    moved_first_ = std::max(moved_first_,
                            cv::norm(*first.position_px - finding_.markers.front().position_px));
    moved_last_ = std::max(moved_last_,
                           cv::norm(*end.position_px - finding_.markers[last].position_px));
  }
  int64_t frames() const { return frames_; }
  int64_t both() const { return both_; }  // Frames with both ends found.
  double moved_first() const { return moved_first_; }
  double moved_last() const { return moved_last_; }

 private:
  const MarkerFinding& finding_;
  int64_t frames_ = 0, both_ = 0;
  double moved_first_ = 0, moved_last_ = 0;
};

std::optional<bool> LastEndIsFixed(const InitOptions& options, const MarkerFinding& finding,
                                   std::string* note) {
  TrackingConfig config;
  for (const FoundMarker& m : finding.markers) config.markers.push_back(m.spec);
  std::unique_ptr<FrameSource> source = OpenFrameSource(options.source);
  Frame frame;
  for (int64_t i = 0; i < options.frame; ++i) {
    if (!source->read(frame)) return std::nullopt;
  }
  // The frames that follow, through the pipeline as `track` would run them.
  TrackingSession session(config);
  EndMotionSink motion(finding);
  RunOptions run;
  run.max_frames = kMotionFrames;
  const RunSummary summary = RunPipeline(*source, session, {&motion}, run);
  if (!summary.ok() && motion.frames() == 0) return std::nullopt;
  const size_t last = finding.markers.size() - 1;
  const int64_t frames = motion.frames(), both = motion.both();
  const double moved_first = motion.moved_first(), moved_last = motion.moved_last();
  char text[200];
  std::snprintf(text, sizeof(text), "over %lld frames from frame %lld, %s moved %.1f px and %s %.1f px",
                static_cast<long long>(frames), static_cast<long long>(options.frame),
                finding.markers.front().spec.name.c_str(), moved_first,
                finding.markers[last].spec.name.c_str(), moved_last);
  *note = text;
  if (both * 2 < frames || std::max(moved_first, moved_last) < kMinMotionPx) return std::nullopt;
  if (moved_last < kFixedEndRatio * moved_first) return true;
  if (moved_first < kFixedEndRatio * moved_last) return false;
  return std::nullopt;
}

}  // namespace

cv::Point2d ParsePointOption(const std::string& text, const std::string& option) {
  const std::vector<double> v = ParseNumbers(text, 2, option, "X,Y in pixels, e.g. 320,240");
  return {v[0], v[1]};
}

cv::Rect ParseRectOption(const std::string& text, const std::string& option) {
  const std::vector<double> v =
      ParseNumbers(text, 4, option, "X,Y,W,H in pixels, e.g. 100,50,400,300");
  if (v[2] < 1 || v[3] < 1 || std::abs(v[0]) > 1e6 || std::abs(v[1]) > 1e6 || v[2] > 1e6 ||
      v[3] > 1e6) {
    throw InputError(option + " '" + text + "': width and height must be at least 1 px");
  }
  return cv::Rect(static_cast<int>(std::lround(v[0])), static_cast<int>(std::lround(v[1])),
                  static_cast<int>(std::lround(v[2])), static_cast<int>(std::lround(v[3])));
}

Frame ReadFrameAt(const FrameSourceSpec& spec, int64_t position) {
  if (position < 0) throw InputError("--frame " + std::to_string(position) + ": must be 0 or more");
  std::unique_ptr<FrameSource> source = OpenFrameSource(spec);
  if (source->is_live()) throw InputError("init and pick read a video or image sequence, not a camera");
  Frame frame;
  for (int64_t i = 0; i <= position; ++i) {
    if (!source->read(frame)) {
      throw InputError(source->description() + ": has " + std::to_string(i) +
                       " frames, so there is no frame " + std::to_string(position) +
                       " (--frame counts from 0)");
    }
  }
  return frame;
}

InitResult RunInit(const InitOptions& options) {
  CheckOutputs({{"-o", options.config_out},
                {"--picture", options.picture_out.value_or(PictureBeside(options.config_out))}},
               options.source);
  const Frame frame = ReadFrameAt(options.source, options.frame);
  MarkerFinderOptions finder = options.finder;
  // The rois apply from this frame on: the index `track` will give it (an image sequence's
  // numbering, a video's position).
  finder.frame_index = frame.index;
  InitResult result;
  result.finding = FindMarkers(frame.image, finder);
  MarkerFinding& finding = result.finding;
  if (options.frame > 0) {
    // A marker told apart by its colour alone needs no roi: without one `track` follows it from
    // the input's first frame, where a roi (holding from this frame on) would leave it not
    // started. Identical markers and markers among look-alikes outside a search region keep theirs.
    for (FoundMarker& m : finding.markers) {
      if (!m.needs_roi && !finding.intensity && !finder.search_px) {
        m.spec.params.get<ColourParams>().roi.reset();
      }
    }
  }
  if (finding.ok() && finding.markers.size() >= 2 && !finder.base_near_px) {
    // The base is where the body is clamped: the video shows it better than the image border.
    std::string seen;
    const std::optional<bool> last_fixed = LastEndIsFixed(options, finding, &seen);
    if (last_fixed && *last_fixed) ReverseBodyOrder(&finding);
    const auto base_note =
        std::find_if(finding.notes.begin(), finding.notes.end(),
                     [](const std::string& note) { return note.rfind("base: ", 0) == 0; });
    if (base_note != finding.notes.end()) {
      *base_note = "base: " + finding.markers.front().spec.name +
                   (last_fixed ? " (the end that stays put: " + seen + ")"
                               : " (the end nearer the image border, as the video does not show "
                                 "which end is fixed: " + seen + "; --base X,Y chooses)");
    }
  }

  result.picture_file = options.picture_out.value_or(PictureBeside(options.config_out));
  const cv::Mat picture = DrawMarkerFinding(frame.image, result.finding);
  bool written = false;
  try {
    written = cv::imwrite(result.picture_file, picture);
  } catch (const cv::Exception&) {
    written = false;
  }
  if (!written) {
    throw InputError(result.picture_file + ": cannot write the picture (use .png or .jpg, and a "
                     "folder that exists)");
  }
  if (!result.finding.ok()) {
    throw InputError("frame " + std::to_string(options.frame) + " of " + options.source.input +
                     ": " + result.finding.problem + "; picture: " + result.picture_file);
  }
  for (const FoundMarker& m : result.finding.markers) result.config.markers.push_back(m.spec);
  result.config.measure = result.finding.measure;
  SaveTrackingConfig(result.config, options.config_out);
  // What track will read: the file must load as it was meant (a failure here is a bug).
  result.config = LoadTrackingConfig(options.config_out);
  return result;
}

TrackingConfig RunPick(const PickOptions& options) {
  if (options.at_px.empty()) throw InputError("--at: give at least one point X,Y");
  std::vector<PathRole> outputs{{"-o", options.config_out}};
  CheckOutputs(outputs, options.source, options.base_config);
  TrackingConfig config;
  if (options.base_config) {
    config = LoadTrackingConfig(*options.base_config);
    if (options.at_px.size() > config.markers.size()) {
      throw InputError("--at: " + std::to_string(options.at_px.size()) + " points for the " +
                       std::to_string(config.markers.size()) + " markers of " +
                       *options.base_config + " (one point per marker, in its order)");
    }
  }
  const Frame frame = ReadFrameAt(options.source, options.frame);
  if (frame.image.type() != CV_8UC3) throw InputError(options.source.input + ": not a BGR video");
  // The live window's defaults: what a click there gives.
  const LiveOptions live;
  for (size_t i = 0; i < options.at_px.size(); ++i) {
    const cv::Point2d& at = options.at_px[i];
    char where[64];
    std::snprintf(where, sizeof(where), "%g,%g", at.x, at.y);
    std::string why;
    const auto pick = PickMarkerColourAt(frame.image, at, live.picker, live.select_box_px, &why);
    if (!pick) {
      throw InputError("--at " + std::string(where) + " in frame " +
                       std::to_string(options.frame) + ": " + why);
    }
    // The pick's roi holds from this frame on (at frame 0 the marker may have been elsewhere).
    const int roi_frame = static_cast<int>(std::clamp<int64_t>(frame.index, 0, 1000000000));
    if (options.base_config) {
      // A template marker becomes a colour marker: the pick is its colour.
      ColourParams colour;
      if (const auto* had = config.markers[i].params.get_if<ColourParams>()) colour = *had;
      ApplyColourPick(*pick, &colour);
      colour.roi_frame = roi_frame;
      config.markers[i].params = colour;
    } else {
      MarkerSpec spec;
      ColourParams& colour = spec.params.emplace<ColourParams>();
      ApplyColourPick(*pick, &colour);
      colour.roi_frame = roi_frame;
      std::string name = PickName(pick->ranges);
      int same = 0;
      for (const MarkerSpec& m : config.markers) {
        if (m.name == name || m.name.rfind(name + "_", 0) == 0) ++same;
      }
      if (same > 0) name += "_" + std::to_string(same + 1);
      spec.name = name;
      config.markers.push_back(spec);
    }
  }
  if (!options.base_config) config.measure = BodyMeasure(config.markers);
  SaveTrackingConfig(config, options.config_out);
  return LoadTrackingConfig(options.config_out);
}

namespace {

// What init's and pick's flags set until they run.
struct InitArgs {
  InitOptions options;
  std::optional<std::string> roi, base;
  std::optional<int> markers;
};
struct PickArgs {
  PickOptions options;
  std::vector<std::string> at;
};

// The frame init and pick read and the config they write: -i, --frame, -o and --fps, in
// `options` of Args (its source, frame and config_out).
template <typename Args>
FlagTable<Args> OneFrameFlags(const std::string& frame_help) {
  return {
      ValueFlag<Args>(kInputFlag, [](Args& a) -> auto& { return a.options.source.input; })
          .Help("Video file, folder of images, printf pattern (frames/%04d.png) or synth:NAME")
          .Required(),
      ValueFlag<Args>("--frame", [](Args& a) -> auto& { return a.options.frame; })
          .Help(frame_help)
          .ShowDefault()
          .Check(NumberIn(0, 1e12)),
      OutputFlag<Args>([](Args& a) -> auto& { return a.options.config_out; }, "out",
                       "The config to write (YAML)")
          .ShowDefault(),
      SequenceFpsFlag<Args>([](Args& a) -> auto& { return a.options.source.sequence_fps; },
                            "Frame rate of an image sequence"),
  };
}

const FlagTable<InitArgs>& InitFlags() {
  using A = InitArgs;
  static const FlagTable<InitArgs> table = [] {
    FlagTable<InitArgs> flags = OneFrameFlags<A>(
        "Which frame to analyse, counting from 0. After the first, markers told apart by colour "
        "get no roi (track finds them from the first frame); dots and --roi finds get a roi from "
        "this frame on (not started before it)");
    const FlagTable<InitArgs> own = {
        ValueFlag<A>("--picture", [](A& a) -> auto& { return a.options.picture_out; })
            .Help("The picture of what was found and rejected (default: the config's name .png)"),
        ValueFlag<A>("--roi", &A::roi)
            .Help("Look only inside X,Y,W,H (the actuator's area): look-alikes elsewhere are "
                  "ignored, and each marker gets a roi"),
        ValueFlag<A>("--markers", &A::markers)
            .Help("How many markers the body carries: any other count found is an error")
            .Check(NumberIn(1, 64)),
        ValueFlag<A>("--base", &A::base)
            .Help("X,Y near the base (the fixed end). Default: the end that stays put over the "
                  "next 90 frames, else the end nearer the image border"),
    };
    flags.insert(flags.end(), own.begin(), own.end());
    return flags;
  }();
  return table;
}

const FlagTable<PickArgs>& PickFlags() {
  using A = PickArgs;
  static const FlagTable<PickArgs> table = [] {
    FlagTable<PickArgs> flags = OneFrameFlags<A>("Which frame, counting from 0");
    const FlagTable<PickArgs> own = {
        ValueFlag<A>("--at", &A::at)
            .Help("X,Y of a marker's centre in pixels (repeat per marker)")
            .Required(),
        ValueFlag<A>(kConfigFlag, [](A& a) -> auto& { return a.options.base_config; })
            .Help("Update this config's markers in order instead of writing new ones")
            .Check(CLI::ExistingFile),
    };
    flags.insert(flags.end(), own.begin(), own.end());
    return flags;
  }();
  return table;
}

}  // namespace

CommandRunner SetupInitCommand(CLI::App& sub) {
  auto args = std::make_shared<InitArgs>();
  sub.description(
      "Write a marker config without a GUI: find the markers in one frame by themselves\n"
      "(compact, saturated blobs of distinct colours; else white or black dots), take\n"
      "each one's HSV range from its own pixels (as a click in `live` does), order them from\n"
      "base (the end that stays put in the frames that follow) to tip, and write the config\n"
      "(markers, roi, triple or chain) plus a picture of what was found (green rings, numbered\n"
      "base to tip) and what was rejected (red crosses with the reason). A marker is written\n"
      "only when a tracker built from its range finds exactly that blob. Look-alikes of one\n"
      "colour, no marker at all, blobs unlike one body's markers or an unclear order: init\n"
      "writes no config, says why and exits 2. Check the picture, then run `softsight track`.\n"
      "Examples:\n"
      "  softsight init --input run.avi -o markers.yaml        (also writes markers.png)\n"
      "  softsight init --input run.avi --roi 100,40,400,380 --markers 3 -o markers.yaml");
  AddFlags(sub, InitFlags(), args.get());
  return [args] {
    InitOptions options = args->options;
    if (args->roi) options.finder.search_px = ParseRectOption(*args->roi, "--roi");
    if (args->base) options.finder.base_near_px = ParsePointOption(*args->base, "--base");
    options.finder.expected_count = args->markers;
    const LiveOptions live;  // The live window's click pick and search box.
    options.finder.picker = live.picker;
    options.finder.roi_side_px = live.select_box_px;
    InitResult result;
    try {
      result = RunInit(options);
    } catch (const InputError&) {
      throw;  // Reported once, by main(); the picture (if written) says more.
    }
    const MarkerFinding& f = result.finding;
    for (size_t i = 0; i < f.markers.size(); ++i) {
      const FoundMarker& m = f.markers[i];
      char line[256];
      std::snprintf(line, sizeof(line), "%zu %s at (%.2f, %.2f), radius %.1f px: ", i + 1,
                    m.spec.name.c_str(), m.position_px.x, m.position_px.y, m.radius_px);
      std::cout << line << Describe(m.spec.params.get<ColourParams>()) << "\n";
    }
    if (result.config.measure.has_triple()) {
      std::cout << "triple: " << result.config.measure.base << ", "
                << result.config.measure.middle << ", " << result.config.measure.tip
                << (result.config.measure.chain.empty() ? "" : " (and the chain of all)") << "\n";
    }
    for (const std::string& note : f.notes) std::cout << "note: " << note << "\n";
    std::cout << "rejected " << f.rejected.size() << " other blobs (see the picture)\n"
              << "wrote " << options.config_out << " and " << result.picture_file << "\n"
              << "next: softsight track --config " << options.config_out << " --input "
              << options.source.input << " -o run.csv\n";
    return 0;
  };
}

CommandRunner SetupPickCommand(CLI::App& sub) {
  auto args = std::make_shared<PickArgs>();
  sub.description(
      "Write HSV ranges for markers at given pixels of one frame, exactly as a click on them in\n"
      "`live` gives (the same pick: the pixels within 5 px of the point, and a 32 px search box\n"
      "around it as the marker's roi). Give one --at per marker, base first: new markers are\n"
      "named by their colour (three make the paper's triple, more a chain), or with --config\n"
      "the config's markers get the colours in their order.\n"
      "Examples:\n"
      "  softsight pick --input run.avi --frame 0 --at 212,300 --at 300,250 --at 390,300 -o m.yaml\n"
      "  softsight pick --input run.avi --config markers.yaml --at 212,300 -o markers2.yaml");
  AddFlags(sub, PickFlags(), args.get());
  return [args] {
    PickOptions options = args->options;
    for (const std::string& at : args->at) options.at_px.push_back(ParsePointOption(at, "--at"));
    const TrackingConfig config = RunPick(options);
    for (size_t i = 0; i < options.at_px.size(); ++i) {
      const MarkerSpec& m = config.markers[i];
      std::cout << m.name << ": " << Describe(m.params.get<ColourParams>()) << "\n";
    }
    std::cout << "wrote " << options.config_out << "\n";
    return 0;
  };
}

}  // namespace softsight
