#pragma once
/// \file control/reactionless.hpp
/// Reactionless control of any mechanism (docs/architecture.md, "The model": control is organised
/// by controller over the model): the actuated joints are split into task joints, whose motion is given, and balancing
/// joints, whose motion the controller computes every tick so that the selected components of the
/// momentum about O, h = [P; H_O], stay at their target h*. The shaking wrench is dh/dt
/// (algorithm/shaking_wrench.hpp), so a constant target cancels the selected components of it.
///
/// Derivation (any tree, gear couplings, closed loops). The momentum is linear in the joint
/// velocities, h = A(q) v (algorithm/momentum.hpp). With loops v = C(q) v# over the actuated
/// coordinates v# (algorithm/loops.hpp; C = I for an open mechanism), so h = K v# with K = A C.
/// S selects the cancelled rows; K's columns split into the task block K_t and the balancing
/// block K_b:
///
///     S K_b v_b = S h* - S K_t v_t                                     (rates)
///
/// Differentiating h = A v along the motion, with a = C a# + c (c the loops' acceleration bias):
/// dh/dt = A C a# + A c + (dA/dt) v = K a# + W(q, v, c), where W(q, v, a) is the shaking wrench of
/// the motion (q, v, a) (so W(q, v, c) = A c + (dA/dt) v). Hence
///
///     S K_b a_b = S dh*/dt - S K_t a_t - S W(q, v, c)                 (feed-forward)
///
/// and the predicted shaking wrench of the commanded motion is W(q, v, c) + K a#.
///
/// Computation: K is never formed. When no balancing joint moves a loop's frame (or the mechanism
/// is open), C's balancing columns are unit vectors: K_b = A_b, the momentum-matrix columns of the
/// balancing joints, which need only the composite inertias of the subtrees those joints move, and
/// K_t v_t = A C [v_t; 0] is the momentum of the task's motion with the balancing joints still (a
/// velocity pass and the links' momenta). An RK4 stage that only turns the balancing joints (the
/// third, and the next tick's first) places, moves and sums those subtrees again, nothing else.
/// The feed-forward folds K_t a_t into one shaking-wrench pass, W(q, v, c + C [a_t; 0]) =
/// W(q, v, c) + K_t a_t, which also gives h. With a balancing joint inside a loop, K_b = A C_b
/// from the whole momentum matrix. On a closed mechanism, RK4's loop solves at t + dt/2 and
/// t + dt start from the last solution followed along the closure to second order (algorithm/
/// loops.hpp), which needs the loops' acceleration bias c where the step starts: the t + dt solve
/// gets c at t + dt/2 extrapolated from c at the last three ticks' starts (consecutive ticks of
/// a sampled trajectory), and the solves then close the loops at their predictions, with no
/// Newton step.
///
/// The balancing rates are integrated at the controller's rate (explicit Euler, or classical RK4
/// with the task motion at t + dt/2 and t + dt). Each solve is a least-squares / minimum-norm
/// solution of S K_b x = r: with n_b balancing joints and k cancelled components it is exact for
/// n_b = k, least squares for n_b < k and minimum norm for n_b > k, where the remaining freedom
/// (the null space of S K_b) follows a secondary objective z: return to a home pose and keep off
/// the joint limits, v_b = x + (I - (S K_b)^+ S K_b) z. When cond(S K_b) exceeds max_condition the
/// solve is damped least squares with lambda = damping * sigma_max(S K_b) and the tick reports
/// Status::singular; nothing divides by a vanishing determinant.
///
/// PAMINSA's reactionless wrist (papers/paminsa/reactionless_wrist.hpp) is the special case with
/// the three wrist joints balancing and cancel = moment: S K_b = N(q_w) (eq 23, corrected) and
/// S K_t v_t = D (eq 19); tests/cpp/test_reactionless.cpp checks that the two agree.
///
/// Real time: every tick is noexcept, allocation-free (all buffers are sized at construction) and
/// bounded (the loop solve has its iteration bound). Bad input never propagates: non-finite input
/// gives Status::non_finite_input, input beyond the configured ranges Status::out_of_range, a loop
/// solve failure Status::solver_error; each holds the last safe command (balancing joints at their
/// current positions, every velocity and acceleration zero) and the state does not advance.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mechbal/algorithm/loops.hpp"
#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/joint_controller.hpp"
#include "mechbal/control/joint_limits.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/detail/link_subset.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/model/rigid_body.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

