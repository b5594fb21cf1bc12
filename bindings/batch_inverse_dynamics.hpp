#pragma once
// Batch inverse dynamics with the base support wrench, shared by every chain back end that offers
// inverse_dynamics(q, qd, qdd, tau, &support_force, &support_moment) (KDL, mechbal's RNE).
// Instants with bad input or an overflowing result give zeros and their flags in
// status_per_instant (N,); status is the OR.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>

#include "array_checks.hpp"
#include "mechbal/status.hpp"

namespace mechbal::pyb {

template <typename Dynamics>
pybind11::dict batch_inverse_dynamics(Dynamics& d, const Array& q, const Array& qd,
                                      const Array& qdd) {
  const auto n = static_cast<pybind11::ssize_t>(d.dof());
  const auto N = batch_rows(n, {{q, "q"}, {qd, "v"}, {qdd, "a"}});
  OutArray tau = make_array({N, n}), F = make_array({N, 3}), M = make_array({N, 3});
  auto per_instant = make_status_array(N);
  using CVec = Eigen::Map<const Eigen::VectorXd>;
  Status status = Status::ok;
  for (pybind11::ssize_t k = 0; k < N; ++k) {
    Eigen::Map<Eigen::VectorXd> t(tau.mutable_data(k, 0), n);
    Eigen::Vector3d f, mo;
    const Status s = d.inverse_dynamics(CVec(q.data(k, 0), n), CVec(qd.data(k, 0), n),
                                        CVec(qdd.data(k, 0), n), t, &f, &mo);
    if (s != Status::ok) {  // bad instants give zeros and set their flag
      t.setZero();
      f.setZero();
      mo.setZero();
    }
    status |= s;
    per_instant.mutable_at(k) = static_cast<std::uint32_t>(s);
    Eigen::Map<Eigen::Vector3d>(F.mutable_data(k, 0)) = f;
    Eigen::Map<Eigen::Vector3d>(M.mutable_data(k, 0)) = mo;
  }
  pybind11::dict out;
  out["tau"] = tau;
  out["support_force"] = F;
  out["support_moment"] = M;
  out["status"] = status;
  out["status_per_instant"] = per_instant;
  return out;
}

}  // namespace mechbal::pyb
