// `softsight evaluate`: a reproducible accuracy and speed comparison of the tracking methods.
//
// Renders a scene in memory (exact truth, no video file) and runs one TrackingSession per method
// over the very same frames: the colour tracker, and each template measure (sad, ssd, zncc) in
// gray and in colour. Each method is configured the way a person would set it up:
//   colour:    HSV thresholds around each marker's hue (ThresholdsFor, shared with `demo`);
//              with sensor noise a Gaussian pre-filter (ksize 5).
//   templates: a square of odd side ~2.6 x marker radius dragged on frame 0, centred on the
//              rounded true centroid, so its centre is off the true centre by up to 0.5 px per
//              axis, as with a mouse.
// See docs/evaluation.md for the metrics.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "softsight/config/config.h"
#include "softsight/io/frame_source.h"
#include "softsight/sim/scene.h"
#include "softsight/track/tracker.h"

namespace softsight {

struct EvaluateOptions {
  SceneOptions scene;            // Kind, size and frame count (default: bending, 300 frames).
  NoiseOptions noise;            // Sensor noise, blur, gain ramp, noise seed.
                                 // (The command line sets noise.seed = scene.seed, as synth does.)
  std::vector<Occluder> occluders;  // Covers drawn over the scene (tests; not on the command line).
  // Methods to compare: any of TrackerMethods() (default all, in the registry's order).
  std::vector<std::string> methods = TrackerMethods();
  // Template matching modes: gray and/or colour (default both). The colour method has no mode.
  std::vector<std::string> modes = {"gray", "colour"};
  // Template trackers report the dragged rectangle's centre (the paper's position) instead of the
  // marker's centre of symmetry (TemplateParams::report). Default off, the library's default.
  bool rect_centre = false;
  // Template trackers match the whole square instead of the disc inscribed in it
  // (TemplateParams::round_mask). Default off: the library matches the disc.
  bool square_mask = false;
  std::optional<std::string> csv_file;  // The table as CSV as well.
  bool quiet = false;            // No progress line.

  // Throws InputError (one line naming the option and the value) when an option is unusable.
  void Check() const;
};

// One method's figures over the whole sequence, from the one truth scorer (sim/truth_score.h):
// "visible" means visible_fraction >= kMustFindVisibleFraction (0.5) in the renderer's truth;
// marker-frames with a smaller visible part count neither as misses nor in the error, since
// finding or losing a mostly covered marker are both acceptable.
struct MethodResult {
  std::string method;               // colour, sad, ssd, zncc
  std::optional<std::string> mode;  // gray or colour for the template methods; absent for colour.
  int64_t visible = 0;              // Marker-frames visible.
  int64_t found_visible = 0;        // ... of which found.
  int64_t misses = 0;               // Visible but not found.
  int64_t hidden = 0;               // Marker-frames fully hidden (visible_fraction == 0).
  int64_t false_reports = 0;        // Found while fully hidden.
  // Absolute error |tracked - true centroid| over the found visible marker-frames; absent when
  // none was found.
  std::optional<double> centroid_rms_px;
  std::optional<double> centroid_max_px;
  std::optional<double> centroid_p95_px;  // 95th percentile of the same errors.
  int64_t wrong_finds = 0;          // Found farther than kWrongFindPx (3 px) from the truth.
  // The reported sigma against the errors (TruthScore): hits with one, within 3, beyond 5.
  int64_t with_sigma = 0, within_3_sigma = 0, beyond_5_sigma = 0;
  // Precision: the same error after subtracting, per marker, the constant offset (tracked - true)
  // measured on the first frame where the marker was found and visible (frame 0 normally): what
  // remains once the half-pixel placement of a dragged template is taken out.
  std::optional<double> precision_rms_px;
  std::optional<double> precision_max_px;
  // Angle (eq. 7) against the truth's angle over frames where both exist; absent when none did.
  std::optional<double> angle_rms_deg;
  int64_t angle_frames = 0;
  double proc_ms_median = 0.0;      // Per frame, all markers: FrameResult::proc_ms.
  double proc_ms_p99 = 0.0;

  std::string label() const;        // "colour", "zncc gray", ...
};

struct EvaluateReport {
  std::string conditions;           // One line: scene, size, frames, noise, blur, gain, seeds
                                    // (background texture / noise).
  int64_t frames = 0;
  std::vector<MethodResult> methods;
};

// Renders the scene and evaluates every requested method. Throws InputError for bad options.
EvaluateReport RunEvaluate(const EvaluateOptions& options);

// The config the built-in comparison gives `method` (and, for templates, `mode`) on the scene of
// `options`, whose frame 0 has the truth `first`: what `evaluate --input` is compared with.
TrackingConfig EvaluateMethodConfig(const std::string& method,
                                    const std::optional<std::string>& mode,
                                    const EvaluateOptions& options, const SceneTruth& first);

// A user's own recording against its own truth: `evaluate --input VIDEO --truth TRUTH.csv
// --config CFG`.
struct VideoEvaluateOptions {
  FrameSourceSpec source;
  std::string truth_csv;   // synth's truth CSV, or any CSV with frame and <name>_x, <name>_y.
  std::string config_file;
  std::optional<std::string> csv_file;  // The table as CSV as well.
  bool quiet = false;
};

// The truth CSV: a `frame` column (the source's frame index, as in track's CSV); per marker
// <name>_x, <name>_y (empty: hidden) and optionally <name>_visible (the visible fraction 0..1;
// absent: 1 where x and y are given, else 0); optionally angle_deg. Config markers are matched
// to the truth's by name; markers the truth does not have are not scored (the report's
// conditions say which). Frames without a truth row are not scored. The one scorer as the
// built-in path (sim/truth_score.h), so a rendered video with synth's truth gives the built-in
// figures. Throws InputError naming the file and column.
EvaluateReport RunVideoEvaluate(const VideoEvaluateOptions& options);

// The report as a Markdown table, ready to paste in the README (with the conditions above it).
std::string FormatEvaluateMarkdown(const EvaluateReport& report);

// The report as CSV (one row per method); throws InputError naming the file when it can't write.
void WriteEvaluateCsv(const EvaluateReport& report, const std::string& file);

// Parses "--gain-ramp" text "START,END" (two positive numbers); throws InputError.
void ParseGainRamp(const std::string& text, NoiseOptions* noise);

}  // namespace softsight
