#include "mechbal/control/factory.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/decoupled_control.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/control/reactionless.hpp"
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

/// The torque limit in force per actuated coordinate: the smaller of `[control] torque_limit`
/// (when given) and the model's declared effort limit; +infinity where neither is declared.
/// Empty when the table's vector has the wrong size (check_size reports it).
Eigen::VectorXd torque_limit_in_force(const MechanismModel& model, const ControlConfig& c) {
  const int n = model.num_actuated();
  if (!c.torque_limit.empty() && static_cast<int>(c.torque_limit.size()) != n) return vec(c.torque_limit);
  Eigen::VectorXd limit(n);
  for (int i = 0; i < n; ++i) {
    const double declared = model.effort_limits()(model.actuated_coordinates()[static_cast<std::size_t>(i)]);
    limit(i) = c.torque_limit.empty() ? declared : std::min(c.torque_limit[static_cast<std::size_t>(i)], declared);
  }
  return limit;
}

/// The joint controllers' input range of a `[control]` table: its max_speed (no other bound).
JointInputRange input_range(const ControlConfig& c) {
  JointInputRange r;
  r.max_speed = c.max_speed;
  return r;
}

/// ComputedTorque over its own MechanismDynamics (the controller holds a reference to it).
class OwnedComputedTorque : public JointController {
 public:
  OwnedComputedTorque(const MechanismModel& model, const ControlConfig& c, const Eigen::VectorXd& q_guess)
      : dynamics_(model, q_guess),
        controller_(dynamics_, vec(c.kp), vec(c.kd), torque_limit_in_force(model, c), input_range(c)) {}
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

[[noreturn]] void fail(const std::string& field, const std::string& message) {
  throw std::invalid_argument("control." + field + ": " + message);
}

void require_kind(const ControlConfig& c, ControlKind kind, const char* what) {
  if (c.kind != kind) {
    fail("kind", std::string(what) + " needs kind = '" + control_kind_name(kind) + "' (got '" +
                     control_kind_name(c.kind) + "')");
  }
}

/// The reactionless controllers' own construction errors name "reactionless.<field>": say
/// "control." where the field is the table's.
template <typename T, typename Fn>
T rename_errors(Fn fn) {
  try {
    return fn();
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    if (what.rfind("reactionless.", 0) == 0) what = "control." + what.substr(13);
    throw std::invalid_argument(what);
  }
}

ReactionlessIntegrator integrator_of(const std::string& name) {
  if (name == "euler") return ReactionlessIntegrator::euler;
  if (name == "rk4") return ReactionlessIntegrator::rk4;
  fail("integrator", "must be one of euler, rk4 (got '" + name + "')");
}

}  // namespace

std::uint32_t cancel_mask(const std::vector<std::string>& cancel, const std::string& field) {
  if (cancel.empty()) throw std::invalid_argument(field + ": must name at least one momentum component");
  std::uint32_t mask = 0;
  for (std::size_t i = 0; i < cancel.size(); ++i) {
    const std::uint32_t m = momentum_component(cancel[i]);
    if (m == 0) {
      throw std::invalid_argument(field + "[" + std::to_string(i) + "]: '" + cancel[i] +
                                  "' is not a momentum component (moment, force, both, moment_x, "
                                  "moment_y, moment_z, force_x, force_y, force_z)");
    }
    mask |= m;
  }
  return mask;
}

std::uint32_t task_rows_mask(const std::vector<std::string>& rows, const std::string& field) {
  static const std::pair<const char*, std::uint32_t> names[] = {
      {"linear", cancel_force}, {"angular", cancel_moment}, {"all", cancel_both}, {"v_x", force_x},
      {"v_y", force_y},         {"v_z", force_z},          {"w_x", moment_x},  {"w_y", moment_y},
      {"w_z", moment_z}};
  if (rows.empty()) throw std::invalid_argument(field + ": must name at least one twist component");
  std::uint32_t mask = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::uint32_t bit = 0;
    for (const auto& n : names)
      if (rows[i] == n.first) bit = n.second;
    if (bit == 0) {
      throw std::invalid_argument(field + "[" + std::to_string(i) + "]: '" + rows[i] +
                                  "' is not a twist component (all, linear, angular, v_x, v_y, v_z, w_x, w_y, "
                                  "w_z)");
    }
    mask |= bit;
  }
  return mask;
}

