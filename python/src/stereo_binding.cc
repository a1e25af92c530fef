// softsight.track_stereo: two views of a calibrated pair of cameras through the same
// StereoSession and CSV column table as `softsight track-stereo`, the columns returned as numpy
// arrays (docs/stereo.md); softsight.frames_stereo: the same run, one pair's row at a time.
#include <cstdlib>
#include <limits>
#include <memory>
#include <mutex>

#include <opencv2/imgcodecs.hpp>
#include <pybind11/stl.h>

#include "bindings.h"
#include "run_reader.h"
#include "softsight/calib/board_frame.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/core/error.h"
#include "softsight/io/frame_offset.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/output_guard.h"
#include "softsight/io/stereo_input.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/stereo_session.h"

namespace softsight::python {
namespace {

std::string StereoPath(const py::object& value, const char* what) {
  const std::optional<std::string> path = AsPath(value);
  if (!path) throw py::type_error(std::string(what) + ": a path (str, bytes or os.PathLike)");
  return *path;
}

// How a column's CSV field is given to Python: frame and right_frame as integers, <marker>_status
// as text, every other column as a float (NaN for an empty field). One rule for track_stereo's
// arrays and frames_stereo's rows, so the two hold the same values.
enum class FieldKind { kIndex, kText, kNumber };
FieldKind KindOf(const std::string& name) {
  if (name == "frame" || name == "right_frame") return FieldKind::kIndex;
  if (name.size() > 7 && name.compare(name.size() - 7, 7, "_status") == 0) return FieldKind::kText;
  return FieldKind::kNumber;
}
double NumberOf(const std::string& field) {
  return field.empty() ? std::numeric_limits<double>::quiet_NaN()
                       : std::strtod(field.c_str(), nullptr);
}

// The rows as the CLI's CSV has them, then one numpy array per column: frame and right_frame
// int64, <marker>_status str, every other column float64 (NaN for an empty field).
py::dict StereoColumnsDict(const BasicCsvColumnTable<StereoFrameResult>& table,
                           const std::vector<std::string>& rows) {
  const size_t n = rows.size();
  py::module_ np = py::module_::import("numpy");
  py::dict out;
  std::vector<std::vector<std::string>> fields(table.size(), std::vector<std::string>(n));
  for (size_t r = 0; r < n; ++r) {
    size_t start = 0;
    for (size_t c = 0; c < table.size(); ++c) {
      const size_t end = std::min(rows[r].find(',', start), rows[r].size());
      fields[c][r] = rows[r].substr(start, end - start);
      start = end + 1;
    }
  }
  for (size_t c = 0; c < table.size(); ++c) {
    const std::string& name = table.column(c).name;
    const FieldKind kind = KindOf(name);
    if (kind == FieldKind::kText) {
      py::list values(n);
      for (size_t r = 0; r < n; ++r) values[r] = py::str(fields[c][r]);
      out[py::str(name)] = np.attr("array")(values, py::arg("dtype") = "U");
    } else if (kind == FieldKind::kIndex) {
      py::array_t<int64_t> values(n);
      for (size_t r = 0; r < n; ++r)
        values.mutable_data()[r] = std::strtoll(fields[c][r].c_str(), nullptr, 10);
      out[py::str(name)] = values;
    } else {
      py::array_t<double> values(n);
      for (size_t r = 0; r < n; ++r) values.mutable_data()[r] = NumberOf(fields[c][r]);
      out[py::str(name)] = values;
    }
  }
  return out;
}

// Each pair's row as the CSV's text.
class RowTextSink : public PairSink {
 public:
  RowTextSink(BasicCsvColumnTable<StereoFrameResult> table, std::vector<std::string>& rows)
      : table_(std::move(table)), rows_(rows) {}
  void consume(const FramePair& pair, const StereoFrameResult& result) override {
    (void)pair;
    table_.append_row(result, row_);
    rows_.push_back(row_);
  }

