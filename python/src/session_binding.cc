// softsight.Session: frames from the caller's own code (numpy arrays) through a TrackingSession.
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>

#include <opencv2/imgproc.hpp>
#include <pybind11/stl.h>

#include "bindings.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/io/csv_columns.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/tracking_session.h"

namespace softsight::python {
namespace {

class PySession {
 public:
  explicit PySession(TrackingConfig config)
      : session_(config), columns_(TrackingColumns(config).names()) {}

  FrameResult process(const py::object& frame_object, double time_s,
                      std::optional<int64_t> index) {
    // Checked here rather than by pybind11's overload matching, whose message quotes the whole
    // value (megabytes for a list of pixels).
    if (!py::isinstance<py::array>(frame_object)) {
      throw py::type_error("frame: a numpy array (HxWx3 BGR or HxW gray, uint8) as "
                           "cv2.VideoCapture.read() gives, got " +
                           std::string(py::str(py::type::of(frame_object).attr("__name__"))));
    }
    const py::array image = py::reinterpret_borrow<py::array>(frame_object);
    py::object copy;  // Holds a contiguous copy when the array's layout needs one.
    const cv::Mat pixels =
        ImageHeader(image, "frame " + std::to_string(index.value_or(next_index_)), &copy);
    py::gil_scoped_release release;  // Other Python threads run while this frame is tracked.
    const std::lock_guard<std::mutex> lock(mutex_);  // One frame at a time per session.
    last_call_released_gil_ = PyGILState_Check() == 0;
    const int64_t frame_index = index.value_or(next_index_);
    const std::string what = "frame " + std::to_string(frame_index);
    // A NaN or negative time would reach the CSV and the motion model as if measured.
    if (!(std::isfinite(time_s) && time_s >= 0.0)) {
      throw InputError(what + ": time_s " + ShortNumber(time_s) + " must be a finite number >= 0");
    }
    if (frame_index < 0) throw InputError(what + ": a frame index must be >= 0");
    Frame frame;
    frame.index = frame_index;
    frame.time_s = time_s;
    if (pixels.channels() == 1) {
      // The library's frames are BGR (core/types.h): a gray frame is expanded into a buffer the
      // session reuses.
      cv::cvtColor(pixels, gray_as_bgr_, cv::COLOR_GRAY2BGR);
      frame.image = gray_as_bgr_;
    } else {
      frame.image = pixels;  // A header on the caller's pixels: no copy.
    }
    if (first_size_.empty()) {
      // As track() and the program refuse a gray video: colour markers on gray frames would
      // only ever be "lost", which reads as a tracking failure rather than a wrong input. Only a
      // one-channel array is judged: a dark colour frame (a camera warming up) is not gray input.
      if (NeedsColour(session_.config()) && pixels.channels() == 1) {
        throw InputError(what + ": a gray frame, but " + GrayFrameProblem());
      }
      first_size_ = frame.image.size();
    } else if (frame.image.size() != first_size_) {
      throw InputError(what + ": " + std::to_string(frame.image.cols) + "x" +
                       std::to_string(frame.image.rows) + " pixels, but this session's frames are " +
                       std::to_string(first_size_.width) + "x" +
                       std::to_string(first_size_.height) +
                       " (a Session follows one camera: make a new one for another size)");
    }
    last_frame_address_ = reinterpret_cast<uintptr_t>(frame.image.data);
    const FrameResult& result = session_.process(frame);
    next_index_ = frame_index + 1;
    return result;  // A copy: the session reuses its own for the next frame.
  }

