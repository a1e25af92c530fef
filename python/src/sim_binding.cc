// softsight.sim: the synthetic renderer with its exact truth, rendering into numpy arrays.
#include <memory>
#include <variant>

#include <pybind11/stl.h>

#include "bindings.h"
#include "softsight/core/error.h"
#include "softsight/sim/builtin_scenes.h"
#include "softsight/sim/chessboard.h"

namespace softsight::python {
namespace {

py::dict TruthDict(const SceneTruth& t) {
  py::dict markers;
  for (const MarkerTruth& m : t.markers) {
    py::dict one;
    one["x"] = m.centroid_px ? py::object(py::float_(m.centroid_px->x)) : py::object(py::none());
    one["y"] = m.centroid_px ? py::object(py::float_(m.centroid_px->y)) : py::object(py::none());
    one["visible_fraction"] = m.visible_fraction;
    markers[py::str(m.name)] = one;
  }
  const py::dict measurement = MeasurementDict(t.measurement);
  py::dict out;
  out["frame"] = t.frame_index;
  out["time_s"] = t.time_s;
  out["bend_deg"] = t.bend_deg;
  out["centreline_radius_px"] = Optional(t.centreline_radius_px);
  out["markers"] = markers;
  out["measurement"] = measurement;
  return out;
}

// A built-in scene by name, with the options a notebook changes most.
class PyScene {
 public:
  PyScene(const std::string& name, std::optional<int> frames, std::optional<std::pair<int, int>> size,
          std::optional<double> fps, std::optional<double> max_bend_deg, bool oscillate,
          std::optional<uint64_t> seed, const NoiseOptions& noise, int supersample)
      : name_(name) {
    RenderOptions render;
    render.supersample = supersample;
    BuiltinSceneOptions options = ParseBuiltinScene(name);
    if (auto* scene = std::get_if<SceneOptions>(&options)) {
      if (frames) scene->frame_count = *frames;
      if (size) scene->size = {size->first, size->second};
      if (fps) scene->fps = *fps;
      if (max_bend_deg) scene->max_bend_deg = *max_bend_deg;
      scene->oscillate = oscillate;
      if (seed) scene->seed = *seed;
      SetActuatorScene(name, scene);  // Last: the bench's look-alikes depend on the rest.
      fps_ = scene->fps;
      for (const SceneMarker& m : scene->markers) names_.push_back(m.name);
      actuator_ = std::make_unique<SyntheticScene>(*scene, noise, render);
    } else {
      auto& plate = std::get<PlateSceneOptions>(options);
      if (frames) plate.frame_count = *frames;
      if (size) plate.size = {size->first, size->second};
      if (fps) plate.fps = *fps;
      if (seed) plate.seed = *seed;
      fps_ = plate.fps;
      plate_ = std::make_unique<PlateScene>(plate, noise, render);
      for (int i = 0; i < plate.dot_count; ++i) names_.push_back("dot" + std::to_string(i));
    }
  }

  int frame_count() const { return actuator_ ? actuator_->frame_count() : plate_->frame_count(); }
  cv::Size size() const {
    return actuator_ ? actuator_->options().size : plate_->options().size;
  }

  py::tuple render(int index, std::optional<py::array> out) {
    if (index < 0 || index >= frame_count()) {
      throw py::index_error("frame " + std::to_string(index) + " is outside 0.." +
                            std::to_string(frame_count() - 1));
    }
    const cv::Size s = size();
    py::array_t<uint8_t> image;
    if (out) {
      // Drawn into as it is: an array of another type would be converted into a copy, and the
      // caller's `out` left untouched.
      if (!out->dtype().is(py::dtype::of<uint8_t>())) {
        throw py::value_error("out: expected a uint8 array, got " +
                              std::string(py::str(out->dtype())));
      }
      image = py::reinterpret_borrow<py::array_t<uint8_t>>(*out);
      if (!image || image.ndim() != 3 || image.shape(0) != s.height || image.shape(1) != s.width ||
          image.shape(2) != 3 || !(image.flags() & py::array::c_style) || !image.writeable()) {
        throw py::value_error("out: expected a writable C-contiguous uint8 array of shape (" +
                              std::to_string(s.height) + ", " + std::to_string(s.width) + ", 3)");
      }
    } else {
      image = py::array_t<uint8_t>({s.height, s.width, 3});
    }
    // The renderer draws straight into the array (its buffer is reused when size and type fit).
    cv::Mat header(s.height, s.width, CV_8UC3, image.mutable_data());
    SceneTruth truth;
    {
      py::gil_scoped_release release;
      truth = actuator_ ? actuator_->render(index, header) : plate_->render(index, header);
    }
    CV_Assert(header.data == image.data());
    return py::make_tuple(image, TruthDict(truth));
  }

  const std::string& name() const { return name_; }
  double fps() const { return fps_; }
  const std::vector<std::string>& marker_names() const { return names_; }

