// The key functions of the control layer's interfaces. A polymorphic class whose virtual functions
// are all inline has its vtable and typeinfo emitted in every translation unit that constructs or
// destroys one; a unit compiled without RTTI (the real-time test) then emits a vtable with no
// typeinfo, and when the linker keeps that copy UBSan's vptr check fails. An out-of-line
// destructor gives each vtable one home: this file, in the library, compiled with RTTI.
#include "mechbal/control/dynamics.hpp"
#include "mechbal/control/joint_controller.hpp"

namespace mechbal {

InverseDynamics::~InverseDynamics() = default;
ForwardDynamics::~ForwardDynamics() = default;
JointController::~JointController() = default;

}  // namespace mechbal