 private:
  BasicCsvColumnTable<StereoFrameResult> table_;
  std::vector<std::string>& rows_;
  std::string row_;
};

// The bench board's frame (`track-stereo --bench-board`): the board from `chessboard` and
// `square_mm`, else the stereo file's.
BoardFrame BenchFrame(const py::object& bench_board, const std::optional<std::string>& chessboard,
                      std::optional<double> square_mm, const std::string& stereo_file,
                      const StereoCalibration& calibration,
                      const TriangulationOptions& triangulation) {
  const py::sequence images = bench_board.cast<py::sequence>();
  if (images.size() != 2) {
    throw InputError("bench_board: give two images, the left and the right view of the board");
  }
  const std::string left_file = StereoPath(images[0], "bench_board");
  const std::string right_file = StereoPath(images[1], "bench_board");
  const std::optional<ChessboardSpec> stored = LoadStereoCalibrationBoard(stereo_file);
  if ((!chessboard || !square_mm) && !stored) {
    throw InputError("bench_board: " + stereo_file +
                     " does not say which board it was calibrated with; give chessboard and "
                     "square_mm");
  }
  ChessboardSpec board = stored.value_or(ChessboardSpec{});
  if (chessboard) board.inner_corners = ParseChessboardSize(*chessboard, "chessboard");
  if (square_mm) board.square_mm = *square_mm;
  const cv::Mat left_image = cv::imread(left_file, cv::IMREAD_COLOR);
  const cv::Mat right_image = cv::imread(right_file, cv::IMREAD_COLOR);
  return LocateBenchBoard(Triangulator(calibration, triangulation), board, left_file, left_image,
                          right_file, right_image);
}

// What track_stereo and frames_stereo read, checked and found as `track-stereo` does: both
// views' markers, the calibration, the options, both inputs and the frame offset between them
// (found from a flash or the motion when not given), the bench board.
struct StereoSetup {
  TrackingConfig left_config, right_config;
  StereoCalibration calibration;
  StereoOptions options;
  FrameSourceSpec left_spec, right_spec;
  int64_t frame_offset = 0;
  FrameOffsetOptions offset_options;
  std::optional<FrameOffsetEstimate> found_offset;
  std::optional<BoardFrame> bench;
};

StereoSetup SetUpStereo(const py::object& left, const py::object& right, const py::object& config,
                        const py::object& stereo, std::optional<int64_t> max_frames,
                        const py::object& right_config, std::optional<int64_t> frame_offset,
                        int64_t max_offset_frames, double max_epipolar_px,
                        const std::string& reference_plane, double fps,
                        const py::object& bench_board,
                        const std::optional<std::string>& chessboard,
                        std::optional<double> square_mm) {
  if (max_frames && *max_frames < 0) {
    throw InputError("max_frames: " + std::to_string(*max_frames) + " must be >= 0");
  }
  StereoSetup setup;
  setup.left_config = ResolveConfig(config, std::nullopt);
  setup.right_config =
      right_config.is_none() ? setup.left_config : ResolveConfig(right_config, std::nullopt);
  setup.calibration = LoadStereoCalibration(StereoPath(stereo, "stereo"));
  const StereoCalibration& calibration = setup.calibration;
  StereoOptions& options = setup.options;
  options.triangulation.max_epipolar_px = max_epipolar_px;
  options.reference_plane = ParseReferencePlane(reference_plane, "reference_plane");
  if (bench_board.is_none() && (chessboard || square_mm)) {
    throw InputError(std::string(chessboard ? "chessboard" : "square_mm") +
                     " describes the bench_board board; give bench_board=(left, right)");
  }
  if (options.reference_plane == StereoOptions::ReferencePlane::kBoard && bench_board.is_none()) {
    throw InputError("reference_plane board: the bench board's plane; give bench_board=(left, "
                     "right) (one pair of images of the board lying on the bench)");
  }
  FrameOffsetOptions& offset_options = setup.offset_options;
  offset_options.max_offset_frames = max_offset_frames;
  std::string error;
  if (!frame_offset && !offset_options.Check(&error)) throw InputError(error);
  std::optional<BoardFrame>& bench = setup.bench;
  if (!bench_board.is_none()) {
    bench = BenchFrame(bench_board, chessboard, square_mm, StereoPath(stereo, "stereo"),
                       calibration, options.triangulation);
    options.board_normal =
        cv::Vec3d(bench->rotation(0, 2), bench->rotation(1, 2), bench->rotation(2, 2));
    options.results_in_board = *bench;
  }
  FrameSourceSpec& left_spec = setup.left_spec;
  FrameSourceSpec& right_spec = setup.right_spec;
  left_spec.input = StereoPath(left, "left");
  right_spec.input = StereoPath(right, "right");
  left_spec.sequence_fps = right_spec.sequence_fps = fps;
  // Not given: found from a flash or the motion, as `track-stereo` does without --frame-offset
  // (within max_offset_frames; the frames the run can use and the range beyond them).
  if (!frame_offset) {
    py::gil_scoped_release release;
    std::optional<int64_t> frames;
    if (max_frames) frames = *max_frames + max_offset_frames;
    setup.found_offset = FindFrameOffset(*OpenFrameSource(left_spec), *OpenFrameSource(right_spec),
                                         offset_options, frames,
                                         FrameOffsetNames{"left and right", "frame_offset=N"});
    frame_offset = setup.found_offset->offset_frames;
  }
  setup.frame_offset = *frame_offset;
  return setup;
}

// Both inputs, right frame i + frame_offset paired with left frame i (call without the GIL).
std::unique_ptr<StereoInput> OpenPairs(const StereoSetup& setup) {
  return PairByIndex(OpenFrameSource(setup.left_spec), OpenFrameSource(setup.right_spec),
                     setup.frame_offset, "frame_offset");
}

py::tuple TrackStereo(const py::object& left, const py::object& right, const py::object& config,
                      const py::object& stereo, std::optional<int64_t> max_frames,
                      const py::object& right_config, std::optional<int64_t> frame_offset,
                      int64_t max_offset_frames, double max_epipolar_px,
                      const std::string& reference_plane, double fps,
                      const py::object& bench_board, const std::optional<std::string>& chessboard,
                      std::optional<double> square_mm) {
  const StereoSetup setup =
      SetUpStereo(left, right, config, stereo, max_frames, right_config, frame_offset,
                  max_offset_frames, max_epipolar_px, reference_plane, fps, bench_board,
                  chessboard, square_mm);
  const StereoCalibration& calibration = setup.calibration;
  const std::optional<FrameOffsetEstimate>& found_offset = setup.found_offset;
  const std::optional<BoardFrame>& bench = setup.bench;

  // The one run (pipeline/run.h RunPipeline on pairs), with `track-stereo`'s CSV table and
  // figures; the rows kept as the CSV's text, made into columns below.
  std::vector<std::string> rows;
  int64_t pairs = 0;
  py::dict found, epipolar;
  std::vector<int64_t> found_count, epipolar_count;
  std::vector<std::string> names, segments;
  {
    py::gil_scoped_release release;
    const std::unique_ptr<StereoInput> input = OpenPairs(setup);
    StereoSession session(setup.left_config, setup.right_config, calibration, setup.options);
    names = session.marker_names();
    segments = session.segment_names();
    RowTextSink kept(StereoColumns(names, segments), rows);
    StereoFiguresSink figures;
    RunOptions run_options;
    run_options.max_frames = max_frames;
    const RunSummary run = RunPipeline(*input, session, {&kept, &figures}, run_options);
    if (!run.ok()) throw InputError(run.error);
    pairs = run.frames;
    for (size_t i = 0; i < names.size(); ++i) {
      found_count.push_back(run.markers[i].found);
      epipolar_count.push_back(figures.figures().epipolar[i]);
    }
  }
  for (size_t i = 0; i < names.size(); ++i) {
    found[py::str(names[i])] = found_count[i];
    epipolar[py::str(names[i])] = epipolar_count[i];
  }
  py::dict summary;
  summary["pairs"] = pairs;
  summary["found"] = found;
  summary["epipolar"] = epipolar;
  summary["baseline_mm"] = calibration.baseline_mm();
  // The offset used and where it came from: "given", "flash" or "motion" (with the motion's
  // correlation at the offset and at the next best peak, None when there is none).
  summary["frame_offset"] = setup.frame_offset;
  summary["frame_offset_method"] =
      found_offset ? FrameOffsetMethodName(found_offset->method) : "given";
  py::object correlation = py::none(), next_correlation = py::none();
  if (found_offset && found_offset->method == FrameOffsetEstimate::Method::kMotion) {
    correlation = py::float_(*found_offset->peak_correlation);
    if (found_offset->second_correlation) {
      next_correlation = py::float_(*found_offset->second_correlation);
    }
  }
  summary["frame_offset_correlation"] = correlation;
  summary["frame_offset_next_correlation"] = next_correlation;
  if (found_offset) {
    summary["frame_offset_report"] = DescribeFrameOffset(*found_offset, setup.offset_options);
  } else {
    summary["frame_offset_report"] = py::none();
  }
  if (bench) {
    summary["bench_board_rms_mm"] = bench->rms_mm;
    summary["bench_board_origin_mm"] =
        py::make_tuple(bench->origin_mm[0], bench->origin_mm[1], bench->origin_mm[2]);
  }
  return py::make_tuple(StereoColumnsDict(StereoColumns(names, segments), rows), summary);
}

// softsight.frames_stereo's reader: track_stereo's set-up and run (the one run loop over pairs,
// pipeline/run.h StereoRunStream, with its key-frame check), one pair's row per next() as the
// table has it, the GIL released while the pair is read and tracked. close() (or the end, or an
// error) releases both inputs, so a generator closed early lets go of the files.
class StereoFrameStream : public ClosableRunReader<StereoFrameStream> {
 public:
  StereoFrameStream(const py::object& left, const py::object& right, const py::object& config,
                    const py::object& stereo, std::optional<int64_t> max_frames,
                    const py::object& right_config, std::optional<int64_t> frame_offset,
                    int64_t max_offset_frames, double max_epipolar_px,
                    const std::string& reference_plane, double fps, const py::object& bench_board,
                    const std::optional<std::string>& chessboard, std::optional<double> square_mm)
      : setup_(SetUpStereo(left, right, config, stereo, max_frames, right_config, frame_offset,
                           max_offset_frames, max_epipolar_px, reference_plane, fps, bench_board,
                           chessboard, square_mm)) {
    py::gil_scoped_release release;
    input_ = OpenPairs(setup_);
    session_ = std::make_unique<StereoSession>(setup_.left_config, setup_.right_config,
                                               setup_.calibration, setup_.options);
    table_ = std::make_unique<BasicCsvColumnTable<StereoFrameResult>>(
        StereoColumns(session_->marker_names(), session_->segment_names()));
    RunOptions options;
    options.max_frames = max_frames;
    stream_ = std::make_unique<StereoRunStream>(*input_, *session_, options);
  }

