// softsight.geometry: the paper's measurements (eqs. 7-9) and the circle fit on numpy points.
#include <limits>

#include <pybind11/stl.h>

#include "bindings.h"
#include "softsight/geometry/circle_fit.h"
#include "softsight/geometry/triangle.h"

namespace softsight::python {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Points as an (N, 2) float64 array; a single (2,) point counts as N = 1 (`single` set).
py::array_t<double> Points(const py::handle& value, const char* what, bool* single) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a) throw py::value_error(std::string(what) + ": expected points (x, y) as numbers");
  *single = a.ndim() == 1;
  if (!((a.ndim() == 1 && a.shape(0) == 2) || (a.ndim() == 2 && a.shape(1) == 2))) {
    throw py::value_error(std::string(what) + ": expected a point (x, y) or an (N, 2) array");
  }
  return a;
}

// f(base, middle, tip) over N triples: a float (None when undefined) for one triple, else an
// array with NaN where undefined.
template <typename F>
py::object OverTriples(const py::handle& base, const py::handle& middle, const py::handle& tip,
                       F f) {
  bool s1 = false, s2 = false, s3 = false;
  const auto a = Points(base, "base", &s1), b = Points(middle, "middle", &s2),
             c = Points(tip, "tip", &s3);
  const py::ssize_t n = a.size() / 2;
  if (b.size() / 2 != n || c.size() / 2 != n) {
    throw py::value_error("base, middle and tip must hold the same number of points");
  }
  const double *pa = a.data(), *pb = b.data(), *pc = c.data();
  if (s1 && s2 && s3) {
    return Optional(f({pa[0], pa[1]}, {pb[0], pb[1]}, {pc[0], pc[1]}));
  }
  py::array_t<double> out(n);
  double* po = out.mutable_data();
  for (py::ssize_t i = 0; i < n; ++i) {
    po[i] = f({pa[2 * i], pa[2 * i + 1]}, {pb[2 * i], pb[2 * i + 1]}, {pc[2 * i], pc[2 * i + 1]})
                .value_or(kNaN);
  }
  return out;
}

std::vector<cv::Point2d> PointList(const py::handle& value) {
  bool single = false;
  const auto a = Points(value, "points", &single);
  std::vector<cv::Point2d> out;
  for (py::ssize_t i = 0; i < a.size() / 2; ++i) out.emplace_back(a.data()[2 * i], a.data()[2 * i + 1]);
  return out;
}

}  // namespace

void BindGeometry(py::module_& root) {
  py::module_ m = root.def_submodule(
      "geometry",
      "The paper's measurements (section 3, eqs. 7-9) and the circle fit, on points in any unit "
      "(pixels in, pixels out). Points are (x, y) pairs or (N, 2) arrays; a value that cannot be "
      "computed is None for one point, NaN in an array.");
  m.def(
      "angle_deg",
      [](const py::object& base, const py::object& middle, const py::object& tip) {
        return OverTriples(base, middle, tip, AngleAtMiddleDeg);
      },
      py::arg("base"), py::arg("middle"), py::arg("tip"),
      "Angle at `middle` between the rays to `base` and `tip` (eq. 7), degrees in [0, 180]; 180 "
      "when straight. None/NaN when middle coincides with base or tip.");
  m.def(
      "chord",
      [](const py::object& base, const py::object& tip) {
        return OverTriples(base, base, tip, [](const cv::Point2d& a, const cv::Point2d&,
                                               const cv::Point2d& c) -> std::optional<double> {
          return Chord(a, c);
        });
      },
      py::arg("base"), py::arg("tip"), "Chord c = |base - tip|.");
  m.def(
      "sagitta",
      [](const py::object& base, const py::object& middle, const py::object& tip) {
        return OverTriples(base, middle, tip, Sagitta);
      },
      py::arg("base"), py::arg("middle"), py::arg("tip"),
      "Distance d of `middle` from the line through base and tip (None when they coincide).");
  m.def(
      "radius",
      [](const py::object& base, const py::object& middle, const py::object& tip) {
        return OverTriples(base, middle, tip, [](const cv::Point2d& a, const cv::Point2d& b,
                                                 const cv::Point2d& c) {
          return MeasureTriangle(a, b, c).radius;
        });
      },
      py::arg("base"), py::arg("middle"), py::arg("tip"),
      "Radius of curvature from chord and sagitta (eq. 8); None when straight.");
  m.def(
      "arc_length",
      [](const py::object& base, const py::object& middle, const py::object& tip) {
        return OverTriples(base, middle, tip, [](const cv::Point2d& a, const cv::Point2d& b,
                                                 const cv::Point2d& c) {
          return MeasureTriangle(a, b, c).arc_length;
        });
      },
      py::arg("base"), py::arg("middle"), py::arg("tip"),
      "Arc length (eq. 9; the major arc past a half circle; the chord when straight).");
  m.def(
      "circumradius",
      [](const py::object& base, const py::object& middle, const py::object& tip) {
        return OverTriples(base, middle, tip, Circumradius);
      },
      py::arg("base"), py::arg("middle"), py::arg("tip"),
      "Radius of the circle through the three points (None when collinear).");
  m.def("radius_from_chord_sagitta",
        [](double c, double d) { return Optional(RadiusFromChordSagitta(c, d)); },
        py::arg("chord"), py::arg("sagitta"), "Eq. 8: R = (c^2 + 4 d^2) / (8 d); None for d = 0.");
  m.def("arc_length_from_chord_sagitta",
        [](double c, double d) { return Optional(ArcLengthFromChordSagitta(c, d)); },
        py::arg("chord"), py::arg("sagitta"), "Eq. 9: L = R * theta (the chord when d = 0).");
  m.def(
      "fit_circle",
      [](const py::object& points) -> py::object {
        const std::optional<CircleFit> fit = FitCircleTaubin(PointList(points));
        if (!fit) return py::none();
        py::dict out;
        out["centre"] = py::make_tuple(fit->centre.x, fit->centre.y);
        out["radius"] = fit->radius;
        out["rms_residual"] = fit->rms_residual;
        return out;
      },
      py::arg("points"),
      "Taubin's least-squares circle through (N, 2) points: {'centre': (x, y), 'radius', "
      "'rms_residual'}, or None for fewer than 3, coincident or collinear points.");
  m.def(
      "arc_length_through_points",
      [](const py::object& points) -> py::object {
        const std::vector<cv::Point2d> p = PointList(points);
        const std::optional<CircleFit> fit = FitCircleTaubin(p);
        if (!fit) return py::none();
        return Optional(ArcLengthThroughPoints(*fit, p));
      },
      py::arg("points"),
      "Length along the fitted circle from the first to the last point through the others in "
      "order (None when no circle fits).");
}

}  // namespace softsight::python
