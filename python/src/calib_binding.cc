// softsight.calib: chessboard calibration, undistortion and the metric scale, on numpy arrays.
#include <cmath>

#include <pybind11/stl.h>

#include "bindings.h"
#include "softsight/calib/camera_calibration.h"
#include "softsight/core/error.h"

namespace softsight::python {
namespace {

py::array_t<double> Matrix(const cv::Matx33d& m) {
  py::array_t<double> out({3, 3});
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.mutable_at(r, c) = m(r, c);
  }
  return out;
}

cv::Matx33d ToMatrix(const py::handle& value, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) {
    throw py::value_error(std::string(what) + ": expected a 3x3 array");
  }
  cv::Matx33d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = a.at(r, c);
  }
  return m;
}

py::dict CameraDict(const CameraIntrinsics& camera) {
  py::dict out;
  out["image_size"] = py::make_tuple(camera.image_size.width, camera.image_size.height);
  out["camera_matrix"] = Matrix(camera.camera_matrix);
  out["distortion"] = py::array_t<double>(camera.distortion.size(), camera.distortion.data());
  return out;
}

// A camera dict, checked as the camera file reader checks a file: a missing key or a value
// OpenCV would refuse deep inside is an InputError naming the key, not a KeyError or an OpenCV
// RuntimeError.
CameraIntrinsics ToCamera(const py::dict& camera) {
  for (const char* key : {"image_size", "camera_matrix", "distortion"}) {
    if (!camera.contains(key)) {
      throw InputError(std::string("camera: missing key '") + key +
                       "' (a camera is {'image_size': (w, h), 'camera_matrix': 3x3, "
                       "'distortion': (k1, k2, p1, p2[, k3])}, as load_camera gives)");
    }
  }
  CameraIntrinsics out;
  std::pair<int, int> size;
  try {
    size = camera["image_size"].cast<std::pair<int, int>>();
    out.distortion = camera["distortion"].cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw InputError("camera: image_size must be (width, height) and distortion a list of numbers");
  }
  if (size.first <= 0 || size.second <= 0) {
    throw InputError("camera: image_size (" + std::to_string(size.first) + ", " +
                     std::to_string(size.second) + ") must be positive");
  }
  out.image_size = {size.first, size.second};
  out.camera_matrix = ToMatrix(camera["camera_matrix"], "camera_matrix");
  const size_t n = out.distortion.size();
  if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    throw InputError("camera: distortion has " + std::to_string(n) +
                     " coefficients; OpenCV takes 4, 5, 8, 12 or 14");
  }
  for (double v : out.distortion) {
    if (!std::isfinite(v)) throw InputError("camera: distortion holds a value that is not finite");
  }
  const cv::Matx33d k = out.camera_matrix;
  if (!(k(0, 0) > 0.0 && k(1, 1) > 0.0 && std::isfinite(k(0, 2)) && std::isfinite(k(1, 2)))) {
    throw InputError("camera: camera_matrix needs positive, finite focal lengths (fx, fy)");
  }
  return out;
}

std::vector<cv::Point2f> ToCorners(const py::handle& value) {
  const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != 2 || a.shape(1) != 2) throw py::value_error("corners: expected (N, 2)");
  std::vector<cv::Point2f> out;
  for (py::ssize_t i = 0; i < a.shape(0); ++i) out.emplace_back(a.at(i, 0), a.at(i, 1));
  return out;
}

py::array_t<float> FromCorners(const std::vector<cv::Point2f>& corners) {
  py::array_t<float> out({static_cast<py::ssize_t>(corners.size()), py::ssize_t{2}});
  for (size_t i = 0; i < corners.size(); ++i) {
    out.mutable_at(i, 0) = corners[i].x;
    out.mutable_at(i, 1) = corners[i].y;
  }
  return out;
}

ChessboardSpec Board(std::pair<int, int> inner_corners, double square_mm) {
  ChessboardSpec board;
  board.inner_corners = {inner_corners.first, inner_corners.second};
  board.square_mm = square_mm;
  std::string problem;
  if (!board.Check(&problem)) throw InputError("chessboard: " + problem);
  return board;
}

py::dict PlaneDict(const PlaneCalibration& plane) {
  py::dict out;
  out["plane_mm_from_image"] = Matrix(plane.plane_mm_from_image);
  out["mm_per_px"] = plane.mm_per_px;
  out["rms_mm"] = plane.rms_mm;
  return out;
}

}  // namespace

