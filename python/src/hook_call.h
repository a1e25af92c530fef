// What the softsight Python module (softsight.track(hook=...)) and the program's embedded
// interpreter (`--hook file.py`, src/app/python_hook.cc) share: a hook's frame as numpy, the
// values it returns, its columns and its traceback. Header-only, so that both build it against
// their own pybind11 (the module's extension, the program's embedding) without a library between
// them. Every function here needs the GIL.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "softsight/core/error.h"
#include "softsight/core/types.h"
#include "softsight/pipeline/hook.h"

namespace softsight::python {

namespace py = pybind11;

// None for an absent value.
inline py::object Optional(const std::optional<double>& value) {
  return value ? py::object(py::float_(*value)) : py::object(py::none());
}

// The measurement as a dict with the CSV's names, None where the CSV has an empty field (the
// session's results, the renderer's truth and the hooks' results use it).
inline py::dict MeasurementDict(const Measurement& m) {
  py::dict out;
  out["angle_deg"] = Optional(m.angle_deg);
  out["chord_px"] = Optional(m.chord_px);
  out["sagitta_px"] = Optional(m.sagitta_px);
  out["radius_px"] = Optional(m.radius_px);
  out["arc_length_px"] = Optional(m.arc_length_px);
  out["circumradius_px"] = Optional(m.circumradius_px);
  out["tip_disp_px"] = Optional(m.tip_disp_px);
  out["chord_mm"] = Optional(m.chord_mm);
  out["sagitta_mm"] = Optional(m.sagitta_mm);
  out["radius_mm"] = Optional(m.radius_mm);
  out["arc_length_mm"] = Optional(m.arc_length_mm);
  out["tip_disp_mm"] = Optional(m.tip_disp_mm);
  return out;
}

// The frame as a read-only numpy array (rows x cols x 3 uint8, BGR) on the frame's own pixels: no
// copy per frame. The array holds a reference to the pixels (a cv::Mat header in its capsule),
// so a hook that keeps it never reads freed memory; but the source may write the next frame into
// the same buffer: a hook copies (frame.copy()) what it keeps past the call.
inline py::array FrameView(const cv::Mat& image) {
  auto* held = new cv::Mat(image);
  const py::capsule owner(held, [](void* mat) { delete static_cast<cv::Mat*>(mat); });
  std::vector<py::ssize_t> shape{image.rows, image.cols};
  std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(image.step[0]),
                                   static_cast<py::ssize_t>(image.elemSize())};
  if (image.channels() > 1) {
    shape.push_back(image.channels());
    strides.push_back(static_cast<py::ssize_t>(image.elemSize1()));
  }
  py::array array(py::dtype::of<uint8_t>(), shape, strides, held->data, owner);
  // Read-only, as pybind11 makes its own read-only arrays: the frame is every sink's.
  py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return array;
}

// A hook's declared columns: a list or tuple of str. Throws InputError saying what it is instead.
inline std::vector<std::string> ColumnNames(const py::handle& columns, const std::string& what) {
  const auto refuse = [&] {
    return InputError(what + " must be a list of str, the names of the values on_frame returns, "
                             "e.g. [\"tip_speed\"]; it is " +
                      std::string(py::str(py::repr(columns))));
  };
  if (!py::isinstance<py::list>(columns) && !py::isinstance<py::tuple>(columns)) throw refuse();
  std::vector<std::string> names;
  for (const py::handle name : columns) {
    if (!py::isinstance<py::str>(name)) throw refuse();
    names.push_back(name.cast<std::string>());
  }
  return names;
}

// What on_frame returned into `out`: a dict of column -> number (None or nan: an empty field), or
// None for no values. Throws InputError naming the key or the value that is wrong (the run
// then ends: it is the hook's bug, not a moment's failure).
inline void TakeValues(const py::handle& returned, HookValues& out) {
  if (returned.is_none()) return;
  if (!py::isinstance<py::dict>(returned)) {
    throw InputError("on_frame returned " + std::string(py::str(py::repr(returned))).substr(0, 80) +
                     ": it returns a dict of column name -> number, or None");
  }
  for (const auto item : py::reinterpret_borrow<py::dict>(returned)) {
    if (!py::isinstance<py::str>(item.first)) {
      throw InputError("on_frame returned the key " + std::string(py::str(py::repr(item.first))) +
                       ": keys are column names (str)");
    }
    const std::string key = item.first.cast<std::string>();
    if (!out.find(key)) out.set(key, 0.0);  // Throws, naming the declared columns.
    if (item.second.is_none()) continue;
    // Numbers, numpy scalars, bools: whatever Python turns into a float (not a str).
    const double value = PyFloat_AsDouble(item.second.ptr());
    if (value == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      throw InputError("on_frame returned " +
                       std::string(py::str(py::repr(item.second))).substr(0, 80) + " for '" + key +
                       "': not a number");
    }
    out.set(key, value);
  }
}

// The Python error as Python prints it: its traceback, then its type and message.
inline std::string TracebackText(const py::error_already_set& error) {
  try {
    const py::list lines = py::module_::import("traceback")
                               .attr("format_exception")(error.type(), error.value(), error.trace());
    std::string text;
    for (const py::handle line : lines) text += line.cast<std::string>();
    return text;
  } catch (const std::exception&) {
    return error.what();
  }
}

}  // namespace softsight::python
