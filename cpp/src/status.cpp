#include "mechbal/status.hpp"

namespace mechbal {

const char* status_name(Status s) noexcept {
  // Single flags get their own name; combinations are reported generically (no allocation).
  switch (s) {
    case Status::ok: return "ok";
    case Status::non_finite_input: return "non_finite_input";
    case Status::singular: return "singular";
    case Status::saturated: return "saturated";
    case Status::bad_size: return "bad_size";
    case Status::solver_error: return "solver_error";
    case Status::out_of_range: return "out_of_range";
  }
  return "multiple";
}

}  // namespace mechbal