/// Rows of h = [P; H_O] as bit flags (a set of them is a `cancel` mask).
enum MomentumComponent : std::uint32_t {
  force_x = 1u << 0,
  force_y = 1u << 1,
  force_z = 1u << 2,
  moment_x = 1u << 3,
  moment_y = 1u << 4,
  moment_z = 1u << 5,
};
constexpr std::uint32_t cancel_force = force_x | force_y | force_z;
constexpr std::uint32_t cancel_moment = moment_x | moment_y | moment_z;
constexpr std::uint32_t cancel_both = cancel_force | cancel_moment;

/// The cancel mask of a name: "moment", "force", "both", "moment_x|y|z", "force_x|y|z"; 0 when
/// unknown.
std::uint32_t momentum_component(const std::string& name) noexcept;

enum class ReactionlessIntegrator { euler, rk4 };

using Vec6 = Eigen::Matrix<double, 6, 1>;

struct ReactionlessConfig {
  /// Names of the balancing joints: actuated coordinates of the model (every coordinate of an
  /// open mechanism is actuated). The other actuated coordinates are the task joints.
  std::vector<std::string> balancing_joints;
  std::uint32_t cancel = cancel_moment;  ///< MomentumComponent flags, at least one
  ReactionlessIntegrator integrator = ReactionlessIntegrator::euler;
  double rate_hz = 1000.0;      ///< tick rate [Hz], in [1, 1e6]
  double damping = 1e-2;        ///< DLS damping relative to sigma_max(S K_b), in (0, 1)
  double max_condition = 1e4;   ///< cond(S K_b) above which the solve is damped (Status::singular)
  /// |v_b| limit per balancing joint [rad/s or m/s] (> 0; the model's velocity limit when
  /// smaller; +infinity, the default: only the model's): the rate vector is scaled down,
  /// direction kept, Status::saturated
  double max_rate = no_limit;
  /// |a_b| limit of the feed-forward per balancing joint [rad/s^2 or m/s^2] (> 0, default
  /// +infinity: no limit): scaled down, Status::saturated; zero when the rates saturated
  double max_acceleration = no_limit;
  /// hold the balancing joints (zero rates, Status::saturated) when a tick would take one beyond
  /// the model's position limits
  bool position_limits = true;
  /// false: the model's declared velocity limits are not applied (only max_rate): the demand
  /// study of a motion (the rates it needs, mechbal.control.feasibility), not a controller
  bool velocity_limits = true;
  /// null-space objective (n_b > k): z = -home_gain (q_b - home) - limit_gain * (q_b - mid) / half_range^2
  /// (the second term for joints with finite limits) [1/s]
  double home_gain = 0.0;
  double limit_gain = 0.0;
  Eigen::VectorXd home;  ///< balancing joints' home [rad or m]; empty: their initial positions
  /// input range of the task joints' q, v, a (every component; default no limit)
  JointInputRange task_range;
  /// |h*| and |h| input range per component [kg m/s, kg m^2/s] (default +infinity: no limit)
  double max_momentum = no_limit;
  double max_moment = no_limit;  ///< |dh*/dt| per component [N, N m] (default no limit)
  LoopSolveOptions loop_options;
};

/// Throws std::invalid_argument naming the field and the value.
void validate_reactionless_config(const ReactionlessConfig& config);

