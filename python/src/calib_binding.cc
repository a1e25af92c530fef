// softsight.calib: chessboard calibration, undistortion and the metric scale.
#include "bindings.h"

namespace softsight::python {

void BindCalib(py::module_& root) {
  root.def_submodule("calib", "Camera calibration from chessboard views and the plane's scale.");
}

}  // namespace softsight::python