  // The benchmark's reference: `calls` frames through TrackingSession::process alone, timed in
  // C++ (the same header, indices and lock as process(); no Python in the loop). Seconds.
  double time_cpp_process(const py::array& image, int calls) {
    py::object copy;
    const cv::Mat pixels = ImageHeader(image, "frame", &copy);
    if (pixels.channels() != 3) throw InputError("frame: the benchmark takes BGR frames");
    py::gil_scoped_release release;
    Frame frame;
    frame.image = pixels;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) {
      const std::lock_guard<std::mutex> lock(mutex_);
      frame.index = next_index_;
      session_.process(frame);
      next_index_ = frame.index + 1;
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  TrackingSession& session() { return session_; }
  const std::vector<std::string>& columns() const { return columns_; }
  int64_t next_index() const { return next_index_; }
  uintptr_t last_frame_address() const { return last_frame_address_; }
  bool last_call_released_gil() const { return last_call_released_gil_; }
  std::mutex& mutex() { return mutex_; }

 private:
  TrackingSession session_;
  std::vector<std::string> columns_;
  std::mutex mutex_;
  std::atomic<int64_t> next_index_{0};  // Read for messages before the lock is taken.
  cv::Size first_size_;
  cv::Mat gray_as_bgr_;
  uintptr_t last_frame_address_ = 0;
  bool last_call_released_gil_ = false;
};

const MarkerObservation& FindMarker(const FrameResult& r, const std::string& name) {
  for (const MarkerObservation& m : r.markers) {
    if (m.name == name) return m;
  }
  throw py::key_error("no marker named '" + name + "'");
}

template <typename Class>
void MeasurementProperty(Class& c, const char* name, std::optional<double> Measurement::*member,
                         const char* doc) {
  c.def_property_readonly(
      name, [member](const FrameResult& r) { return Optional(r.measurement.*member); }, doc);
}

}  // namespace


void BindSession(py::module_& m) {
  py::class_<MarkerObservation>(m, "Marker", R"doc(
One marker in one frame. ``x``, ``y`` are None when it was not found (never a stale or guessed
position); ``status`` says why: found, lost, ambiguous, implausible, covered, out_of_frame,
not_started, stale (the CSV's <name>_status).)doc")
      .def_readonly("name", &MarkerObservation::name)
      .def_property_readonly(
          "x",
          [](const MarkerObservation& o) -> py::object {
            if (!o.observation.found()) return py::none();
            return py::float_(o.observation.position_px->x);
          },
          "Centroid column in pixels (pixel (row i, column j) has its centre at x = j), or None.")
      .def_property_readonly(
          "y",
          [](const MarkerObservation& o) -> py::object {
            if (!o.observation.found()) return py::none();
            return py::float_(o.observation.position_px->y);
          },
          "Centroid row in pixels, or None.")
      .def_property_readonly(
          "sigma_px",
          [](const MarkerObservation& o) -> py::object {
            if (!o.observation.found()) return py::none();
            return Optional(o.observation.sigma_px);
          },
          "The position's standard uncertainty along each axis in pixels (a found marker lies "
          "within 3 sigma of its true centre), or None.")
      .def_property_readonly(
          "found", [](const MarkerObservation& o) { return o.observation.found(); },
          "Whether the marker was found (verified) in this frame.")
      .def_property_readonly(
          "score", [](const MarkerObservation& o) { return Optional(o.observation.score); },
          "The tracker's quality (colour: area / reference area; ZNCC: the correlation; SAD/SSD: "
          "mean difference per pixel and channel), or None.")
      .def_property_readonly(
          "status",
          [](const MarkerObservation& o) { return MarkerStatusName(o.observation.status()); },
          "Why the marker has (or has no) position.")
      .def_property_readonly(
          "track", [](const MarkerObservation& o) { return TrackStateName(o.track); },
          "Where the marker's track stands (the CSV's <name>_track): tentative (found, the first "
          "report of its track), confirmed, coasting (not found, still predicted), or lost.")
      .def_property_readonly(
          "candidates", [](const MarkerObservation& o) { return o.observation.candidates; },
          "With status 'ambiguous': how many candidates fitted about equally.")
      .def("__repr__", [](const MarkerObservation& o) {
        std::string text = "Marker(" + o.name + ": " + MarkerStatusName(o.observation.status());
        if (o.observation.found()) {
          text += " at (" + std::string(py::str(py::float_(o.observation.position_px->x))) + ", " +
                  std::string(py::str(py::float_(o.observation.position_px->y))) + ")";
        }
        return text + ")";
      });

  py::class_<FrameResult> result(m, "FrameResult", R"doc(
What the session learned from one frame: every marker (``result.markers``, or
``result["red"]``) and the measurements, None where the CSV has an empty field (a marker
missing, no radius when straight, no _mm values without a scale).)doc");
  result.def_readonly("frame", &FrameResult::frame_index, "The frame's index.")
      .def_readonly("time_s", &FrameResult::time_s, "The frame's time in seconds.")
      .def_readonly("proc_ms", &FrameResult::proc_ms, "Tracking + measurement time (ms).")
      .def_readonly("markers", &FrameResult::markers, "Every marker, in config order.")
      .def("__getitem__", &FindMarker, py::arg("name"), py::return_value_policy::reference_internal,
           "The marker named `name` (KeyError when there is none).")
      .def_property_readonly("measurement", [](const FrameResult& r) { return MeasurementDict(r.measurement); },
                             "Every measurement by name (None where absent).")
      .def_property_readonly(
          "inner_angle_deg",
          [](const FrameResult& r) {
            py::list out;
            for (const auto& a : r.measurement.inner_angle_deg) out.append(Optional(a));
            return out;
          },
          "With a chain: the angle at each inner marker, in chain order (None where unknown).")
      .def("__repr__", [](const FrameResult& r) {
        std::string text = "FrameResult(frame " + std::to_string(r.frame_index);
        for (const MarkerObservation& o : r.markers) {
          text += ", " + o.name + " " + MarkerStatusName(o.observation.status());
        }
        if (r.measurement.angle_deg) {
          text += ", angle " + std::string(py::str(py::float_(*r.measurement.angle_deg))) + " deg";
        }
        return text + ")";
      });
  MeasurementProperty(result, "angle_deg", &Measurement::angle_deg,
                      "Angle at the middle marker (paper eq. 7), degrees; 180 when straight.");
  MeasurementProperty(result, "chord_px", &Measurement::chord_px, "Distance base-tip (px).");
  MeasurementProperty(result, "sagitta_px", &Measurement::sagitta_px,
                      "Distance of the middle marker from the chord (px).");
  MeasurementProperty(result, "radius_px", &Measurement::radius_px,
                      "Radius of curvature (eq. 8, or the circle fit with more markers); None "
                      "when straight.");
  MeasurementProperty(result, "arc_length_px", &Measurement::arc_length_px,
                      "Arc length (eq. 9) (px).");
  MeasurementProperty(result, "circumradius_px", &Measurement::circumradius_px,
                      "Radius of the circle through the three markers: a cross-check (not in "
                      "the CSV).");
  MeasurementProperty(result, "tip_disp_px", &Measurement::tip_disp_px,
                      "Bending distance: tip displacement from its reference (px).");
  MeasurementProperty(result, "chord_mm", &Measurement::chord_mm, "chord_px in millimetres.");
  MeasurementProperty(result, "sagitta_mm", &Measurement::sagitta_mm, "sagitta_px in mm.");
  MeasurementProperty(result, "radius_mm", &Measurement::radius_mm, "radius_px in mm.");
  MeasurementProperty(result, "arc_length_mm", &Measurement::arc_length_mm, "arc_length_px in mm.");
  MeasurementProperty(result, "tip_disp_mm", &Measurement::tip_disp_mm, "tip_disp_px in mm.");

  py::class_<PySession>(m, "Session", R"doc(
Tracks the markers of a config in frames your code supplies (a camera loop, cv2.VideoCapture,
a notebook), one frame at a time, as ``softsight track`` does for a file.

    session = softsight.Session("markers.yaml")
    ok, frame = cap.read()
    result = session.process(frame, time_s=0.0)
    result["red"].x, result.angle_deg

``frame`` is a uint8 numpy array, HxWx3 BGR (as OpenCV gives) or HxW gray; BGR frames are read
in place, not copied (a gray frame is expanded to BGR in a buffer the session reuses). The GIL is
released while a frame is processed, so other Python threads keep running.)doc")
      .def(py::init([](const py::object& config, const std::optional<std::string>& method) {
             TrackingConfig resolved = ResolveConfig(config, method);
             py::gil_scoped_release release;
             return std::make_unique<PySession>(std::move(resolved));
           }),
           py::arg("config"), py::arg("method") = py::none(),
           "A session for `config` (a softsight.Config, a YAML path or a dict); `method` "
           "overrides every marker's method. Raises InputError on a bad config.")
      .def("process", &PySession::process, py::arg("frame"), py::arg("time_s"),
           py::arg("index") = py::none(), R"doc(
Tracks every marker in ``frame`` and measures. Returns a FrameResult.

``time_s`` is the frame's time in seconds; ``index`` its position in the stream (default: one
more than the last, starting at 0), which template ``frame:`` keys refer to. Raises
softsight.InputError for a frame that is not uint8 HxWx3 / HxW, or whose size differs from the
first frame's.)doc")
      .def_property_readonly("columns", &PySession::columns,
                             "The CSV's column names for this session's config.")
      .def_property_readonly("next_index", &PySession::next_index,
                             "The index the next frame gets when process() is not given one.")
      .def(
          "reset_tip_reference",
          [](PySession& s) {
            const std::lock_guard<std::mutex> lock(s.mutex());
            s.session().reset_tip_reference();
          },
          "The next frame where the tip is found becomes the bending distance's reference.")
      .def(
          "reselect",
          [](PySession& s, const std::string& marker, const py::array& frame,
             const std::vector<int>& rect, double time_s,
             std::optional<int64_t> index) -> FrameResult {
            if (rect.size() != 4) throw py::value_error("rect: expected (x, y, width, height)");
            py::object copy;
            const cv::Mat pixels = ImageHeader(frame, "reselect frame", &copy);
            Frame f;
            f.image = pixels;
            if (pixels.channels() == 1) cv::cvtColor(pixels, f.image, cv::COLOR_GRAY2BGR);
            f.time_s = time_s;
            py::gil_scoped_release release;
            const std::lock_guard<std::mutex> lock(s.mutex());
            f.index = index.value_or(std::max<int64_t>(0, s.next_index() - 1));
            return s.session().reselect(marker, f, cv::Rect(rect[0], rect[1], rect[2], rect[3]));
            // (A copy, made under the lock: the session reuses its result.)
          },
          py::arg("marker"), py::arg("frame"), py::arg("rect"), py::arg("time_s") = 0.0,
          py::arg("index") = py::none(),
          "The marker is inside rect (x, y, width, height) on `frame` (default index: the last "
          "processed frame's): re-cuts its template or restricts its colour tracker's next "
          "acquisition (the live window's mouse recalibration). Returns that frame's result.")
      // For the binding's own tests: where the pixels the library last read were, and whether
      // the GIL was released while it read them.
      .def_property_readonly("_last_frame_address", &PySession::last_frame_address)
      .def_property_readonly("_last_call_released_gil", &PySession::last_call_released_gil)
      .def("_time_cpp_process", &PySession::time_cpp_process, py::arg("frame"), py::arg("calls"),
           "For the overhead benchmark (python/bench): seconds for `calls` frames through the C++ "
           "TrackingSession::process alone.");

  m.def(
      "_image_header",
      [](const py::array& array) {
        py::object copy;
        const cv::Mat header = ImageHeader(array, "image", &copy);
        return py::make_tuple(reinterpret_cast<uintptr_t>(header.data), header.rows, header.cols,
                              header.channels(), header.step[0], static_cast<bool>(copy));
      },
      py::arg("array"),
      "For tests: (data address, rows, cols, channels, row step, copied) of the cv::Mat the "
      "binding makes for `array`.");
}

}  // namespace softsight::python
