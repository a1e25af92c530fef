// softsight.sim: the synthetic renderer with its exact truth.
#include "bindings.h"

namespace softsight::python {

void BindSim(py::module_& root) {
  root.def_submodule("sim", "The synthetic actuator renderer and its exact ground truth.");
}

}  // namespace softsight::python