/// One tick's command. Actuated vectors follow model.actuated_coordinates(); the full ones every
/// coordinate of the model (passive joints of the loops and gear couplings included).
struct ReactionlessCommand {
  Eigen::VectorXd q, v, a;             ///< actuated coordinates at t_n (task as given, balancing computed)
  Eigen::VectorXd q_full, v_full, a_full;  ///< every coordinate at t_n
  Eigen::VectorXd next_balancing;      ///< balancing joints' positions at t_n + dt
  Vec6 momentum = Vec6::Zero();        ///< h = [P; H_O] of the command at t_n
  Vec3 shaking_force = Vec3::Zero();   ///< predicted dP/dt of the command [N]
  Vec3 shaking_moment = Vec3::Zero();  ///< predicted dH_O/dt [N m]
  double condition = 1.0;              ///< cond(S K_b) at t_n
  Status status = Status::ok;
};

class ReactionlessController {
 public:
  /// `q0`, `v0`: the actuated coordinates at the start (v0 empty: at rest); the target is the
  /// momentum there (reactionless). `q_guess`: every coordinate near the assembly (closed loops;
  /// default zeros). Throws std::invalid_argument naming the field on a bad configuration, a
  /// balancing joint that is not an actuated coordinate, sizes, or a start that cannot be
  /// assembled. Not real time.
  ReactionlessController(std::shared_ptr<const MechanismModel> model, const ReactionlessConfig& config,
                         const Eigen::VectorXd& q0, const Eigen::VectorXd& v0 = Eigen::VectorXd(),
                         const Eigen::VectorXd& q_guess = Eigen::VectorXd());
  ReactionlessController(MechanismModel model, const ReactionlessConfig& config, const Eigen::VectorXd& q0,
                         const Eigen::VectorXd& v0 = Eigen::VectorXd(), const Eigen::VectorXd& q_guess = Eigen::VectorXd());

  const MechanismModel& model() const noexcept { return *model_; }
  std::shared_ptr<const MechanismModel> shared_model() const noexcept { return model_; }
  const ReactionlessConfig& config() const noexcept { return config_; }
  int num_actuated() const noexcept { return na_; }
  int num_task() const noexcept { return nt_; }
  int num_balancing() const noexcept { return nb_; }
  int num_cancelled() const noexcept { return k_; }
  /// Indices into the actuated coordinates of the task and balancing joints.
  const std::vector<int>& task_joints() const noexcept { return task_; }
  const std::vector<int>& balancing_joints() const noexcept { return balancing_; }
  /// Rows of h cancelled (0..5, linear first).
  const std::vector<int>& cancelled_rows() const noexcept { return rows_; }
  double dt() const noexcept { return dt_; }

  /// Restart from the actuated state (q0, v0) with the target h* = its momentum (constant).
  /// Real time. Bad input (sizes, non-finite, out of range, loops that cannot be assembled):
  /// nothing changes, the status says why.
  Status reset(const Eigen::Ref<const Eigen::VectorXd>& q0, const Eigen::Ref<const Eigen::VectorXd>& v0) noexcept;
  /// Set a given target h* (6, all rows; the uncancelled ones are ignored) and its rate dh*/dt for
  /// the next ticks (a target trajectory: call before each tick). Out of range or non-finite:
  /// nothing changes.
  Status set_target(const Vec6& momentum, const Vec6& momentum_rate) noexcept;
  const Vec6& target() const noexcept { return target_; }
  const Vec6& target_rate() const noexcept { return target_rate_; }

