#pragma once
// One Python tick of a joint controller (ComputedTorque, DecoupledJointController): (tau, status).
// Wrong sizes are a ValueError at the boundary; non-finite input returns the held command and its
// status, as the C++ step does.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>

#include "mechbal/status.hpp"

namespace mechbal::pyb {

template <typename Controller>
pybind11::tuple controller_step(Controller& c, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                const Eigen::VectorXd& q_des, const Eigen::VectorXd& qd_des,
                                const Eigen::VectorXd& qdd_des) {
  Eigen::VectorXd tau = c.last_command();
  const Status s = c.step(q, qd, q_des, qd_des, qdd_des, tau);
  if (s == Status::bad_size)
    throw pybind11::value_error("q, qd, q_des, qd_des, qdd_des must each have dof values");
  return pybind11::make_tuple(tau, s);
}

}  // namespace mechbal::pyb
