#include "app/track_stereo_command.h"

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>

#include "app/cli_checks.h"
#include "app/commands.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/config/config.h"
#include "softsight/core/error.h"
#include "softsight/io/csv_writer.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/output_guard.h"
#include "softsight/pipeline/stereo_session.h"
#include "softsight/track/colour_tracker.h"
#include "track/tracker_kind.h"

namespace softsight {
namespace {

TrackingConfig LoadStereoViewConfig(const std::string& file) {
  TrackingConfig config = LoadTrackingConfig(file);
  for (const MarkerSpec& spec : config.markers) {
    if (const auto missing = spec.params.kind().missing_for_batch(spec.params)) {
      throw InputError(file + ": marker '" + spec.name + "' " + *missing);
    }
  }
  return config;
}

std::optional<double> Median(std::vector<double>& values) {
  if (values.empty()) return std::nullopt;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace

TrackStereoSummary RunTrackStereo(const TrackStereoOptions& options, std::ostream& report) {
  if (options.csv_file.empty()) throw InputError("--csv: give the file to write");
  if (options.max_frames && *options.max_frames < 0) {
    throw InputError("--max-frames " + std::to_string(*options.max_frames) + ": must be 0 or more");
  }
  const TrackingConfig left_config = LoadStereoViewConfig(options.config_file);
  const TrackingConfig right_config =
      options.right_config_file ? LoadStereoViewConfig(*options.right_config_file) : left_config;
  const StereoCalibration stereo = LoadStereoCalibration(options.stereo_file);
  StereoOptions stereo_options;
  stereo_options.triangulation.max_epipolar_px = options.max_epipolar_px;
  stereo_options.reference_plane =
      ParseReferencePlane(options.reference_plane, "--reference-plane");
  std::string error;
  if (!stereo_options.Check(&error)) throw InputError("--max-epipolar-px: " + error);

  FrameSourceSpec left_spec, right_spec;
  left_spec.input = options.left_input;
  right_spec.input = options.right_input;
  left_spec.sequence_fps = right_spec.sequence_fps = options.sequence_fps;
  const std::unique_ptr<FrameSource> left = OpenFrameSource(left_spec);
  const std::unique_ptr<FrameSource> right = OpenFrameSource(right_spec);

  std::vector<PathRole> inputs = ConfigInputs(left_config);
  if (options.right_config_file) {
    for (PathRole& role : ConfigInputs(right_config)) inputs.push_back(std::move(role));
  }
  inputs.push_back({"--stereo", options.stereo_file});
  for (const std::string& file : left->files()) inputs.push_back({"--left", file});
  for (const std::string& file : right->files()) inputs.push_back({"--right", file});
  CheckOutputsAreNotInputs({{"--csv", options.csv_file}}, inputs);

  // Markers move in depth before two cameras: seen smaller than learned, a colour marker with the
  // rim fit is taken as partly hidden and placed by a circle of its old size (up to 1 px off,
  // 2 mm in depth at 300 mm; docs/stereo.md). Said, not overridden: the config decides.
  std::string rim_fitted;
  for (const MarkerSpec& spec : left_config.markers) {
    const auto* colour = spec.params.get_if<ColourParams>();
    if (colour != nullptr && colour->rim_fit)
      rim_fitted += (rim_fitted.empty() ? "" : ", ") + spec.name;
  }
  if (!rim_fitted.empty()) {
    report << "note: " << rim_fitted << " use the rim fit (rim_fit: true); for markers moving in "
           << "depth set rim_fit: false (docs/stereo.md)\n";
  }

  StereoSession session(left_config, right_config, stereo, stereo_options);
  const std::vector<std::string> names = session.marker_names();

  // The offset: the first |offset| frames of the view that started earlier have no partner.
  Frame left_frame, right_frame;
  FrameSource& ahead = options.frame_offset > 0 ? *right : *left;
  for (int64_t skipped = 0; skipped < std::abs(options.frame_offset); ++skipped) {
    if (!ahead.read(options.frame_offset > 0 ? right_frame : left_frame)) {
      throw InputError("--frame-offset " + std::to_string(options.frame_offset) + ": " +
                       ahead.description() + " has only " + std::to_string(skipped) + " frames");
    }
  }

  BasicCsvWriter<StereoFrameResult> csv(options.csv_file, StereoColumns(names));
  TrackStereoSummary summary;
  summary.found.assign(names.size(), {"", 0});
  summary.epipolar.assign(names.size(), {"", 0});
  for (size_t i = 0; i < names.size(); ++i)
    summary.found[i].first = summary.epipolar[i].first = names[i];
  std::vector<double> sigmas, epipolar_distances;
  std::optional<std::string> ended;
  while (!options.max_frames || summary.pairs < *options.max_frames) {
    const bool have_left = left->read(left_frame);
    const bool have_right = have_left && right->read(right_frame);
    if (!have_left || !have_right) {
      if (have_left) ended = right->description() + " ended first";
      break;
    }
    const StereoFrameResult& result = session.process(left_frame, right_frame);
    csv.write(result);
    ++summary.pairs;
    for (size_t i = 0; i < result.markers.size(); ++i) {
      const StereoPoint& p = result.markers[i].point;
      if (p.found()) {
        ++summary.found[i].second;
        sigmas.push_back(*p.sigma_mm);
      }
      if (p.status == StereoStatus::kEpipolar) ++summary.epipolar[i].second;
      if (p.epipolar_px) epipolar_distances.push_back(*p.epipolar_px);
    }
  }
  summary.median_sigma_mm = Median(sigmas);
  summary.median_epipolar_px = Median(epipolar_distances);

  report << summary.pairs << " pairs of frames (right frame = left frame "
         << (options.frame_offset >= 0 ? "+ " : "- ") << std::abs(options.frame_offset) << ")";
  if (ended) report << "; " << *ended;
  report << "; baseline " << std::fixed << std::setprecision(1) << stereo.baseline_mm() << " mm\n";
  for (size_t i = 0; i < names.size(); ++i) {
    report << "  " << names[i] << ": found in 3D in " << summary.found[i].second << " of "
           << summary.pairs;
    if (summary.epipolar[i].second > 0) {
      report << " (" << summary.epipolar[i].second << " refused by the epipolar check)";
    }
    report << "\n";
  }
  report << std::setprecision(3);
  if (summary.median_epipolar_px) {
    report << "epipolar distance: median " << *summary.median_epipolar_px << " px (limit "
           << options.max_epipolar_px << ")";
  }
  if (summary.median_sigma_mm)
    report << "; 3D uncertainty: median " << *summary.median_sigma_mm << " mm";
  report << "\nwrote " << options.csv_file << "\n";
  report.unsetf(std::ios::floatfield);
  return summary;
}

CommandRunner SetupTrackStereoCommand(CLI::App& sub) {
  auto options = std::make_shared<TrackStereoOptions>();
  sub.description(
      "Track the markers in two synchronised videos of a calibrated pair of cameras and write\n"
      "their 3D positions (mm, first camera's frame) and the 3D measurements, one CSV row per\n"
      "pair of frames: the angle at the middle marker, the bending plane and its angle out of\n"
      "the reference plane, radius and arc length of the 3D circle, tip displacement.\n"
      "A marker is found in 3D only when both views found it and the pair passes the\n"
      "epipolar check (docs/stereo.md).\n"
      "Example:\n"
      "  softsight calibrate --left cal/left/ --right cal/right/ --chessboard 9x6 --square-mm 25 "
      "--out stereo.yaml\n"
      "  softsight track-stereo -c markers.yaml --left left.avi --right right.avi "
      "--stereo stereo.yaml --csv run3d.csv");
  sub.add_option("-c,--config", options->config_file, "Marker config (YAML), see examples/")
      ->required()
      ->check(CLI::ExistingFile);
  sub.add_option("--right-config", options->right_config_file,
                 "The right view's marker config, when its colours or rois differ (same names)")
      ->check(CLI::ExistingFile);
  sub.add_option("--left", options->left_input, "The first camera's video (or image sequence)")
      ->required();
  sub.add_option("--right", options->right_input, "The second camera's video (or image sequence)")
      ->required();
  sub.add_option("--stereo", options->stereo_file,
                 "The rig from `softsight calibrate --left ... --right ...`")
      ->required();
  sub.add_option("-o,--csv", options->csv_file, "Where to write the per-frame CSV")->required();
  sub.add_option("--frame-offset", options->frame_offset,
                 "Pair left frame i with right frame i + N (the right camera started N frames "
                 "earlier; negative: later)");
  sub.add_option("--max-epipolar-px", options->max_epipolar_px,
                 "A pair farther than this from its epipolar line is not believed (status "
                 "epipolar)")
      ->capture_default_str()
      ->check(NumberIn(1e-3, 1e3));
  sub.add_option("--reference-plane", options->reference_plane,
                 "The out-of-plane angle against: image (the first camera's image plane) or first "
                 "(the first frame's bending plane)")
      ->capture_default_str();
  sub.add_option("--fps", options->sequence_fps, "Frame rate of image sequences")
      ->capture_default_str()
      ->check(NumberIn(1e-3, 1e6));
  sub.add_option("--max-frames", options->max_frames, "Stop after this many pairs")
      ->check(NumberIn(0, 1e15));
  return [options] {
    RunTrackStereo(*options, std::cout);
    return 0;
  };
}

}  // namespace softsight
