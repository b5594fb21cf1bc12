#pragma once
/// \file mechanism_dynamics.hpp
/// MechanismDynamics: the InverseDynamics and ForwardDynamics back end of the general model, so the
/// controllers (ComputedTorque, DecoupledJointController) and the closed-loop simulator
/// (closed_loop.hpp) drive any MechanismModel, closed loops included.
///
/// Coordinates are the actuated ones (model.actuated_coordinates(); every coordinate of an open
/// mechanism). For a closed mechanism each call solves the loops (algorithm/loops.hpp), warm-started
/// from the previous call's passive coordinates, and works with the projected dynamics:
/// tau# = C^T tau(q, v, a), M# = C^T M C. An open mechanism takes the tree algorithms directly.
///
/// It owns an immutable copy of the model (shared, never a reference to something that can change
/// underneath, unlike KDL's solvers) and its MechanismData; every call is noexcept and
/// allocation-free.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <memory>

#include "mechbal/algorithm/loops.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/control/dynamics.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/model/rigid_body.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

class MechanismDynamics;
/// Instantiated in mechanism_dynamics.cpp only (its vtable and typeinfo: see SupportWrenchDynamics).
extern template class SupportWrenchDynamics<MechanismDynamics>;

class MechanismDynamics : public SupportWrenchDynamics<MechanismDynamics>, public ForwardDynamics {
 public:
  /// `q_guess` (model.dof() values, default zeros): the full coordinates near the assembly the
  /// loops start from (the assembly mode). Throws std::invalid_argument when an open mechanism has
  /// passive (unactuated) coordinates, which this back end cannot drive, or q_guess has the wrong
  /// size.
  explicit MechanismDynamics(MechanismModel model, const Eigen::VectorXd& q_guess = Eigen::VectorXd());
  explicit MechanismDynamics(std::shared_ptr<const MechanismModel> model,
                             const Eigen::VectorXd& q_guess = Eigen::VectorXd());

  /// Number of actuated coordinates.
  int dof() const noexcept override { return model_->num_actuated(); }
  const MechanismModel& model() const noexcept { return *model_; }
  MechanismData& data() noexcept { return data_; }
  /// Full coordinates of the last solved pose (the warm start of the next call).
  const Eigen::VectorXd& solved_position() const noexcept { return q_; }
  LoopSolveOptions& loop_options() noexcept { return options_; }

  /// tau# = M#(q#) a# + b#(q#, v#) (gravity and springs included). Sizes must equal dof() (Status::bad_size),
  /// input finite (Status::non_finite_input), tau untouched otherwise; a closed mechanism that
  /// cannot be assembled gives Status::solver_error (tau untouched); near a parallel singularity
  /// Status::singular with the computed tau. The InverseDynamics call (SupportWrenchDynamics) is
  /// this one without the wrench.
  using SupportWrenchDynamics<MechanismDynamics>::inverse_dynamics;
  /// As above; `support_force`/`support_moment` (when non-null) receive the wrench the base exerts
  /// on the moving links (moment about O, gravity included; bodies fixed to the base excluded).
  Status inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& qdd,
                          Eigen::Ref<Eigen::VectorXd> tau, Vec3* support_force,
                          Vec3* support_moment) noexcept;
  /// a# = M#^-1 (tau# - b#). Status::singular when M# is not positive definite (qdd untouched).
  Status forward_dynamics(const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd,
                          const Eigen::Ref<const Eigen::VectorXd>& tau,
                          Eigen::Ref<Eigen::VectorXd> qdd) noexcept override;
  /// M#(q#) (dof x dof).
  Status mass_matrix(const Eigen::Ref<const Eigen::VectorXd>& q, Eigen::Ref<Eigen::MatrixXd> M) noexcept;
  /// G#(q#): gravity alone (springs: static_torque).
  Status gravity(const Eigen::Ref<const Eigen::VectorXd>& q, Eigen::Ref<Eigen::VectorXd> g) noexcept;
  /// G#(q#) + K#(q#): gravity and springs, the actuated forces that hold the mechanism still.
  Status static_torque(const Eigen::Ref<const Eigen::VectorXd>& q, Eigen::Ref<Eigen::VectorXd> s) noexcept;
  /// b#(q#, v#) = C#(q#, v#) v# + G#(q#) + K#(q#) (springs included).
  Status bias(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
              Eigen::Ref<Eigen::VectorXd> b) noexcept;
  /// C#(q#, v#) v# alone (no gravity, no springs).
  Status coriolis(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
                  Eigen::Ref<Eigen::VectorXd> c) noexcept;

 private:
  static bool failed(Status s) noexcept {
    return has(s, Status::solver_error) || has(s, Status::bad_size) || has(s, Status::non_finite_input);
  }

  std::shared_ptr<const MechanismModel> model_;
  MechanismData data_;
  Eigen::VectorXd q_;       ///< full coordinates: warm start and last solved pose
  Eigen::VectorXd zero_;    ///< dof() zeros
  Eigen::VectorXd work_;    ///< dof()
  Eigen::LDLT<Eigen::MatrixXd> ldlt_;
  LoopSolveOptions options_;
};

}  // namespace mechbal
