// Conversions between Python objects and the library's types, and the Config class.
#include <cmath>
#include <filesystem>
#include <cstring>

#include <pybind11/stl.h>

#include "bindings.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/io/csv_columns.h"
#include "softsight/pipeline/sinks.h"

namespace softsight::python {
namespace {

std::string Describe(const py::handle& value) {
  return std::string(py::str(py::type::of(value).attr("__name__")));
}

std::string FloatText(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  return py::str(py::float_(value));  // Python's shortest round-trip text ("0.1", "1e-05").
}

// The config with the files it names relative to itself (`template.file`, `camera:`) made
// relative to `target`, where it is saved, so the saved config names the same files from there.
TrackingConfig RebasedConfig(const TrackingConfig& config, const std::string& target) {
  namespace fs = std::filesystem;
  const auto rebased = [&](const std::string& path) {
    if (path.empty() || fs::path(path).is_absolute()) return path;
    std::error_code error;
    const fs::path from = config.source_file.empty() || config.source_file == kDictConfigName
                              ? fs::current_path(error)
                              : fs::absolute(config.source_file, error).parent_path();
    const fs::path to = fs::absolute(target, error).parent_path();
    if (error) return path;
    const fs::path relative = (from / path).lexically_normal().lexically_proximate(to);
    return relative.empty() ? path : relative.string();
  };
  TrackingConfig out = config;
  for (auto& [name, file] : out.template_files) file = rebased(file);
  if (out.camera_file) out.camera_file = rebased(*out.camera_file);
  for (ConfigChange& change : out.changes) change.template_file = rebased(change.template_file);
  return out;
}

}  // namespace

std::optional<std::string> AsPath(const py::handle& source) {
  if (!py::isinstance<py::str>(source) && !py::isinstance<py::bytes>(source) &&
      !py::hasattr(source, "__fspath__")) {
    return std::nullopt;
  }
  // os.fsencode gives the bytes the file system sees: the same for a str, a bytes path and a
  // pathlib.Path, also for names that are not UTF-8 (Python's surrogateescape).
  const std::string path = py::bytes(py::module_::import("os").attr("fsencode")(source));
  if (path.find('\0') != std::string::npos) {
    throw InputError(EscapeForMessage(path) + ": a path holding a NUL byte");
  }
  return path;
}

YAML::Node ToYaml(const py::handle& value, const std::string& file, const std::string& path,
                  int depth) {
  const auto error = [&](const std::string& problem) {
    return InputError(file + ": " + (path.empty() ? "top level" : EscapeForMessage(path, 200)) +
                      ": " + problem);
  };
  // A config is a few levels deep; the bound keeps a dict that contains itself, or one nested
  // thousands deep, from overflowing the stack (the recursion below is one frame per level).
  if (depth > kMaxConfigDepth) {
    throw error("nested deeper than " + std::to_string(kMaxConfigDepth) +
                " levels (a dict or list that contains itself?)");
  }
  // None would read as "not given" (the default: no mm columns for scale_mm_per_px), silently.
  if (value.is_none()) throw error("None is not a config value (leave the key out for its default)");
  if (py::isinstance<py::bool_>(value)) return YAML::Node(value.cast<bool>() ? "true" : "false");
  if (py::isinstance<py::str>(value)) {
    // Tagged as YAML tags a quoted scalar: "0.25" stays a string, refused where a number goes.
    YAML::Node node(value.cast<std::string>());
    node.SetTag("!");
    return node;
  }
  if (py::isinstance<py::int_>(value)) return YAML::Node(std::string(py::str(value)));
  if (py::isinstance<py::float_>(value)) return YAML::Node(FloatText(value.cast<double>()));
  if (py::isinstance<py::dict>(value) || py::hasattr(value, "keys")) {
    YAML::Node node(YAML::NodeType::Map);
    for (const py::handle key : value.attr("keys")()) {
      if (!py::isinstance<py::str>(key)) {
        throw error("key " + std::string(py::repr(key)) +
                    " is not a string (config keys are names)");
      }
      const std::string name = key.cast<std::string>();
      node[name] = ToYaml(value[key], file, path.empty() ? name : path + "." + name, depth + 1);
    }
    return node;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value) ||
      py::isinstance<py::array>(value)) {
    YAML::Node node(YAML::NodeType::Sequence);
    size_t i = 0;
    for (const py::handle item : value) {
      node.push_back(ToYaml(item, file, path + "[" + std::to_string(i++) + "]", depth + 1));
    }
    return node;
  }
  if (AsPath(value)) return YAML::Node(*AsPath(value));
  // numpy scalars: np.int64 is not an int, np.float32 not a float.
  if (py::hasattr(value, "dtype") && py::hasattr(value, "item")) {
    return ToYaml(value.attr("item")(), file, path, depth + 1);
  }
  throw error(WithArticle(Describe(value)) +
              " cannot be a config value (use numbers, strings, lists, dicts)");
}

