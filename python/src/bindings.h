// Shared pieces of the softsight Python module (softsight._core): the binders of each part of the
// API and the conversions between Python objects and the library's types.
#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <yaml-cpp/yaml.h>

#include "hook_call.h"
#include "softsight/config/config.h"

namespace softsight::python {

namespace py = pybind11;

void BindConfig(py::module_& m);
void BindSession(py::module_& m);
void BindTrack(py::module_& m);
void BindGeometry(py::module_& m);
void BindSim(py::module_& m);
void BindCalib(py::module_& m);
void BindStereo(py::module_& m);

// A config as Python holds it: the library's config and where it came from (a path or a dict),
// which is what a pickle carries (a Dask worker reloads it, with the same checks).
struct PyConfig {
  TrackingConfig config;
  py::object origin;                    // str path, or a dict.
  std::optional<std::string> method;    // The method override it was loaded with.
};

// The name a config given as a dict has in error messages ("<dict>: markers[0].name: ...").
inline constexpr const char* kDictConfigName = "<dict>";

// A path given as str, bytes or os.PathLike, as the bytes the file system sees (os.fsencode);
// nothing for other values. Throws InputError for a path holding a NUL byte.
std::optional<std::string> AsPath(const py::handle& source);

// A config from a path (str or os.PathLike), a mapping or a Config. `method` overrides every
// marker's method (as `--method`). Throws InputError with the library's messages.
PyConfig LoadPyConfig(const py::handle& source, const std::optional<std::string>& method);
TrackingConfig ResolveConfig(const py::handle& source, const std::optional<std::string>& method);

// A Python value as a YAML node with no marks (so messages name keys, not lines): mappings,
// lists and tuples, str, bool, int, float (inf and nan as YAML's .inf and .nan), None, os.PathLike
// and numpy scalars. Throws InputError naming `file` and the key path for anything else.
// Deeper than this a Python config is refused (InputError) rather than recursed into.
inline constexpr int kMaxConfigDepth = 64;
YAML::Node ToYaml(const py::handle& value, const std::string& file, const std::string& path,
                  int depth = 0);

// A header on the pixels of `array` when its layout allows it (no copy): uint8, HxWx3 (BGR) or
// HxW (gray), each row's pixels contiguous, rows any distance apart (slices of a bigger image
// too). Otherwise `keep_alive` receives a C-contiguous copy and the header is on that. Throws
// InputError naming `what` ("frame 12") for another dtype or shape.
cv::Mat ImageHeader(const py::array& array, const std::string& what, py::object* keep_alive);

// An image as a new numpy array (copied: the Mat's buffer is reused by its owner).
py::array ToNumpy(const cv::Mat& image);

// MeasurementDict and Optional: hook_call.h (the program's embedded hooks use them too).

// An (x, y) pair or a numpy array of two numbers as a point; throws ValueError naming `what`.
cv::Point2d ToPoint(const py::handle& value, const char* what);

}  // namespace softsight::python