 private:
  std::string name_;
  double fps_ = 30.0;
  std::vector<std::string> names_;
  std::unique_ptr<SyntheticScene> actuator_;
  std::unique_ptr<PlateScene> plate_;
};

}  // namespace

void BindSim(py::module_& root) {
  py::module_ m = root.def_submodule(
      "sim",
      "The synthetic renderer with exact ground truth: the built-in scenes of `softsight synth` "
      "and `synth:NAME` inputs, rendered into numpy arrays.");
  py::class_<PyScene>(m, "Scene", R"doc(
A built-in scene: "bending", "wedge1", "wedge4", "bench" (look-alikes on a textured bench) or
"plate" (a gray plate with five white dots tilting and growing). ``render(i)`` returns the
frame (uint8 HxWx3 BGR) and its exact truth: each marker's centroid of its rendered visible
area, the bend, and the paper's measurements from the true centroids.

    scene = softsight.sim.Scene("bending", frames=30, noise=2.0)
    image, truth = scene.render(0)
    truth["markers"]["red"]["x"], truth["measurement"]["angle_deg"])doc")
      .def(py::init([](const std::string& name, std::optional<int> frames,
                       std::optional<std::pair<int, int>> size, std::optional<double> fps,
                       std::optional<double> max_bend_deg, bool oscillate,
                       std::optional<uint64_t> seed, double noise, double blur,
                       std::pair<double, double> gain, uint64_t noise_seed, int supersample) {
             NoiseOptions n;
             n.sigma = noise;
             n.blur_sigma_px = blur;
             n.gain_start = gain.first;
             n.gain_end = gain.second;
             n.seed = noise_seed;
             return std::make_unique<PyScene>(name, frames, size, fps, max_bend_deg, oscillate,
                                              seed, n, supersample);
           }),
           py::arg("name") = "bending", py::kw_only(), py::arg("frames") = py::none(),
           py::arg("size") = py::none(), py::arg("fps") = py::none(),
           py::arg("max_bend_deg") = py::none(), py::arg("oscillate") = false,
           py::arg("seed") = py::none(), py::arg("noise") = 0.0, py::arg("blur") = 0.0,
           py::arg("gain") = std::pair<double, double>(1.0, 1.0), py::arg("noise_seed") = 7,
           py::arg("supersample") = 4,
           "size is (width, height); noise the sensor noise sigma (grey levels), blur the optical "
           "blur sigma (px), gain the illumination gain at the first and last frame. Raises "
           "InputError naming a bad option.")
      .def("render", &PyScene::render, py::arg("index"), py::arg("out") = py::none(),
           "(image, truth) of frame `index`; `out` (a uint8 HxWx3 array) is drawn into and "
           "returned instead of a new array.")
      .def_property_readonly("frame_count", &PyScene::frame_count)
      .def_property_readonly("fps", &PyScene::fps)
      .def_property_readonly("name", &PyScene::name)
      .def_property_readonly("size", [](const PyScene& s) {
        return py::make_tuple(s.size().width, s.size().height);
      }, "(width, height)")
      .def_property_readonly("marker_names", &PyScene::marker_names)
      .def("__len__", &PyScene::frame_count);

  m.def(
      "render_chessboard",
      [](const py::array_t<double>& camera_matrix, const std::vector<double>& distortion,
         std::pair<int, int> inner_corners, double square_mm, std::pair<int, int> size,
         double distance_mm,
         double tilt_x_deg, double tilt_y_deg, double roll_deg, double noise) {
        CameraModel camera;
        camera.image_size = {size.first, size.second};
        if (camera_matrix.ndim() != 2 || camera_matrix.shape(0) != 3 || camera_matrix.shape(1) != 3) {
          throw py::value_error("camera_matrix: expected a 3x3 array");
        }
        const auto k = camera_matrix.unchecked<2>();
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) camera.camera_matrix(r, c) = k(r, c);
        }
        camera.distortion = distortion;
        ChessboardPattern pattern;
        pattern.inner_corners = {inner_corners.first, inner_corners.second};
        pattern.square_mm = square_mm;
        ChessboardLook look;
        look.noise_sigma = noise;
        cv::Mat image;
        ChessboardView view;
        {
          py::gil_scoped_release release;
          const ChessboardRenderer renderer(camera, pattern, look);
          view = renderer.render(
              LookAtBoard(pattern, distance_mm, tilt_x_deg, tilt_y_deg, roll_deg), image);
        }
        py::array_t<float> corners({static_cast<py::ssize_t>(view.corners_px.size()), py::ssize_t{2}});
        for (size_t i = 0; i < view.corners_px.size(); ++i) {
          corners.mutable_at(i, 0) = view.corners_px[i].x;
          corners.mutable_at(i, 1) = view.corners_px[i].y;
        }
        return py::make_tuple(ToNumpy(image), corners);
      },
      py::arg("camera_matrix"), py::arg("distortion") = std::vector<double>{}, py::kw_only(),
      py::arg("inner_corners") = std::pair<int, int>(9, 6), py::arg("square_mm") = 25.0,
      py::arg("size") = std::pair<int, int>(640, 480), py::arg("distance_mm") = 500.0,
      py::arg("tilt_x_deg") = 0.0, py::arg("tilt_y_deg") = 0.0, py::arg("roll_deg") = 0.0,
      py::arg("noise") = 0.0,
      "A chessboard as a camera with KNOWN intrinsics and distortion sees it: (gray image, true "
      "inner corners (N, 2) in detection order). For testing calibration against exact truth.");
}

}  // namespace softsight::python
