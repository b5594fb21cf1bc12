#pragma once
// pybind11 glue only: each bindings/*.cpp file converts the types of one area of the core and
// registers its binder with MECHBAL_REGISTER_BINDINGS; module.cpp runs every registered binder.
// A new area is a new file: nothing else to edit.
#include <pybind11/pybind11.h>

#include <functional>
#include <string>
#include <vector>

namespace mechbal::pyb {

using Binder = void (*)(pybind11::module_&);

struct BinderEntry {
  int order;  ///< lower first (enums used by later areas are bound early)
  std::string name;
  Binder fn;
};

inline std::vector<BinderEntry>& binders() {
  static std::vector<BinderEntry> registry;
  return registry;
}

struct RegisterBinder {
  RegisterBinder(int order, const char* name, Binder fn) { binders().push_back({order, name, fn}); }
};

}  // namespace mechbal::pyb

#define MECHBAL_REGISTER_BINDINGS(order, name, fn) \
  static const ::mechbal::pyb::RegisterBinder mechbal_binder_##name(order, #name, fn)