  /// One tick with the configured integrator: the task joints' motion at t_n (q_t, v_t, a_t, each
  /// num_task()) and, for RK4, their positions and velocities at t_n + dt/2 and t_n + dt (Euler
  /// ignores them). Sizes wrong: Status::bad_size, nothing written.
  Status step(const Eigen::Ref<const Eigen::VectorXd>& q_t, const Eigen::Ref<const Eigen::VectorXd>& v_t,
              const Eigen::Ref<const Eigen::VectorXd>& a_t, const Eigen::Ref<const Eigen::VectorXd>& q_t_half,
              const Eigen::Ref<const Eigen::VectorXd>& v_t_half, const Eigen::Ref<const Eigen::VectorXd>& q_t_next,
              const Eigen::Ref<const Eigen::VectorXd>& v_t_next) noexcept;
  /// One explicit-Euler tick whatever the configured integrator.
  Status step_euler(const Eigen::Ref<const Eigen::VectorXd>& q_t, const Eigen::Ref<const Eigen::VectorXd>& v_t,
                    const Eigen::Ref<const Eigen::VectorXd>& a_t) noexcept;

  const ReactionlessCommand& command() const noexcept { return command_; }
  /// Balancing joints' positions at the next tick (the state).
  const Eigen::VectorXd& balancing_state() const noexcept { return q_b_; }
  /// The model's data at the last evaluation (kinematics of the last stage; its momentum_matrix
  /// is only filled when a balancing joint moves a loop: see "Computation" above).
  const MechanismData& data() const noexcept { return data_; }

 private:
  void build(const Eigen::VectorXd& q0, const Eigen::VectorXd& v0, const Eigen::VectorXd& q_guess);
  /// The momentum matrix A and the loop projection C at actuated positions (q_t, q_b) (loops
  /// solved into q_full_); v_act_: actuated velocities (its task entries: the task's rates). Fills
  /// Kb_ and ht_ (task_momentum). With `acceleration`, also the loops' acceleration bias c (the
  /// feed-forward at t_n needs it; an RK4 stage that only needs the rates not). When no balancing
  /// joint moves a loop, c comes from the momentum pass (the link accelerations of the velocity
  /// products alone, then the loops' bias and one solve), and without `acceleration` too until
  /// bias_count_ reaches 3: the next loop solve's warm start predicts from it (from t_n + dt/2 to
  /// t_n + dt, a stale c costs a Newton step); from then on tick() extrapolates it instead.
  Status evaluate(const Eigen::Ref<const Eigen::VectorXd>& q_t, const Eigen::VectorXd& q_b,
                  bool acceleration = true) noexcept;
  /// evaluate() at the same task positions with other balancing positions, for a closed
  /// mechanism whose loops the balancing joints do not move (no loop solve).
  Status rebalance(const Eigen::VectorXd& q_b) noexcept;
  /// When no balancing joint moves a loop: Ab_ = A_b (the balancing columns of the momentum
  /// matrix, from the composites of the balancing subtrees alone) and ht_ = A vt_full_, the
  /// momentum of the task's motion with the balancing joints still (vt_full_, set by evaluate),
  /// at q_full_. `whole` false: only the balancing subtrees moved since the last whole one (the
  /// other links' velocities and momentum rest_ are kept). The full A and K = A C are never formed:
  /// K's task columns enter only through K_t v_t, and K_t a_t through the shaking wrench.
  /// `bias` (with `whole`): the same pass also gives the links' accelerations at a = 0, and from
  /// them the loops' acceleration bias c (after a velocity-level loop solve at q_full_).
  Status task_momentum(bool whole, bool bias = false) noexcept;
  /// Factorise S K_b (damping when cond > max_condition); then solve() applies the operator.
  /// `condition`: where the condition number is reported (null: only the decision is needed, and
  /// a cheap bound settles it when it can).
  Status factorise(double* condition) noexcept;
  void solve(const Eigen::Ref<const Eigen::VectorXd>& r, Eigen::VectorXd& x) noexcept;
  void project_null(const Eigen::VectorXd& z, Eigen::VectorXd& out) noexcept;
  /// Balancing rates at the evaluated pose and task rates (ht_) for the target h.
  Status rates(const Vec6& h, const Eigen::VectorXd& q_b, Eigen::VectorXd& v_b, double* condition) noexcept;
  Status limit_rate(Eigen::VectorXd& v_b) const noexcept;
  Status hold(Status why) noexcept;
  Status tick(const Eigen::Ref<const Eigen::VectorXd>& q_t, const Eigen::Ref<const Eigen::VectorXd>& v_t,
              const Eigen::Ref<const Eigen::VectorXd>& a_t, const Eigen::Ref<const Eigen::VectorXd>* q_half,
              const Eigen::Ref<const Eigen::VectorXd>* v_half, const Eigen::Ref<const Eigen::VectorXd>* q_next,
              const Eigen::Ref<const Eigen::VectorXd>* v_next) noexcept;
  bool task_in_range(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& v,
                     const Eigen::Ref<const Eigen::VectorXd>* a) const noexcept;

  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;

