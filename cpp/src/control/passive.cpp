#include "mechbal/control/passive.hpp"

#include <stdexcept>
#include <string>

namespace mechbal {

PassiveController::PassiveController(int dof) : dof_(dof) {
  if (dof < 1) throw std::invalid_argument("dof: must be >= 1 (got " + std::to_string(dof) + ")");
  zero_ = Eigen::VectorXd::Zero(dof);
}

Status PassiveController::step(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
                               const Eigen::Ref<const Eigen::VectorXd>&, const Eigen::Ref<const Eigen::VectorXd>&,
                               const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd> tau) noexcept {
  if (q.size() != dof_ || qd.size() != dof_ || tau.size() != dof_) return Status::bad_size;
  tau.setZero();
  if (!q.allFinite() || !qd.allFinite()) return Status::non_finite_input;
  return Status::ok;
}

}  // namespace mechbal
