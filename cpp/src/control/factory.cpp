#include "mechbal/control/factory.hpp"

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/decoupled_control.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/control/passive.hpp"

namespace mechbal {

const char* control_kind_name(ControlKind kind) noexcept {
  switch (kind) {
    case ControlKind::computed_torque: return "computed_torque";
    case ControlKind::decoupled: return "decoupled";
    case ControlKind::reactionless: return "reactionless";
    case ControlKind::passive: return "passive";
    case ControlKind::none: break;
  }
  return "none";
}

namespace {

Eigen::VectorXd vec(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

/// ComputedTorque over its own MechanismDynamics (the controller holds a reference to it).
class OwnedComputedTorque : public JointController {
 public:
  OwnedComputedTorque(const MechanismModel& model, const ControlConfig& c, const Eigen::VectorXd& q_guess)
      : dynamics_(model, q_guess), controller_(dynamics_, vec(c.kp), vec(c.kd), vec(c.torque_limit)) {}
  int dof() const noexcept override { return controller_.dof(); }
  Status step(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
              const Eigen::Ref<const Eigen::VectorXd>& q_des, const Eigen::Ref<const Eigen::VectorXd>& qd_des,
              const Eigen::Ref<const Eigen::VectorXd>& qdd_des, Eigen::Ref<Eigen::VectorXd> tau) noexcept override {
    return controller_.step(q, qd, q_des, qd_des, qdd_des, tau);
  }

 private:
  MechanismDynamics dynamics_;
  ComputedTorque controller_;
};

void check_size(const std::vector<double>& v, int n, const char* field, bool may_be_empty) {
  if ((may_be_empty && v.empty()) || static_cast<int>(v.size()) == n) return;
  throw std::invalid_argument(std::string("control.") + field + ": must have " + std::to_string(n) +
                              " values (one per actuated joint), got " + std::to_string(v.size()));
}

/// decoupled without k: the diagonal of M#(0), which must be diagonal (a dynamically balanced design).
std::vector<double> balanced_diagonal(const MechanismModel& model, const Eigen::VectorXd& q_guess) {
  MechanismDynamics dyn(model, q_guess);
  const int n = dyn.dof();
  Eigen::MatrixXd M(n, n);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  const Status s = dyn.mass_matrix(q, M);
  if (s != Status::ok || !M.allFinite()) {
    throw std::invalid_argument("control.k: the mass matrix at q = 0 could not be evaluated; give k");
  }
  const double scale = M.diagonal().cwiseAbs().maxCoeff();
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (i != j && std::abs(M(i, j)) > 1e-9 * scale) {
        throw std::invalid_argument("control.k: the mass matrix at q = 0 is not diagonal (M[" + std::to_string(i) +
                                    "][" + std::to_string(j) + "] = " + std::to_string(M(i, j)) +
                                    "): the decoupled controller needs a dynamically balanced design, or give k");
      }
    }
  }
  return std::vector<double>(M.diagonal().data(), M.diagonal().data() + n);
}

}  // namespace

std::unique_ptr<JointController> make_controller(const MechanismModel& model, const ControlConfig& control,
                                                 const Eigen::VectorXd& q_guess) {
  const int n = model.num_actuated();
  switch (control.kind) {
    case ControlKind::computed_torque: {
      check_size(control.kp, n, "kp", false);
      check_size(control.kd, n, "kd", false);
      check_size(control.torque_limit, n, "torque_limit", true);
      return std::make_unique<OwnedComputedTorque>(model, control, q_guess);
    }
    case ControlKind::decoupled: {
      check_size(control.kp, n, "kp", false);
      check_size(control.kd, n, "kd", false);
      check_size(control.torque_limit, n, "torque_limit", true);
      check_size(control.k, n, "k", true);
      const std::vector<double> k = control.k.empty() ? balanced_diagonal(model, q_guess) : control.k;
      return std::make_unique<DecoupledJointController>(vec(k), vec(control.kp), vec(control.kd),
                                                        vec(control.torque_limit));
    }
    case ControlKind::reactionless:
      throw std::invalid_argument(
          "control.kind: 'reactionless' is read and checked, but this build has no reactionless controller "
          "yet (use computed_torque or decoupled)");
    case ControlKind::passive:
      return std::make_unique<PassiveController>(n);
    case ControlKind::none: break;
  }
  throw std::invalid_argument("control: the case has no [control] table (kind none): nothing to build");
}

}  // namespace mechbal
