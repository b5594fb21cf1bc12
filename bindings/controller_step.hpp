#pragma once
// One Python tick of a joint controller (ComputedTorque, DecoupledJointController): (tau, status).
// Arguments go through the checked conversion (array_checks.hpp); a wrong size is a ValueError
// naming the argument, the expected and the received shape. Non-finite or out-of-range input
// returns the held command and its status, as the C++ step does.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <string>

#include "array_checks.hpp"
#include "mechbal/status.hpp"
#include "mechbal/computed_torque.hpp"
#include "mechbal/joint_limits.hpp"

namespace mechbal::pyb {

template <typename Controller>
pybind11::tuple controller_step(Controller& c, const Array& q, const Array& qd, const Array& q_des,
                                const Array& qd_des, const Array& qdd_des) {
  const auto n = static_cast<pybind11::ssize_t>(c.dof());
  const std::string context = "the controller has " + std::to_string(n) + " joints";
  const Eigen::VectorXd q_ = vector_arg(q, "q", n, false, context.c_str());
  const Eigen::VectorXd qd_ = vector_arg(qd, "qd", n, false, context.c_str());
  const Eigen::VectorXd q_des_ = vector_arg(q_des, "q_des", n, false, context.c_str());
  const Eigen::VectorXd qd_des_ = vector_arg(qd_des, "qd_des", n, false, context.c_str());
  const Eigen::VectorXd qdd_des_ = vector_arg(qdd_des, "qdd_des", n, false, context.c_str());
  Eigen::VectorXd tau = c.last_command();
  const Status s = c.step(q_, qd_, q_des_, qd_des_, qdd_des_, tau);
  return pybind11::make_tuple(tau, s);
}

/// The input range of a joint controller from the Python keyword arguments.
inline JointInputRange joint_input_range(double max_position, double max_speed,
                                         double max_acceleration) {
  JointInputRange r;
  r.max_position = max_position;
  r.max_speed = max_speed;
  r.max_acceleration = max_acceleration;
  return r;
}

/// new Controller over any dynamics back end, from Python arguments (the Python model object is
/// kept alive by py::keep_alive in the binding).
template <typename Model>
ComputedTorque* make_computed_torque(Model& model, const Array& kp, const Array& kd,
                                     const pybind11::object& torque_limit, double max_position,
                                     double max_speed, double max_acceleration) {
  // sizes are checked by the constructor (std::invalid_argument naming computed_torque.kp, ...)
  const Eigen::VectorXd limit =
      torque_limit.is_none() ? Eigen::VectorXd()
                             : vector_arg(to_real_array(torque_limit), "torque_limit", -1);
  return new ComputedTorque(model, vector_arg(kp, "kp", -1), vector_arg(kd, "kd", -1), limit,
                            joint_input_range(max_position, max_speed, max_acceleration));
}

}  // namespace mechbal::pyb

#define MECHBAL_JOINT_RANGE_ARGS                                                          \
  pybind11::arg("max_position") = ::mechbal::JointInputRange{}.max_position,               \
  pybind11::arg("max_speed") = ::mechbal::JointInputRange{}.max_speed,                     \
  pybind11::arg("max_acceleration") = ::mechbal::JointInputRange{}.max_acceleration