  std::shared_ptr<const MechanismModel> model_;
  ReactionlessConfig config_;
  MechanismData data_;
  double dt_ = 1e-3;
  int n_ = 0, na_ = 0, nt_ = 0, nb_ = 0, k_ = 0;
  std::vector<int> task_, balancing_, rows_;
  std::vector<int> task_coord_, balancing_coord_;  ///< coordinate indices (into q_full)
  bool closed_ = false;
  bool balancing_in_loops_ = false;  ///< some balancing coordinate moves a loop's frame
  Eigen::VectorXd rate_limit_, lower_, upper_, home_;
  // state
  Eigen::VectorXd q_b_;
  // RK4's last stage solved the loops at (q_t_next, v_t_next) with the momentum of the same loop
  // solution: when the next tick starts at exactly those task positions and rates (a sampled
  // trajectory), its t_n evaluation reuses them (the loop solve, C and c do not depend on the
  // balancing joints when these move no loop frame): only the balancing subtrees' momentum is
  // recomputed (rebalance). Likewise for an open mechanism (no loops).
  bool stage_cache_ = false;
  Status stage_cache_status_ = Status::ok;
  Eigen::VectorXd stage_q_, stage_v_;
  // The loops' acceleration bias c at the starts of the last three consecutive ticks (t_n,
  // t_n - dt, t_n - 2 dt; how many are known: bias_count_): when all three are, RK4's t_n + dt/2
  // stage does not compute its own c (the velocity products of every link, the loops' bias, a
  // solve: about 0.5 us on PAMINSA) but extrapolates it quadratically, which the t_n + dt loop
  // solve's warm start needs to ~1e-6 relative to close at its prediction (c of t_n alone misses
  // by 1e-4: a Newton step on every tick, linearly extrapolated by 1e-6: on most).
  Eigen::VectorXd bias_now_, bias_before_, bias_earlier_;
  int bias_count_ = 0;
  Vec6 target_ = Vec6::Zero(), target_rate_ = Vec6::Zero();
  ReactionlessCommand command_;
  // scratch (sized at construction)
  Eigen::VectorXd q_full_, q_act_, v_act_, a_act_, v_full_, a_full_;
  detail::LinkSubset subtree_;  ///< the links a balancing joint moves (it or an ancestor)
  Eigen::VectorXd vt_full_;  ///< C [v_t; 0]: every coordinate's rate under the task alone
  Eigen::VectorXd vt_act_;   ///< [v_t; 0] over the actuated coordinates
  Eigen::VectorXd c_full_;   ///< scratch: C x of an actuated vector x
  Vec6 ht_ = Vec6::Zero();   ///< A vt_full_: K_t v_t
  Vec6 rest_ = Vec6::Zero(); ///< the part of ht_ from the links outside subtree_
  Eigen::MatrixXd Ab_;       ///< 6 x nb: K_b = A C_b
  Eigen::MatrixXd Kb_;       ///< k x nb: S K_b
  Eigen::VectorXd kb_work_, x_, z_, v_b_, a_b_, k1_, k2_, k3_, k4_, q_stage_, r_nb_;
  SmallVector r_, y_;
  Small gram_;
  bool wide_ = false, square_ = false, damped_ = false;
  Eigen::SelfAdjointEigenSolver<Small> eig_;
  Eigen::LLT<Small> llt_;
  Eigen::PartialPivLU<Small> lu_;
  Eigen::Matrix3d inv3_ = Eigen::Matrix3d::Identity();  ///< (S K_b)^-1 when it is 3 x 3
};

