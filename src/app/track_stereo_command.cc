#include "app/track_stereo_command.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>

#include <opencv2/imgcodecs.hpp>

#include "app/capture_options.h"
#include "app/cli_checks.h"
#include "app/commands.h"
#include "app/publish_options.h"
#include "app/shared_flags.h"
#include "app/stop_request.h"
#include "softsight/calib/board_frame.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/config/config.h"
#include "softsight/core/error.h"
#include "softsight/io/csv_writer.h"
#include "softsight/io/frame_offset.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/output_guard.h"
#include "softsight/io/run_source.h"
#include "softsight/io/stereo_input.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/stereo_session.h"
#include "softsight/pipeline/summary.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/tracker_kind.h"

namespace softsight {

TrackingConfig LoadStereoViewConfig(const std::string& file) {
  TrackingConfig config = LoadTrackingConfig(file);
  for (const MarkerSpec& spec : config.markers) {
    if (const auto missing = spec.params.kind().missing_for_batch(spec.params)) {
      throw InputError(file + ": marker '" + spec.name + "' " + *missing);
    }
  }
  return config;
}

namespace {

std::optional<double> Median(std::vector<double>& values) {
  if (values.empty()) return std::nullopt;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace

namespace {

void CheckOptions(const TrackStereoOptions& options) {
  if (options.csv_file.empty()) throw InputError("--csv: give the file to write");
  if (!options.bench_board.empty() && options.bench_board.size() != 2) {
    throw InputError("--bench-board: give two images, the left and the right view of the board");
  }
  if (options.bench_board.empty() && (!options.chessboard.empty() || options.square_mm)) {
    throw InputError(std::string(options.chessboard.empty() ? "--square-mm" : "--chessboard") +
                     " describes the --bench-board board; give --bench-board LEFT RIGHT");
  }
  if (options.max_frames && *options.max_frames < 0) {
    throw InputError("--max-frames " + std::to_string(*options.max_frames) + ": must be 0 or more");
  }
  if (ParseReferencePlane(options.reference_plane, "--reference-plane") ==
          StereoOptions::ReferencePlane::kBoard &&
      options.bench_board.empty()) {
    throw InputError("--reference-plane board: the bench board's plane; give --bench-board LEFT "
                     "RIGHT (one pair of images of the board lying on the bench)");
  }
}

FrameSourceSpec SpecOf(const std::string& input, double fps) {
  FrameSourceSpec spec;
  spec.input = input;
  spec.sequence_fps = fps;
  return spec;
}

// A source as a run reads it: a camera in its own thread (newest frame), a file decoded ahead.
std::unique_ptr<FrameSource> Open(const FrameSourceSpec& spec) {
  return SourceForRun(OpenFrameSource(spec), FilePacing::kReadAhead);
}

// Finds the frame offset from a flash or the motion (io/frame_offset.h), reports it, or refuses
// in one line.
int64_t FindAndReportFrameOffset(const TrackStereoOptions& options,
                                 const FrameSourceSpec& left_spec,
                                 const FrameSourceSpec& right_spec, std::ostream& report) {
  FrameOffsetOptions offset_options;
  offset_options.max_offset_frames = options.max_offset_frames;
  std::string error;
  if (!offset_options.Check(&error)) throw InputError("--max-offset-frames: " + error);
  // The frames the run can use, and the offset's worth beyond them.
  std::optional<int64_t> frames;
  if (options.max_frames) frames = *options.max_frames + options.max_offset_frames;
  const FrameOffsetEstimate estimate = FindFrameOffset(
      *OpenFrameSource(left_spec), *OpenFrameSource(right_spec), offset_options, frames);
  report << DescribeFrameOffset(estimate, offset_options) << "\n";
  return *estimate.offset_frames;
}

// The pairs the options ask for, the offset found when it is needed.
std::unique_ptr<StereoInput> OpenStereoInput(const TrackStereoOptions& options,
                                             TrackStereoSummary& summary, std::ostream& report) {
  const bool cameras = options.left_camera || options.right_camera;
  const bool files = !options.left_input.empty() || !options.right_input.empty();
  if (int(cameras) + int(files) + int(options.side_by_side.has_value()) != 1) {
    throw InputError(
        "give the two views one way: --left and --right, --side-by-side, or --left-camera and "
        "--right-camera");
  }
  if (options.pair_by != "index" && options.pair_by != "time") {
    throw InputError("--pair-by: expected index or time, got '" + options.pair_by + "'");
  }
  const bool by_time = options.pair_by == "time" || cameras;
  if (!std::isfinite(options.time_offset_ms)) throw InputError("--time-offset-ms: must be finite");
  if (by_time && options.frame_offset) {
    throw InputError("--frame-offset pairs by index; with --pair-by time give --time-offset-ms");
  }
  if (options.side_by_side) {
    if (options.frame_offset.value_or(0) != 0 || options.pair_by == "time") {
      throw InputError("--side-by-side: both views are in one frame (no --frame-offset or "
                       "--pair-by time)");
    }
    return SplitSideBySide(Open(SpecOf(*options.side_by_side, options.sequence_fps)));
  }
  if (cameras) {
    if (!options.left_camera || !options.right_camera) {
      throw InputError("--left-camera and --right-camera: give both");
    }
    FrameSourceSpec left, right;
    left.camera = options.left_camera;
    right.camera = options.right_camera;
    TimePairingOptions pairing;
    pairing.clock = TimePairingOptions::Clock::kCaptureTime;
    pairing.time_offset_ms = options.time_offset_ms;
    return PairByTime(Open(left),
                      Open(right), pairing);
  }
  if (options.left_input.empty() || options.right_input.empty()) {
    throw InputError(std::string(options.left_input.empty() ? "--left" : "--right") +
                     ": give both views' videos (or --side-by-side)");
  }
  const FrameSourceSpec left_spec = SpecOf(options.left_input, options.sequence_fps);
  const FrameSourceSpec right_spec =
      SpecOf(options.right_input, options.right_sequence_fps.value_or(options.sequence_fps));
  TimePairingOptions pairing;
  pairing.time_offset_ms = options.time_offset_ms;
  if (by_time) return PairByTime(Open(left_spec), Open(right_spec), pairing);
  // Frame i with frame i + offset is one moment only when both views run at one rate: a 30 fps
  // and a 15 fps view paired by index drift apart (the 3D points of every pair but the first are
  // of two moments), and the offset search between them finds a confident wrong offset. Two
  // rates are paired by time unless --frame-offset says to pair by index all the same.
  std::unique_ptr<FrameSource> left = Open(left_spec), right = Open(right_spec);
  const std::optional<double> left_fps = left->fps(), right_fps = right->fps();
  if (left_fps && right_fps &&
      std::abs(*left_fps - *right_fps) > 1e-3 * std::max(*left_fps, *right_fps)) {
    report << "note: the left view runs at " << ShortNumber(*left_fps) << " fps and the right at "
           << ShortNumber(*right_fps) << " fps: "
           << (options.frame_offset
                   ? "paired by index all the same, as --frame-offset asks (--pair-by time "
                     "pairs the frames of one moment)\n"
                   : "paired by time (each left frame with the right frame nearest in time); "
                     "--frame-offset N pairs by index instead\n");
    if (!options.frame_offset) return PairByTime(std::move(left), std::move(right), pairing);
  }
  const int64_t offset = options.frame_offset
                             ? *options.frame_offset
                             : FindAndReportFrameOffset(options, left_spec, right_spec, report);
  summary.frame_offset = offset;
  return PairByIndex(std::move(left), std::move(right), offset, "--frame-offset");
}

// The board of --bench-board: --chessboard and --square-mm, else the stereo file's.
ChessboardSpec BenchBoardSpec(const TrackStereoOptions& options) {
  const std::optional<ChessboardSpec> stored = LoadStereoCalibrationBoard(options.stereo_file);
  if ((options.chessboard.empty() || !options.square_mm) && !stored) {
    throw InputError("--bench-board: " + options.stereo_file +
                     " does not say which board it was calibrated with; give --chessboard WxH "
                     "--square-mm S");
  }
  ChessboardSpec board = stored.value_or(ChessboardSpec{});
  if (!options.chessboard.empty()) {
    board.inner_corners = ParseChessboardSize(options.chessboard, "--chessboard");
  }
  if (options.square_mm) {
    if (!(std::isfinite(*options.square_mm) && *options.square_mm > 0.0)) {
      throw InputError("--square-mm: must be the printed square's side in mm (> 0)");
    }
    board.square_mm = *options.square_mm;
  }
  return board;
}

// Finds the bench board in its two images and fits its frame, or refuses in one line.
BoardFrame FindBenchBoard(const TrackStereoOptions& options, const StereoCalibration& stereo,
                          const TriangulationOptions& triangulation) {
  const ChessboardSpec board = BenchBoardSpec(options);
  const std::string& left_file = options.bench_board[0];
  const std::string& right_file = options.bench_board[1];
  const cv::Mat left = cv::imread(left_file, cv::IMREAD_COLOR);
  const cv::Mat right = cv::imread(right_file, cv::IMREAD_COLOR);
  return LocateBenchBoard(Triangulator(stereo, triangulation), board, left_file, left, right_file,
                          right);
}

// What the command returns: the run's counts, the figures only a pair has, the pairing.
TrackStereoSummary Summarise(const RunSummary& run, const StereoRunFigures& figures,
                             const StereoInput& input, const std::vector<std::string>& names,
                             std::optional<int64_t> frame_offset,
                             const std::optional<BoardFrame>& bench) {
  TrackStereoSummary summary;
  summary.frame_offset = frame_offset;
  summary.pairs = run.frames;
  summary.stopped = run.stop_reason == StopReason::kStopRequested;
  for (size_t i = 0; i < names.size(); ++i) {
    summary.found.emplace_back(names[i], run.markers[i].found);
    summary.epipolar.emplace_back(names[i], figures.epipolar[i]);
    summary.timing.emplace_back(names[i], figures.timing[i]);
  }
  if (bench) summary.bench_board_rms_mm = bench->rms_mm;
  summary.max_abs_pair_dt_ms = figures.max_abs_pair_dt_ms;
  std::vector<double> sigmas = figures.sigma_mm, epipolar_distances = figures.epipolar_px;
  std::vector<double> lags = figures.lag_frames;
  summary.median_sigma_mm = Median(sigmas);
  summary.median_epipolar_px = Median(epipolar_distances);
  summary.lagging_pairs = static_cast<int64_t>(lags.size());
  summary.median_lag_frames = Median(lags);
  // One wrong offset lags by one amount all along; two frame rates or a dropped frame by a
  // changing one (no single offset then pairs one moment).
  if (lags.size() >= 4) {
    std::sort(lags.begin(), lags.end());
    summary.steady_lag = lags[lags.size() * 3 / 4] - lags[lags.size() / 4] <= 0.5;
  }
  summary.left_unpaired = input.left_unpaired();
  summary.right_unpaired = input.right_unpaired();

  return summary;
}

// The report: the pairs and how they were paired, each marker found in 3D, the medians, the
// CSV's frame, the notes.
void PrintReport(const TrackStereoOptions& options, const TrackStereoSummary& summary,
                 const RunSummary& run, const StereoInput& input, const StereoCalibration& stereo,
                 const StereoOptions& stereo_options, const std::vector<std::string>& names,
                 std::ostream& report) {
  report << summary.pairs << " pairs of frames";
  if (summary.max_abs_pair_dt_ms) {
    report << " (paired by time; left out without a partner within half a frame interval: "
           << summary.left_unpaired << " left, " << summary.right_unpaired << " right frames";
    if (summary.max_abs_pair_dt_ms) {
      report << "; pairing error up to " << std::fixed << std::setprecision(1)
             << *summary.max_abs_pair_dt_ms << " ms";
    }
    report << ")";
  } else if (summary.left_unpaired > 0 || summary.right_unpaired > 0) {
    const int64_t offset = summary.right_unpaired - summary.left_unpaired;
    report << " (right frame = left frame " << (offset >= 0 ? "+ " : "- ") << std::abs(offset)
           << ")";
  } else {
    report << " (right frame = left frame + 0)";
  }
  if (summary.stopped) {
    report << "; " << run.stop_detail;
  } else if (const std::optional<std::string> ended = input.ended_first()) {
    report << "; " << *ended;
  }
  report << "; baseline " << std::fixed << std::setprecision(1) << stereo.baseline_mm() << " mm\n";
  for (size_t i = 0; i < names.size(); ++i) {
    report << "  " << names[i] << ": found in 3D in " << summary.found[i].second << " of "
           << summary.pairs;
    if (summary.epipolar[i].second > 0 || summary.timing[i].second > 0) {
      report << " (";
      if (summary.epipolar[i].second > 0) {
        report << summary.epipolar[i].second << " refused by the epipolar check";
      }
      if (summary.timing[i].second > 0) {
        report << (summary.epipolar[i].second > 0 ? ", " : "") << summary.timing[i].second
               << " by the pairing check (timing)";
      }
      report << ")";
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
  report << "\nwrote " << options.csv_file;
  if (stereo_options.results_in_board) {
    report << ": <m>_X/_Y/_Z and plane_n* in the bench board's frame (origin at its first inner "
              "corner, X along its first row, Y along its columns, Z into the bench)";
  } else {
    report << ": <m>_X/_Y/_Z in the first camera's frame";
  }
  if (stereo_options.reference_plane == StereoOptions::ReferencePlane::kBoard) {
    report << "; out_of_plane_deg against the bench board's plane";
  }
  report << "\n";
  for (const std::string& note : run.notes) report << "note: " << note << "\n";
  if (summary.median_lag_frames) {
    // A moving marker's right point lies where the marker was some frames before or after: on
    // its epipolar line while it moves along the line, at a wrong depth. Said once, with what
    // would pair one moment.
    const double lag = *summary.median_lag_frames;
    report << "note: in " << summary.lagging_pairs << " of " << summary.pairs
           << " pairs the markers' motion says the right frame is about " << std::fixed
           << std::setprecision(1) << std::abs(lag) << " frames " << (lag > 0 ? "later" : "earlier")
           << " than the left one (moving markers there: status timing, not found in 3D)";
    if (summary.frame_offset && summary.steady_lag) {
      const int64_t better = *summary.frame_offset - std::llround(lag);
      report << "; the frame offset " << *summary.frame_offset
             << " looks wrong: try --frame-offset " << better;
    } else if (summary.frame_offset) {
      report << "; the frame offset " << *summary.frame_offset
             << " looks wrong: leave --frame-offset out to have it found from the motion (two "
                "frame rates: --pair-by time)";
    } else {
      report << "; the two views are not paired at one moment (their clocks or --time-offset-ms?)";
    }
    report << "\n";
  }
  report.unsetf(std::ios::floatfield);
}

// The run on `input`; `bench` is the bench board's frame when already located.
TrackStereoSummary Run(const TrackStereoOptions& options, StereoInput& input,
                       std::ostream& report, std::optional<BoardFrame> bench,
                       const StereoRunHooks& hooks, std::optional<int64_t> frame_offset);

}  // namespace

TrackStereoSummary RunTrackStereo(const TrackStereoOptions& options, std::ostream& report,
                                  const StereoRunHooks& hooks) {
  CheckOptions(options);
  // The bench board first: a refusal should not wait for the frame offset to be found.
  std::optional<BoardFrame> bench;
  if (!options.bench_board.empty()) {
    TriangulationOptions triangulation;
    triangulation.max_epipolar_px = options.max_epipolar_px;
    std::string error;
    if (!triangulation.Check(&error)) throw InputError("--max-epipolar-px: " + error);
    bench = FindBenchBoard(options, LoadStereoCalibration(options.stereo_file), triangulation);
  }
  TrackStereoSummary summary;
  const std::unique_ptr<StereoInput> input = OpenStereoInput(options, summary, report);
  const std::optional<int64_t> offset = summary.frame_offset;
  summary = Run(options, *input, report, bench, hooks, offset);
  return summary;
}

TrackStereoSummary RunTrackStereo(const TrackStereoOptions& options, StereoInput& input,
                                  std::ostream& report, const StereoRunHooks& hooks) {
  CheckOptions(options);
  return Run(options, input, report, std::nullopt, hooks, std::nullopt);
}

namespace {

TrackStereoSummary Run(const TrackStereoOptions& options, StereoInput& input,
                       std::ostream& report, std::optional<BoardFrame> bench,
                       const StereoRunHooks& hooks, std::optional<int64_t> frame_offset) {
  const TrackingConfig left_config = LoadStereoViewConfig(options.config_file);
  const TrackingConfig right_config =
      options.right_config_file ? LoadStereoViewConfig(*options.right_config_file) : left_config;
  const StereoCalibration stereo = LoadStereoCalibration(options.stereo_file);
  StereoOptions stereo_options;
  stereo_options.triangulation.max_epipolar_px = options.max_epipolar_px;
  stereo_options.reference_plane =
      ParseReferencePlane(options.reference_plane, "--reference-plane");
  if (!options.bench_board.empty()) {
    if (!bench) bench = FindBenchBoard(options, stereo, stereo_options.triangulation);
    // Its Z axis in the first camera's frame (kBoard's reference; unused otherwise).
    stereo_options.board_normal =
        cv::Vec3d(bench->rotation(0, 2), bench->rotation(1, 2), bench->rotation(2, 2));
    const cv::Vec3d o = bench->origin_mm;
    report << std::fixed << std::setprecision(1) << "bench board " << options.bench_board[0]
           << " / " << options.bench_board[1] << ": " << bench->corners
           << " corners, fitted to " << std::setprecision(3) << bench->rms_mm << " mm RMS (max "
           << bench->max_mm << " mm); its origin at (" << std::setprecision(1) << o[0] << ", "
           << o[1] << ", " << o[2] << ") mm in the first camera's frame\n";
    report.unsetf(std::ios::floatfield);
    report << std::setprecision(6);
  }
  std::string error;
  if (!stereo_options.Check(&error)) throw InputError("--max-epipolar-px: " + error);
  // The 3D results in the bench board's frame instead of the first camera's.
  if (bench) stereo_options.results_in_board = *bench;

  std::vector<PathRole> inputs = ConfigInputs(left_config);
  if (options.right_config_file) {
    for (PathRole& role : ConfigInputs(right_config)) inputs.push_back(std::move(role));
  }
  inputs.push_back({"--stereo", options.stereo_file});
  for (const std::string& file : input.files()) inputs.push_back({"an input", file});
  for (const std::string& file : options.bench_board) inputs.push_back({"--bench-board", file});
  std::vector<PathRole> outputs = {{"--csv", options.csv_file}};
  if (const std::optional<PathRole> socket = PublishOutput(options.publish)) {
    outputs.push_back(*socket);
  }
  CheckOutputsAreNotInputs(outputs, inputs);
  // Bound now: a bad endpoint is refused before any output is made.
  const std::unique_ptr<PublishSink> publish =
      OpenPublishSink(options.publish, options.config_file);

  // The wiring: pairs -> StereoSession -> the CSV, the stream, the window, the figures.
  StereoSession session(left_config, right_config, stereo, stereo_options);
  const std::vector<std::string> names = session.marker_names();
  const BasicCsvColumnTable<StereoFrameResult> columns =
      StereoColumns(names, session.segment_names());
  BasicCsvSink<FramePair, StereoFrameResult> csv(options.csv_file, columns);
  std::optional<PublishRowsSink<FramePair, StereoFrameResult>> published;
  if (publish) published.emplace(*publish, columns, StereoMarkerSuffixes());
  StereoFiguresSink figures_sink;
  std::vector<PairSink*> sinks{&csv};
  if (published) sinks.push_back(&*published);
  sinks.insert(sinks.end(), hooks.sinks.begin(), hooks.sinks.end());
  sinks.push_back(&figures_sink);

  RunOptions run_options;
  run_options.max_frames = options.max_frames;
  run_options.stop_requested = hooks.stop_requested;
  // The report's words for a stop (below), in the stream's end record too.
  const auto stop_words = [&hooks] {
    return hooks.stop_reason ? hooks.stop_reason() : std::string("stopped from the window");
  };
  run_options.describe_stop = [&stop_words](StopReason reason) {
    return reason == StopReason::kStopRequested ? stop_words() : std::string();
  };
  const RunSummary run = RunPipeline(input, session, sinks, run_options);
  // The error is reported once, where it is handled; the stream's end record has said it.
  if (!run.ok()) throw InputError(run.error);

  const TrackStereoSummary summary =
      Summarise(run, figures_sink.figures(), input, names, frame_offset, bench);
  PrintReport(options, summary, run, input, stereo, stereo_options, names, report);
  return summary;
}

}  // namespace

namespace {

const FlagTable<TrackStereoOptions>& TrackStereoFlags() {
  using A = TrackStereoOptions;
  static const FlagTable<TrackStereoOptions> table = {
      ValueFlag<A>(kConfigFlag, &A::config_file).Help("Marker config (YAML), see examples/")
          .Required()
          .Check(CLI::ExistingFile),
      RightConfigFlag<A>(&A::right_config_file,
                         "The right view's marker config, when its colours or rois differ (same "
                         "names)"),
      ValueFlag<A>(kLeftFlag, &A::left_input).Help("The first camera's video (or image sequence)"),
      ValueFlag<A>(kRightFlag, &A::right_input)
          .Help("The second camera's video (or image sequence)"),
      ValueFlag<A>("--side-by-side", &A::side_by_side)
          .Help("Instead of --left/--right: one video, the first camera in the left half of each "
                "frame, the second in the right half"),
      CameraFlag<A>("--left-camera", &A::left_camera,
                    "Instead of --left/--right: two live cameras, paired by capture time"),
      CameraFlag<A>("--right-camera", &A::right_camera, "The second live camera"),
      ValueFlag<A>(kStereoFlag, &A::stereo_file)
          .Help("The rig from `softsight calibrate --left ... --right ...`")
          .Required(),
      OutputFlag<A>(&A::csv_file, "csv", "Where to write the per-frame CSV").Required(),
      ValueFlag<A>("--frame-offset", &A::frame_offset)
          .Help("Pair left frame i with right frame i + N (the right camera started N frames "
                "earlier; negative: later). Not given: found from a flash or the motion, or "
                "refused"),
      ValueFlag<A>("--max-offset-frames", &A::max_offset_frames)
          .Help("Without --frame-offset: search offsets up to this many frames either way")
          .ShowDefault()
          .Check(NumberIn(0, 100000)),
      ValueFlag<A>("--pair-by", &A::pair_by)
          .Help("index (frame i with frame i + offset) or time (each frame with the other "
                "view's nearest in time, within half a frame interval; CSV column pair_dt_ms)")
          .ShowDefault(),
      ValueFlag<A>("--time-offset-ms", &A::time_offset_ms)
          .Help("With --pair-by time: the right view's clock minus the left one's (ms)")
          .ShowDefault()
          .Check(NumberIn(-1e9, 1e9)),
      MaxEpipolarFlag<A>(&A::max_epipolar_px,
                         "A pair farther than this from its epipolar line is not believed (status "
                         "epipolar)"),
      ValueFlag<A>("--reference-plane", &A::reference_plane)
          .Help("The out-of-plane angle against: image (the first camera's image plane), first "
                "(the first frame's bending plane) or board (the --bench-board's plane: the "
                "bench)")
          .ShowDefault(),
      ValueFlag<A>("--bench-board", &A::bench_board)
          .Help("LEFT RIGHT: one pair of images of the chessboard lying on the bench; the 3D "
                "coordinates are then in the board's frame (origin at its first inner corner, X "
                "along its first row, Y along its columns, Z into the bench) instead of the "
                "first camera's")
          .Finish([](CLI::Option* o) { o->expected(2); }),
      ValueFlag<A>(kChessboardFlag, &A::chessboard)
          .Help("The --bench-board board's inner corners WxH (default: the --stereo "
                "file's)"),
      ValueFlag<A>(kSquareMmFlag, &A::square_mm)
          .Help("The --bench-board board's square side in mm (default: the --stereo file's)"),
      SequenceFpsFlag<A>(&A::sequence_fps, "Frame rate of image sequences"),
      ValueFlag<A>("--right-fps", &A::right_sequence_fps)
          .Help("Frame rate of the right image sequence, when it differs from --fps")
          .Check(NumberIn(1e-3, 1e6)),
      MaxFramesFlag<A>(&A::max_frames, "Stop after this many pairs"),
      SwitchFlag<A>("--window", &A::window)
          .Help("Show both views side by side with their overlay and a strip chart of the 3D, "
                "each camera's and the out-of-plane angle while tracking (needs a display)"),
      NoPaceFlag<A>([](A& a) { a.pace = false; },
                    "With --window: play recorded inputs as fast as they are tracked instead of "
                    "at their frame rate"),
      ChartSecondsFlag<A>(&A::chart_seconds, "With --window: the strip chart's time span, seconds")
          .Check(NumberIn(0.2, 3600)),
  };
  return table;
}

}  // namespace

CommandRunner SetupTrackStereoCommand(CLI::App& sub) {
  return SetupTrackStereoCommand(sub, nullptr);
}

CommandRunner SetupTrackStereoCommand(CLI::App& sub, StereoWindowOpener open_window) {
  auto options = std::make_shared<TrackStereoOptions>();
  sub.description(
      "Track the markers in two synchronised videos of a calibrated pair of cameras and write\n"
      "their 3D positions (mm, first camera's frame) and the 3D measurements, one CSV row per\n"
      "pair of frames: the angle at the middle marker, the bending plane and its angle out of\n"
      "the reference plane, radius and arc length of the 3D circle, tip displacement.\n"
      "A marker is found in 3D only when both views found it and the pair passes the\n"
      "epipolar check and the pairing check (the markers' motion says both frames are of one\n"
      "moment; else a moving marker's status is timing and a note names the offset to try;\n"
      "docs/stereo.md).\n"
      "Example:\n"
      "  softsight calibrate --left cal/left/ --right cal/right/ --chessboard 9x6 --square-mm 25 "
      "--out stereo.yaml\n"
      "  softsight track-stereo -c markers.yaml --left left.avi --right right.avi "
      "--stereo stereo.yaml --csv run3d.csv\n"
      "Without --frame-offset the offset between the two videos is found from a flash or the\n"
      "motion (and refused when unclear); --pair-by time pairs frames by their timestamps.\n"
      "--bench-board LEFT RIGHT (one pair of images of the chessboard lying on the bench) puts\n"
      "the 3D coordinates in the board's frame instead of the first camera's:\n"
      "  softsight track-stereo -c markers.yaml --left left.avi --right right.avi "
      "--stereo stereo.yaml --bench-board bench_left.png bench_right.png --csv run3d.csv\n"
      "--window shows both views side by side while the CSV is written: each marker's ring (a\n"
      "red slanted cross with why when it is not found in 3D: epipolar, right_lost ...), the\n"
      "status of the pair, and a strip chart of the 3D angle beside each camera's own, and of\n"
      "the out-of-plane angle. Keys: space pause / resume, . one pair (paused), q or Esc stop\n"
      "(the CSV keeps the pairs so far). Recorded inputs play at their frame rate (--no-pace:\n"
      "as fast as they are tracked); the window closes at the end of the input:\n"
      "  softsight track-stereo -c markers.yaml --left-camera 0 --right-camera 2 "
      "--stereo stereo.yaml --csv live3d.csv --window");
  AddFlags(sub, TrackStereoFlags(), options.get());
  auto publish = std::make_shared<PublishArgs>();
  AddFlags(sub, PublishFlags(), publish.get());
  return [options, publish, open_window] {
    options->publish = publish->resolved();
    // Ctrl-C or SIGTERM ends the run between pairs with every row written and the summary;
    // the exit code then says so (130 / 143).
    const StopRequest stop;
    StereoRunHooks hooks;
    hooks.stop_reason = [&stop]() -> std::string {
      return stop.signal() != 0 ? StopSignalReason(stop.signal()) : "stopped from the window";
    };
    std::optional<StereoWindowRun> window;
    if (options->window) {
      if (open_window == nullptr) {
        // The launcher runs `track-stereo --window` in the live plugin; this one has no GUI.
        throw InputError("--window: this build's track-stereo has no window (softsight_live.so)");
      }
      // The window draws each view's triangle: it reads the configs the run will.
      const TrackingConfig left = LoadStereoViewConfig(options->config_file);
      const TrackingConfig right = options->right_config_file
                                       ? LoadStereoViewConfig(*options->right_config_file)
                                       : left;
      window = open_window(*options, left, right);
      hooks.sinks = {window->sink.get()};
    }
    hooks.stop_requested = [&stop, &window] {
      return stop.requested() || (window && window->stop_requested && window->stop_requested());
    };
    RunTrackStereo(*options, std::cout, hooks);
    return ExitCodeAfterStop(0);
  };
}

}  // namespace softsight
