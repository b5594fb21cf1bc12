#include "bindings.hpp"

#include "mechbal/version.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() = "mechbal C++ core: shaking wrench, serial chains, trajectories, real-time controllers";
  m.attr("__version__") = MECHBAL_VERSION;
  mechbal::pyb::bind_core(m);
  mechbal::pyb::bind_trajectory(m);
  mechbal::pyb::bind_chain(m);
}
