// Python bindings: Kinematics, IK, trajectories, controllers and the IMU.
#include "bindings.h"

namespace partsim::python {

void BindControl(py::module_& m) {}

}  // namespace partsim::python
