// Python bindings: Robot models and URDF writing.
#include "bindings.h"

namespace partsim::python {

void BindRobots(py::module_& m) {}

}  // namespace partsim::python