PyConfig LoadPyConfig(const py::handle& source, const std::optional<std::string>& method) {
  if (py::isinstance<PyConfig>(source)) {
    const PyConfig& given = source.cast<const PyConfig&>();
    if (!method || method == given.method) return given;
    return LoadPyConfig(given.origin, method);
  }
  PyConfig out;
  out.method = method;
  if (const std::optional<std::string> path = AsPath(source)) {
    out.config = LoadTrackingConfig(*path, method);
    out.origin = py::module_::import("os").attr("fsdecode")(py::bytes(*path));
    return out;
  }
  if (py::isinstance<py::dict>(source) || py::hasattr(source, "keys")) {
    YAML::Node root = ToYaml(source, kDictConfigName, "");
    out.config = ReadTrackingConfig(root, kDictConfigName, method);
    // A copy: later changes to the caller's dict do not change what a pickle reloads.
    out.origin = py::module_::import("copy").attr("deepcopy")(source);
    return out;
  }
  throw py::type_error("config: expected a path, a dict or a softsight.Config, got " +
                       WithArticle(Describe(source)));
}

TrackingConfig ResolveConfig(const py::handle& source, const std::optional<std::string>& method) {
  if (py::isinstance<PyConfig>(source) && !method) return source.cast<const PyConfig&>().config;
  return LoadPyConfig(source, method).config;
}

cv::Mat ImageHeader(const py::array& array, const std::string& what, py::object* keep_alive) {
  const py::dtype dtype = array.dtype();
  if (dtype.kind() != 'u' || dtype.itemsize() != 1) {
    const std::string dtype_name = py::str(dtype.attr("name"));
    throw InputError(what + ": " + WithArticle(dtype_name + " array") +
                     "; softsight needs uint8 pixels (an HxWx3 BGR or HxW gray array, as "
                     "cv2.VideoCapture.read() gives)");
  }
  const bool colour = array.ndim() == 3 && array.shape(2) == 3;
  if (!(array.ndim() == 2 || colour) || array.shape(0) == 0 || array.shape(1) == 0) {
    std::string shape;
    for (py::ssize_t i = 0; i < array.ndim(); ++i) {
      shape += (i > 0 ? ", " : "") + std::to_string(array.shape(i));
    }
    if (array.ndim() == 1) shape += ",";
    throw InputError(what + ": an array of shape (" + shape +
                     "); softsight needs HxWx3 (BGR) or HxW (gray) pixels");
  }
  const int channels = colour ? 3 : 1;
  const py::ssize_t rows = array.shape(0), cols = array.shape(1);
  const bool pixels_contiguous =
      array.strides(1) == channels && (!colour || array.strides(2) == 1) &&
      array.strides(0) >= cols * channels;
  py::array source = array;
  if (!pixels_contiguous) {
    // A view with a column stride or negative strides (frame[:, ::2], a flipped image): copied.
    source = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(array);
    *keep_alive = source;
  }
  // cv::Mat never frees external data; the array outlives the call that uses the header.
  return cv::Mat(static_cast<int>(rows), static_cast<int>(cols), colour ? CV_8UC3 : CV_8UC1,
                 const_cast<void*>(source.data()), static_cast<size_t>(source.strides(0)));
}

py::array ToNumpy(const cv::Mat& image) {
  CV_Assert(image.depth() == CV_8U);
  std::vector<py::ssize_t> shape = {image.rows, image.cols};
  if (image.channels() > 1) shape.push_back(image.channels());
  py::array_t<uint8_t> out(shape);
  const size_t row_bytes = image.cols * image.elemSize();
  for (int r = 0; r < image.rows; ++r) {
    std::memcpy(out.mutable_data(r), image.ptr(r), row_bytes);
  }
  return out;
}