  // The next pair's row (a dict: column -> value, as track_stereo's table has them), or None at
  // the end. Throws InputError as track_stereo does, after the rows before it.
  py::object next() {
    bool have = false;
    {
      py::gil_scoped_release release;
      const std::lock_guard<std::mutex> lock(mutex_);  // One pair at a time.
      if (!closed_) {
        try {
          const std::optional<StereoFrameResult> result = stream_->next();
          if (stream_->ended()) input_.reset();  // The run has ended: the files are let go of.
          if (result) {
            row_.clear();
            table_->append_row(*result, row_);
            have = true;
          } else {
            closed_ = true;
          }
        } catch (...) {
          close_locked();
          throw;
        }
      }
    }
    if (!have) return py::none();
    // The row's text, parsed as track_stereo parses its rows.
    py::dict out;
    size_t start = 0;
    for (size_t c = 0; c < table_->size(); ++c) {
      const size_t end = std::min(row_.find(',', start), row_.size());
      const std::string field = row_.substr(start, end - start);
      start = end + 1;
      const std::string& name = table_->column(c).name;
      switch (KindOf(name)) {
        case FieldKind::kIndex:
          out[py::str(name)] = py::int_(std::strtoll(field.c_str(), nullptr, 10));
          break;
        case FieldKind::kText:
          out[py::str(name)] = py::str(field);
          break;
        case FieldKind::kNumber:
          out[py::str(name)] = py::float_(NumberOf(field));
          break;
      }
    }
    return out;
  }

