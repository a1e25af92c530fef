// softsight._core: the compiled part of the `softsight` Python package (see softsight/__init__.py
// for the public names and docs/python.md for a tour).
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "softsight/core/error.h"
#include "softsight/version.h"

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
  m.doc() = "softsight's C++ library for Python (use the `softsight` package, not this module).";
  m.attr("__version__") = softsight::kVersion;
  m.attr("__license__") = softsight::kLicense;

  // Bad input (a missing file, an unknown key, a corrupt frame, a frame of the wrong dtype or
  // shape): the library's one-line message, as `softsight` prints it after "error: ".
  // Leaked on purpose: a static py::object would be released after the interpreter is gone.
  static auto* input_error =
      new py::exception<softsight::InputError>(m, "InputError", PyExc_ValueError);
  input_error->attr("__module__") = "softsight";
  input_error->doc() =
      "Bad input: a missing or corrupt file, a config with an unknown key or a bad value, a\n"
      "frame of the wrong dtype or shape. The message is the one line `softsight` prints,\n"
      "naming the file, key or frame. A ValueError.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const softsight::InputError& e) {
      (*input_error)(e.what());
    } catch (const cv::Exception& e) {
      // Not a user error: a broken invariant inside OpenCV or softsight (the CLI exits 1 on it).
      PyErr_SetString(PyExc_RuntimeError, (std::string("OpenCV error: ") + e.what()).c_str());
    }
  });

  softsight::python::BindConfig(m);
  softsight::python::BindSession(m);
  softsight::python::BindTrack(m);
  softsight::python::BindGeometry(m);
  softsight::python::BindSim(m);
  softsight::python::BindCalib(m);
  softsight::python::BindStereo(m);
}