cv::Point2d ToPoint(const py::handle& value, const char* what) {
  std::vector<double> xy;
  try {
    xy = value.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
  }
  if (xy.size() != 2) {
    throw py::value_error(std::string(what) + ": expected a point (x, y), got " +
                          std::string(py::repr(value)));
  }
  return {xy[0], xy[1]};
}

void BindConfig(py::module_& m) {
  py::class_<PyConfig>(m, "Config", R"doc(
A checked tracking config: markers, their methods and parameters, the triple or chain, the
metric model. Made by ``softsight.load_config(path_or_dict)``; every key is the YAML file's
(``softsight config --doc`` lists them, examples/markers.yaml documents them).
Pickles as where it came from (the path or the dict), so a Dask worker reloads and re-checks it.)doc")
      .def_property_readonly(
          "marker_names",
          [](const PyConfig& c) {
            std::vector<std::string> names;
            for (const MarkerSpec& spec : c.config.markers) names.push_back(spec.name);
            return names;
          },
          "The markers' names, in config order (the order of the CSV's per-marker columns).")
      .def_property_readonly(
          "methods",
          [](const PyConfig& c) {
            py::dict out;
            for (const MarkerSpec& spec : c.config.markers) out[py::str(spec.name)] = TrackerMethodName(spec.params);
            return out;
          },
          "Each marker's tracking method: colour, sad, ssd or zncc.")
      .def_property_readonly(
          "triple",
          [](const PyConfig& c) -> py::object {
            const MeasureOptions& m = c.config.measure;
            if (!m.has_triple()) return py::none();
            return py::make_tuple(m.base, m.middle, m.tip);
          },
          "(base, middle, tip) marker names, or None without a triple.")
      .def_property_readonly(
          "chain", [](const PyConfig& c) { return c.config.measure.chain; },
          "The chain's marker names, base to tip (empty without a chain).")
      .def_property_readonly(
          "metric", [](const PyConfig& c) { return !c.config.measure.metric.empty(); },
          "Whether a scale or plane is known (the results then have _mm columns).")
      .def_property_readonly(
          "columns", [](const PyConfig& c) { return TrackingColumns(c.config).names(); },
          "The CSV's column names for this config, in order (softsight.track's keys).")
      .def_property_readonly(
          "source", [](const PyConfig& c) { return c.origin; },
          "Where the config came from: the path, or (a copy of) the dict.")
      .def(
          "save", [](const PyConfig& c, const py::object& path) {
            const std::optional<std::string> file = AsPath(path);
            if (!file) throw py::type_error("path: a str, bytes or os.PathLike");
            SaveTrackingConfig(RebasedConfig(c.config, *file), *file);
          },
          py::arg("path"), "Writes the config as YAML that load_config reads to the same values.")
      .def("__repr__",
           [](const PyConfig& c) {
             std::string names;
             for (const MarkerSpec& spec : c.config.markers) {
               names += (names.empty() ? "" : ", ") + spec.name + " (" + TrackerMethodName(spec.params) + ")";
             }
             return "softsight.Config(" + std::string(py::repr(c.origin)) + ": " + names + ")";
           })
      .def(py::pickle(
          [](const PyConfig& c) { return py::make_tuple(c.origin, c.method); },
          [](const py::tuple& state) {
            return LoadPyConfig(state[0], state[1].cast<std::optional<std::string>>());
          }));

  m.def(
      "load_config",
      [](const py::object& source, const std::optional<std::string>& method) {
        return LoadPyConfig(source, method);
      },
      py::arg("source"), py::arg("method") = py::none(), R"doc(
Reads and checks a tracking config.

``source`` is a YAML file (str or os.PathLike) or a dict with the file's keys; ``method``
("colour", "sad", "ssd", "zncc") overrides every marker's method, as ``softsight track
--method``. Relative paths in a file (camera, template and plane files) are beside the file; in
a dict, from the working directory.

Raises softsight.InputError with the CLI's message, e.g.
``markers.yaml:7: markers[0].blob.min_circularity: 1.5 must lie within 0..1``
(a dict has no lines: ``<dict>: markers[0].blob.min_circularity: ...``).)doc");
}

}  // namespace softsight::python