/// The reactionless controller followed by a computed-torque stage (computed_torque.hpp over the
/// model's MechanismDynamics): a JointController over the actuated coordinates, so the closed-loop
/// simulator (closed_loop.hpp) and any joint-space loop drive it. Each tick takes the task joints'
/// entries of (q_des, qd_des, qdd_des) (the balancing joints' entries are ignored: the reactionless
/// tick computes them), and tracks the full command from the measured (q, qd). With RK4 the task
/// motion at t + dt/2 and t + dt is extrapolated from (q_des, qd_des, qdd_des) to second order
/// (the JointController interface gives one sample); use ReactionlessController::step with the
/// planned samples where they are known.
class ReactionlessJointController : public JointController {
 public:
  /// kp, kd, torque_limit, range: as ComputedTorque. Throws std::invalid_argument naming the field.
  ReactionlessJointController(std::shared_ptr<const MechanismModel> model, const ReactionlessConfig& config,
                              const Eigen::VectorXd& q0, const Eigen::VectorXd& kp, const Eigen::VectorXd& kd,
                              const Eigen::VectorXd& torque_limit = Eigen::VectorXd(),
                              const JointInputRange& range = JointInputRange{},
                              const Eigen::VectorXd& q_guess = Eigen::VectorXd());

  int dof() const noexcept override { return reactionless_.num_actuated(); }
  /// tau = computed torque tracking the reactionless command; the status is the OR of both
  /// stages' (the command is held on bad input, as each stage documents).
  Status step(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
              const Eigen::Ref<const Eigen::VectorXd>& q_des, const Eigen::Ref<const Eigen::VectorXd>& qd_des,
              const Eigen::Ref<const Eigen::VectorXd>& qdd_des, Eigen::Ref<Eigen::VectorXd> tau) noexcept override;
  const Eigen::VectorXd& last_command() const noexcept { return ct_.last_command(); }
  void reset() noexcept { ct_.reset(); }
  ReactionlessController& reactionless() noexcept { return reactionless_; }
  const ReactionlessController& reactionless() const noexcept { return reactionless_; }
  ComputedTorque& computed_torque() noexcept { return ct_; }

 private:
  MechanismDynamics dynamics_;
  ReactionlessController reactionless_;
  ComputedTorque ct_;
  Eigen::VectorXd q_t_, v_t_, a_t_, q_h_, v_h_, q_n_, v_n_;
};