ReactionlessConfig reactionless_config(const ControlConfig& control) {
  require_kind(control, ControlKind::reactionless, "a reactionless controller");
  ReactionlessConfig c;
  c.balancing_joints = control.balancing_joints;
  c.cancel = cancel_mask(control.cancel);
  c.integrator = integrator_of(control.integrator);
  c.rate_hz = control.rate_hz;
  c.damping = control.damping;
  c.max_rate = control.max_rate;
  c.task_range.max_speed = control.max_speed;
  c.home_gain = control.home_gain;
  c.limit_gain = control.limit_gain;
  rename_errors<int>([&] {
    validate_reactionless_config(c);
    return 0;
  });
  return c;
}

TaskSpaceConfig task_space_config(const ControlConfig& control) {
  require_kind(control, ControlKind::reactionless, "the operational-space mode");
  if (control.task_frame.empty()) fail("task_frame", "is required for the operational-space mode");
  TaskSpaceConfig c;
  c.frame = control.task_frame;
  c.task_rows = task_rows_mask(control.task_rows);
  c.cancel = cancel_mask(control.cancel);
  c.integrator = integrator_of(control.integrator);
  c.rate_hz = control.rate_hz;
  c.damping = control.damping;
  c.max_rate = control.max_rate;
  return c;
}

std::unique_ptr<ReactionlessController> make_reactionless_controller(const MechanismModel& model,
                                                                     const ControlConfig& control,
                                                                     const Eigen::VectorXd& q0,
                                                                     const Eigen::VectorXd& v0,
                                                                     const Eigen::VectorXd& q_guess) {
  const ReactionlessConfig config = reactionless_config(control);
  if (!control.task_frame.empty()) {
    fail("task_frame", "the operational-space mode follows the frame's path: make_task_controller builds it");
  }
  const Eigen::VectorXd start = q0.size() ? q0 : Eigen::VectorXd(Eigen::VectorXd::Zero(model.num_actuated()));
  return rename_errors<std::unique_ptr<ReactionlessController>>([&] {
    return std::make_unique<ReactionlessController>(std::make_shared<const MechanismModel>(model), config, start, v0,
                                                    q_guess);
  });
}

std::unique_ptr<ReactionlessTaskController> make_task_controller(const MechanismModel& model,
                                                                 const ControlConfig& control,
                                                                 const Eigen::VectorXd& q0,
                                                                 const Eigen::VectorXd& v0) {
  const TaskSpaceConfig config = task_space_config(control);
  const Eigen::VectorXd start = q0.size() ? q0 : Eigen::VectorXd(Eigen::VectorXd::Zero(model.dof()));
  return rename_errors<std::unique_ptr<ReactionlessTaskController>>([&] {
    return std::make_unique<ReactionlessTaskController>(std::make_shared<const MechanismModel>(model), config, start,
                                                        v0);
  });
}

std::unique_ptr<JointController> make_controller(const MechanismModel& model, const ControlConfig& control,
                                                 const Eigen::VectorXd& q_guess, const Eigen::VectorXd& q0) {
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
                                                        torque_limit_in_force(model, control),
                                                        input_range(control));
    }
    case ControlKind::reactionless: {
      const ReactionlessConfig config = reactionless_config(control);
      if (!control.task_frame.empty()) {
        fail("task_frame", "the operational-space mode follows a frame's path, not joint targets: "
                           "make_task_controller builds it");
      }
      if (control.kp.empty() || control.kd.empty()) {
        fail(control.kp.empty() ? "kp" : "kd",
             "is required to build a joint controller (the reactionless controller's computed-torque stage); "
             "make_reactionless_controller builds the motion command alone");
      }
      check_size(control.kp, n, "kp", false);
      check_size(control.kd, n, "kd", false);
      check_size(control.torque_limit, n, "torque_limit", true);
      const Eigen::VectorXd start = q0.size() ? q0 : Eigen::VectorXd(Eigen::VectorXd::Zero(n));
      return rename_errors<std::unique_ptr<JointController>>([&]() -> std::unique_ptr<JointController> {
        return std::make_unique<ReactionlessJointController>(std::make_shared<const MechanismModel>(model), config,
                                                             start, vec(control.kp), vec(control.kd),
                                                             torque_limit_in_force(model, control),
                                                             input_range(control), q_guess);
      });
    }
    case ControlKind::passive:
      return std::make_unique<PassiveController>(n);
    case ControlKind::none: break;
  }
  throw std::invalid_argument("control: the case has no [control] table (kind none): nothing to build");
}

}  // namespace mechbal
