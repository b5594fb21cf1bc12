#include <algorithm>

#include "bindings.hpp"
#include "mechbal/version.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() = "mechbal C++ core: shaking wrench, serial chains, trajectories, real-time controllers";
  m.attr("__version__") = MECHBAL_VERSION;
  auto entries = mechbal::pyb::binders();
  std::stable_sort(entries.begin(), entries.end(),
                   [](const auto& a, const auto& b) { return a.order < b.order; });
  for (const auto& e : entries) e.fn(m);
}