void BindCalib(py::module_& root) {
  py::module_ m = root.def_submodule(
      "calib",
      "Camera calibration from chessboard views (intrinsics, lens distortion), undistortion, "
      "and the scale from pixels to millimetres in the actuator's plane. A camera is a dict: "
      "{'image_size': (w, h), 'camera_matrix': 3x3, 'distortion': (k1, k2, p1, p2[, k3])}.");
  m.def(
      "find_chessboard",
      [](const py::array& image, std::pair<int, int> inner_corners) -> py::object {
        py::object copy;
        const cv::Mat pixels = ImageHeader(image, "image", &copy);
        std::optional<std::vector<cv::Point2f>> corners;
        {
          py::gil_scoped_release release;
          corners = FindChessboard(pixels, {inner_corners.first, inner_corners.second});
        }
        if (!corners) return py::none();
        return FromCorners(*corners);
      },
      py::arg("image"), py::arg("inner_corners") = std::pair<int, int>(9, 6),
      "The board's inner corners (N, 2) with sub-pixel refinement, or None when the whole board "
      "is not visible. `image` is uint8 gray or BGR; inner_corners (per row, per column).");

  py::class_<ChessboardCalibrator>(m, "Calibrator", R"doc(
Accumulates chessboard views one image at a time, then calibrates:

    cal = softsight.calib.Calibrator(inner_corners=(9, 6), square_mm=25)
    for name, image in views: cal.add(name, image)
    camera = cal.calibrate()   # dict: camera_matrix, distortion, image_size, rms_px, used, not_found)doc")
      .def(py::init([](std::pair<int, int> inner_corners, double square_mm, bool estimate_k3,
                       int min_views) {
             CalibrationOptions options;
             options.board = Board(inner_corners, square_mm);
             options.estimate_k3 = estimate_k3;
             options.min_views = min_views;
             return std::make_unique<ChessboardCalibrator>(options);
           }),
           py::arg("inner_corners") = std::pair<int, int>(9, 6), py::arg("square_mm") = 25.0,
           py::arg("estimate_k3") = false, py::arg("min_views") = 3)
      .def(
          "add",
          [](ChessboardCalibrator& c, const std::string& name, const py::array& image) {
            py::object copy;
            const cv::Mat pixels = ImageHeader(image, name, &copy);
            py::gil_scoped_release release;
            return c.add(name, pixels);
          },
          py::arg("name"), py::arg("image"),
          "Looks for the board in `image`; returns whether it was found. InputError when the "
          "size differs from the first image's.")
      .def(
          "calibrate",
          [](const ChessboardCalibrator& c) {
            CalibrationResult result;
            {
              py::gil_scoped_release release;
              result = c.calibrate();
            }
            py::dict out = CameraDict(result.camera);
            out["rms_px"] = result.rms_px;
            out["used"] = result.used;
            out["not_found"] = result.not_found;
            return out;
          },
          "Calibrates from the views with a board (InputError with fewer than min_views).")
      .def_property_readonly("views_found", &ChessboardCalibrator::views_found)
      .def_property_readonly("views_seen", &ChessboardCalibrator::views_seen);

  m.def(
      "load_camera", [](const std::string& path) { return CameraDict(LoadCameraIntrinsics(path)); },
      py::arg("path"), "A camera file written by `softsight calibrate` (InputError naming the key).");
  m.def(
      "undistort_points",
      [](const py::object& points, const py::dict& camera) {
        const Undistorter undistorter(ToCamera(camera));
        std::vector<cv::Point2f> out;
        undistorter.undistort_points(ToCorners(points), out);
        return FromCorners(out);
      },
      py::arg("points"), py::arg("camera"),
      "Raw (distorted) pixel positions (N, 2) to undistorted ones (same camera matrix).");
  m.def(
      "undistort",
      [](const py::array& image, const py::dict& camera) {
        py::object copy;
        const cv::Mat pixels = ImageHeader(image, "image", &copy);
        const Undistorter undistorter(ToCamera(camera));
        cv::Mat out;
        undistorter.apply(pixels, out);
        return ToNumpy(out);
      },
      py::arg("image"), py::arg("camera"), "The image without lens distortion (a new array).");
  m.def(
      "plane_from_corners",
      [](const py::object& corners, std::pair<int, int> inner_corners, double square_mm) {
        return PlaneDict(PlaneFromCorners(ToCorners(corners), Board(inner_corners, square_mm)));
      },
      py::arg("corners"), py::arg("inner_corners") = std::pair<int, int>(9, 6),
      py::arg("square_mm") = 25.0,
      "The actuator's plane from a board's inner corners in UNDISTORTED pixels: "
      "{'plane_mm_from_image': 3x3, 'mm_per_px', 'rms_mm'}.");
  m.def(
      "scale_from_two_points",
      [](const py::object& a, const py::object& b, double distance_mm) {
        return ScaleFromTwoPoints(ToPoint(a, "a"), ToPoint(b, "b"), distance_mm);
      },
      py::arg("a"), py::arg("b"), py::arg("distance_mm"),
      "mm per pixel from two image points a known distance apart.");
}

}  // namespace softsight::python
