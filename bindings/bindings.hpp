#pragma once
// pybind11 glue only: each bind_* function converts types for one header of the core.
#include <pybind11/pybind11.h>

namespace mechbal::pyb {
void bind_core(pybind11::module_& m);        // status, rigid bodies, shaking wrench
void bind_trajectory(pybind11::module_& m);  // rest-to-rest time laws
void bind_chain(pybind11::module_& m);       // serial chains, KDL dynamics
}  // namespace mechbal::pyb
