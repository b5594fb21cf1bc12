#include "mechbal/control/passive.hpp"

#include <stdexcept>
#include <string>

#include "mechbal/control/trajectory.hpp"

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

ClosedLoopLog simulate_passive(ForwardDynamics& plant, const Eigen::VectorXd& q0,
                               const Eigen::VectorXd& qd0, const ClosedLoopOptions& options) {
  const int n = plant.dof();
  if (q0.size() != n || !q0.allFinite())
    throw std::invalid_argument("simulate_passive.q0 must be " + std::to_string(n) + " finite values");
  PassiveController controller(n);
  const RestToRestTrajectory held(q0, q0, 1.0, TimeLaw::quintic);  // ignored by the controller
  return simulate_closed_loop(plant, controller, held, q0, qd0, options);
}

}  // namespace mechbal