/// Operational-space reactionless control (the reaction null space): a redundant open mechanism
/// follows a desired twist of a named frame while its redundancy minimises the selected momentum
/// components' departure from their target. With J the task rows of the frame Jacobian
/// ([v; w] of the frame's origin, O axes; algorithm/jacobian.hpp), K = A the momentum matrix and
/// S the cancelled rows, each tick:
///
///     v0 = J^+ x'                      (minimum-norm task rates; damped near singularity)
///     N  = I - J^+ J                   (the task's null space)
///     z  = (S K N)^+ (S h* - S K v0)   (least squares in the null space; damped)
///     v  = v0 + N z
///
/// so the frame follows x' exactly (while J has full row rank) and the momentum components are
/// cancelled as far as the null space allows (exactly when it is rich enough: n >= task rows +
/// cancelled rows at a regular pose). With fewer null-space dimensions d = n - task rows than
/// cancelled rows k, S K N has rank d at most by construction: z is then the least-squares,
/// minimum-norm solution over those d directions (the joint mode's n_b < k), Status::singular only
/// when they are ill-conditioned; likewise J with more task rows than joints (d = 0: z = 0).
/// Positions are integrated (Euler, or RK4 with the twist at t + dt/2 and t + dt). `null_space =
/// false` drops N z: the pseudo-inverse path, the reference that shows what the redundancy buys.
///
/// Acceleration feed-forward (the joint mode's S K_b a_b = S dh*/dt - S K_t a_t - S W(q, v, 0),
/// generalised to the null-space mode): differentiating J v = x' and S A v = S h* along the motion,
///
///     a0 = J^+ (x'' - J'v)                          (J'v: the frame's acceleration at a = 0)
///     w  = (S A N)^+ (S dh*/dt - S W(q, v, 0) - S A a0)
///     a  = a0 + N w                                 (a = a0 when null_space is false)
///
/// with the same damped factorisations as the rates. The commanded acceleration then keeps the
/// task rows exactly and the cancelled momentum rates at their target as far as the null space
/// allows; like the rates it is the minimum-norm one, so it differs from the time derivative of
/// the rate law by a drift inside the null space of [J; S A N] (the derivative of the
/// pseudo-inverses), which moves neither the frame nor the cancelled components. The predicted
/// shaking wrench of the command is W(q, v, 0) + A a. Real time as ReactionlessController
/// (noexcept, allocation-free, held command on bad input).
struct TaskSpaceConfig {
  std::string frame;                    ///< the task frame (a named frame of the model)
  std::uint32_t task_rows = cancel_both;  ///< rows of [v; w] tracked (MomentumComponent bit order:
                                          ///< force_* = v_x..v_z, moment_* = w_x..w_z)
  std::uint32_t cancel = cancel_moment;   ///< momentum rows minimised in the null space
  ReactionlessIntegrator integrator = ReactionlessIntegrator::euler;
  double rate_hz = 1000.0;
  double damping = 1e-2;       ///< relative to sigma_max, used when cond exceeds max_condition
  double max_condition = 1e4;
  /// per joint [rad/s or m/s] (the model's velocity limit when smaller; default +infinity: only
  /// the model's): scaled down, Status::saturated
  double max_rate = no_limit;
  double max_twist = no_limit;       ///< input range of the desired twist (per component)
  double max_twist_rate = no_limit;  ///< input range of the desired twist's rate (per component)
  /// false: v = J^+ x' only (no null-space term): the reference without the reaction null space
  bool null_space = true;
  /// false: the model's declared velocity limits are not applied (only max_rate): a demand study
  bool velocity_limits = true;
};

class ReactionlessTaskController {
 public:
  /// `q0`: every coordinate at the start (open mechanisms only: every coordinate actuated); the
  /// target momentum is that of (q0, v0) (v0 empty: rest). Throws std::invalid_argument naming
  /// the field.
  ReactionlessTaskController(std::shared_ptr<const MechanismModel> model, const TaskSpaceConfig& config,
                             const Eigen::VectorXd& q0, const Eigen::VectorXd& v0 = Eigen::VectorXd());

  int dof() const noexcept { return n_; }
  double dt() const noexcept { return dt_; }
  int frame() const noexcept { return frame_; }
  const Vec6& target() const noexcept { return target_; }
  /// One tick: the desired twist of the frame at t_n, its rate (for the acceleration
  /// feed-forward) and, for RK4, the twist at t_n + dt/2 and t_n + dt.
  Status step(const Vec6& twist, const Vec6& twist_rate, const Vec6& twist_half, const Vec6& twist_next) noexcept;
  /// The same with the twist's rate estimated from the three samples, (-3 x'(t_n) + 4 x'(t_n + dt/2)
  /// - x'(t_n + dt)) / dt (second order in dt; zero when the three are equal).
  Status step(const Vec6& twist, const Vec6& twist_half, const Vec6& twist_next) noexcept;
  /// The command at t_n: q (positions), v (rates), a (the acceleration feed-forward), the
  /// momentum h = A v, the frame's twist J v, the predicted shaking wrench W(q, v, 0) + A a;
  /// next: q at t_n + dt.
  const Eigen::VectorXd& q() const noexcept { return q_cmd_; }
  const Eigen::VectorXd& v() const noexcept { return v_cmd_; }
  const Eigen::VectorXd& a() const noexcept { return a_cmd_; }
  const Eigen::VectorXd& next() const noexcept { return q_; }
  const Vec6& momentum() const noexcept { return h_; }
  const Vec6& frame_twist() const noexcept { return twist_cmd_; }
  const Vec3& shaking_force() const noexcept { return force_; }
  const Vec3& shaking_moment() const noexcept { return moment_; }
  Status status() const noexcept { return status_; }