 private:
  friend class ClosableRunReader<StereoFrameStream>;
  void release_input() { input_.reset(); }  // Both videos or image sequences.

  StereoSetup setup_;
  std::unique_ptr<StereoInput> input_;
  std::unique_ptr<StereoSession> session_;
  std::unique_ptr<BasicCsvColumnTable<StereoFrameResult>> table_;
  std::unique_ptr<StereoRunStream> stream_;
  std::string row_;
};

}  // namespace

void BindStereo(py::module_& m) {
  py::class_<StereoFrameStream>(
      m, "_StereoFrameStream",
      "softsight.frames_stereo's reader (use softsight.frames_stereo, which closes it).")
      .def(py::init<const py::object&, const py::object&, const py::object&, const py::object&,
                    std::optional<int64_t>, const py::object&, std::optional<int64_t>, int64_t,
                    double, const std::string&, double, const py::object&,
                    const std::optional<std::string>&, std::optional<double>>(),
           py::arg("left"), py::arg("right"), py::arg("config"), py::arg("stereo"),
           py::arg("max_frames"), py::arg("right_config"), py::arg("frame_offset"),
           py::arg("max_offset_frames"), py::arg("max_epipolar_px"), py::arg("reference_plane"),
           py::arg("fps"), py::arg("bench_board"), py::arg("chessboard"), py::arg("square_mm"))
      .def("next", &StereoFrameStream::next, "The next pair's row (a dict), or None at the end.")
      .def("close", &StereoFrameStream::close, "Releases both inputs (idempotent).")
      .def_property_readonly("closed", &StereoFrameStream::closed)
      .def_property_readonly("total", &StereoFrameStream::total)
      .def_property_readonly("done", &StereoFrameStream::done);

  m.def("_track_stereo", &TrackStereo, py::arg("left"), py::arg("right"), py::arg("config"),
        py::arg("stereo"), py::arg("max_frames"), py::arg("right_config"), py::arg("frame_offset"),
        py::arg("max_offset_frames"), py::arg("max_epipolar_px"), py::arg("reference_plane"), py::arg("fps"),
        py::arg("bench_board"), py::arg("chessboard"), py::arg("square_mm"),
        "softsight.track_stereo without the table: (columns dict, summary dict).");
}

}  // namespace softsight::python
