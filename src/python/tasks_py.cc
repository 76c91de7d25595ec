// Python bindings: Door-opening and drawer-pulling tasks.
#include "bindings.h"

namespace partsim::python {

void BindTasks(py::module_& m) {}

}  // namespace partsim::python