 private:
  Status rates(const Eigen::VectorXd& q, const Vec6& twist, Eigen::VectorXd& v) noexcept;
  /// a_cmd_, force_, moment_ at q_ with rates v (right after rates(q_, ...): J^+, N, S A N are
  /// those of q_); saturated: the rates were scaled down, a = 0.
  Status acceleration(const Eigen::VectorXd& v, const Vec6& twist_rate, bool saturated) noexcept;

  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
  /// The minimum-norm least-squares operator x = M^+ r = M^T (M M^T)^+ r of a (rows x n) matrix M
  /// whose rank is at most `rank` by construction (J: min(task rows, n); S A N: min(cancelled
  /// rows, n - rank of J)). rank = rows: Cholesky of M M^T (+ lambda^2 when cond(M) >
  /// max_condition, lambda^2 = damping^2 lambda_max: Status::singular). rank < rows (more rows
  /// than the dimensions that reach them): the pseudo-inverse over the `rank` largest
  /// eigenvalues of M M^T, whose condition decides the damping; the structurally zero ones are
  /// no singularity. rank = 0: x = 0.
  struct MinNorm {
    enum class Kind { zero, cholesky, eigen };
    Kind kind = Kind::zero;
    Small gram, inverse;
    SmallVector y, rhs, scale, projected;
    Eigen::SelfAdjointEigenSolver<Small> eig;
    Eigen::LLT<Small> llt;
  };
  /// Factorise M into f (M's rank at most `rank`); the status: ok, singular (damped, or M = 0),
  /// out_of_range (M M^T not finite: f gives x = 0).
  Status factorise(MinNorm& f, const Eigen::MatrixXd& M, Eigen::Index rank) const noexcept;
  /// x = M^+ r with f = factorise(M).
  static void solve(MinNorm& f, const Eigen::MatrixXd& M, const Eigen::Ref<const Eigen::VectorXd>& r,
                    Eigen::VectorXd& x) noexcept;
  /// (M M^T)^+ (damped as factorised) into f.inverse.
  static void gram_inverse(MinNorm& f) noexcept;
  std::shared_ptr<const MechanismModel> model_;
  TaskSpaceConfig config_;
  MechanismData data_;
  int n_ = 0, frame_ = -1;
  double dt_ = 1e-3;
  std::vector<int> task_rows_, rows_;
  Eigen::VectorXd q_, q_cmd_, v_cmd_, a_cmd_, zero_, a0_, k1_, k2_, k3_, k4_, q_stage_, v0_, z_, w_, rate_limit_;
  Eigen::MatrixXd J_, JpJ_, N_, M_, Jt_;
  Eigen::VectorXd rt_, rm_;
  Eigen::Index rank_J_ = 0, rank_M_ = 0;  ///< the ranks of J and S A N at most (MinNorm)
  MinNorm task_, null_;  ///< J's and S A N's at the last rates(): the feed-forward reuses null_
  Vec6 target_ = Vec6::Zero(), h_ = Vec6::Zero(), twist_cmd_ = Vec6::Zero();
  Vec3 force_ = Vec3::Zero(), moment_ = Vec3::Zero();
  Status status_ = Status::ok;
};

}  // namespace mechbal
