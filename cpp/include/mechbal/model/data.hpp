#pragma once
/// \file data.hpp
/// MechanismData: every buffer the algorithms over a MechanismModel need, allocated once from the
/// model (Pinocchio's Data). Algorithms write their results here; nothing allocates afterwards,
/// except the dense results whose size is quadratic in the model (the mass matrix, dof x dof, and
/// the torque and gravity regressors, dof x 10 bodies): they are sized by the first call of their
/// algorithm, so that a data for a 10,000-link chain is O(n) (a few MB, not GB) when only the O(n)
/// algorithms run. A real-time user of the mass matrix calls reserve_mass_matrix() at set-up
/// (MechanismDynamics does).
/// All world quantities are in the base frame O; moments and angular momenta are about O.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "mechbal/model/model.hpp"
#include "mechbal/model/rigid_body.hpp"

namespace mechbal {

/// Momenta about the base origin O and their rates: what algorithm/shaking_wrench.hpp computes
/// for a mechanism (MechanismData::shaking). Briot & Arakelian 2009, eqs 1-4: the shaking force is
/// F = dP/dt = sum_j m_j a_Gj and the shaking moment about O is M_O = dH_O/dt =
/// sum_j (m_j OG_j x a_Gj + I_j dw_j/dt + w_j x I_j w_j), with I_j the inertia in the base frame.
struct ShakingWrench {
  Vec3 linear_momentum = Vec3::Zero();   ///< P = sum m v_G            [kg m/s]
  Vec3 angular_momentum = Vec3::Zero();  ///< H_O = sum (m OG x v_G + I w) [kg m^2/s]
  Vec3 force = Vec3::Zero();             ///< shaking force F = dP/dt (eq 1)          [N]
  Vec3 moment = Vec3::Zero();            ///< shaking moment M_O = dH_O/dt (eqs 2-4) [N m]
};

/// A wrench on the mechanism from its base or the ground, gravity included (moment about O):
/// MechanismData::base_reaction and support_reaction (algorithm/shaking_wrench.hpp). The
/// mechanism pushes on its base with the opposite wrench.
struct BaseReaction {
  Vec3 force = Vec3::Zero();
  Vec3 moment = Vec3::Zero();
};

struct MechanismData {
  explicit MechanismData(const MechanismModel& model);

  /// Sizes mass_matrix (dof x dof) now, so that mass_matrix() and the closed-loop dynamics
  /// allocate nothing on their first call (real-time set-up).
  void reserve_mass_matrix();
  /// Sizes `buffer` to rows x cols (zeros) when it has another size; false when the memory cannot
  /// be had (the algorithm then returns Status::out_of_range). No allocation when already sized.
  static bool size_dense(Eigen::MatrixXd& buffer, Eigen::Index rows, Eigen::Index cols) noexcept;
  /// Sizes the dof x na buffers of the closed-loop algorithms (loop_projection, the reduced mass
  /// matrix and its work): at construction for a closed model, by the first closed-loop call for
  /// an open one (where na = dof would make them quadratic). False when the memory cannot be had.
  bool size_actuated_buffers(const MechanismModel& model) noexcept;

  int dof;         ///< of the model this data was built for (checked by every algorithm)
  int num_links;
  int num_bodies;
  int num_frames;
  int num_springs;

  // ---- joint positions (every link's joint, gear couplings applied) ----
  std::vector<double> joint_position, joint_velocity, joint_acceleration;

  // ---- forward kinematics: link frames F_i in O (index 0 = base) ----
  std::vector<Mat3> link_rotation;               ///< F_i -> O
  std::vector<Vec3> link_position;               ///< origin of F_i in O
  std::vector<Vec3> link_angular_velocity;       ///< in O
  std::vector<Vec3> link_velocity;               ///< of F_i's origin, in O
  std::vector<Vec3> link_angular_acceleration;   ///< in O
  std::vector<Vec3> link_acceleration;           ///< of F_i's origin, in O (gravity excluded)
  std::vector<BodyState> body_states;            ///< every body's motion (com, rotation, ...), in O
  std::vector<RigidBody> body_inertias;          ///< mass and inertia about com, body = link axes
  std::vector<Eigen::Isometry3d> frame_placements;  ///< named frames in O

  // ---- results ----
  double mass = 0.0;                   ///< total mass [kg]
  Vec3 center_of_mass = Vec3::Zero();  ///< in O [m]
  ShakingWrench shaking;   ///< momenta about O and their rates (shaking force and moment)
  /// Wrench the base exerts on the moving mechanism, gravity included (moment about O): the
  /// bodies on the root link and on links fixed to it are the base's own and do not count
  /// (algorithm/shaking_wrench.hpp).
  BaseReaction base_reaction;
  /// Wrench the ground exerts on every body of the model, those fixed to the base included:
  /// base_reaction plus the weight of the bodies that do not move.
  BaseReaction support_reaction;
  Eigen::VectorXd joint_torque;    ///< inverse dynamics, springs included [N m or N], size dof
  Eigen::VectorXd gravity_torque;  ///< G(q)
  Eigen::VectorXd bias_torque;     ///< C(q, v) v + G(q) + K(q) (springs included)
  /// K(q) = dV_springs/dq: the joint forces that hold the springs still (algorithm/springs.hpp)
  Eigen::VectorXd spring_torque;
  Eigen::VectorXd static_torque;   ///< G(q) + K(q): the joint forces that hold the mechanism still
  Eigen::VectorXd spring_length;   ///< anchor distance d of each spring [m]
  Eigen::VectorXd spring_tension;  ///< tension T at each spring's anchors [N]
  double spring_energy = 0.0;      ///< elastic energy of all springs [J]
  double potential_energy = 0.0;   ///< gravity (zero at O) plus springs [J]
  /// Wrench the base exerts on the moving links through the springs anchored to it (in O, moment
  /// about O): the springs' part of the support wrench (which, the rate of momentum minus the
  /// weights, includes it).
  Vec3 spring_base_force = Vec3::Zero(), spring_base_moment = Vec3::Zero();
  Eigen::MatrixXd mass_matrix;     ///< M(q), dof x dof, symmetric (sized by the first mass_matrix())
  Eigen::MatrixXd momentum_matrix;  ///< 6 x dof: [P; H_O] = A(q) v (linear first)
  Eigen::MatrixXd frame_jacobian;   ///< 6 x dof: [v; w] of a frame's origin, O axes
  /// Regressors over each body's 10 inertial parameters, body b in columns 10b..10b+9:
  /// [m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] with c and I (about the link frame
  /// origin) in the frame of the body's link (Pinocchio's ordering).
  Eigen::MatrixXd torque_regressor;    ///< dof x 10 nb: tau = Y pi (sized on first use)
  Eigen::MatrixXd gravity_regressor;   ///< dof x 10 nb: G(q) = Y pi (sized on first use)
  Eigen::MatrixXd momentum_regressor;  ///< 6 x 10 nb: [P; H_O] = Y pi

  // ---- closed loops (algorithm/loops.hpp); sizes: m constraints, n = dof, na actuated ----
  Eigen::VectorXd loop_residual;           ///< closure equations Phi(q) (m)
  Eigen::MatrixXd loop_jacobian;           ///< A = dPhi/dq (m x n)
  Eigen::VectorXd loop_bias;               ///< gamma = dA/dt v: A a + gamma = 0 (m)
  Eigen::MatrixXd loop_projection;         ///< C: v = C v# (n x na), C = [I; -(A°)^-1 A#] reordered
  Eigen::VectorXd loop_acceleration_bias;  ///< c: a = C a# + c (n)
  double loop_rcond = 1.0;         ///< reciprocal condition estimate of the passive Jacobian A°
  int loop_iterations = 0;         ///< Newton iterations of the last position solve
  double loop_residual_norm = 0.0; ///< max |Phi| after the last position solve [m or rad]
  Eigen::VectorXd closed_position, closed_velocity, closed_acceleration;  ///< q, v, a (n)
  Eigen::VectorXd actuated_force;          ///< tau# = C^T tau (na)
  Eigen::VectorXd actuated_gravity;        ///< C^T G (na)
  Eigen::VectorXd actuated_static_torque;  ///< C^T (G + K): gravity and springs (na)
  Eigen::VectorXd actuated_acceleration;   ///< a# of the forward dynamics (na)
  Eigen::MatrixXd reduced_mass_matrix;     ///< C^T M C (na x na)
  // scratch of the loop algorithms
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  /// The actuated coordinates (indices into model.actuated_coordinates()) that move a loop frame,
  /// fixed at construction: only their columns of C need a solve (the others are unit vectors)
  std::vector<int> loop_actuated_columns;
  RowMajorMatrix loop_block_residual;      ///< m x nla (the refinement's -A# - A° X over loop_actuated_columns)
  RowMajorMatrix loop_block_step;          ///< np x nla
  Eigen::VectorXd loop_constraint_work;    ///< m
  Eigen::VectorXd loop_refine_solution;    ///< np
  Eigen::LDLT<Eigen::MatrixXd> reduced_ldlt;  ///< of C^T M C (na x na)
  /// The passive coordinates in the elimination order of N = A°^T A° (a minimum-degree ordering of
  /// the loops' structure, fixed at construction: PAMINSA's legs before the platform they share, so
  /// that the factor keeps the legs' blocks apart; then sorted by height in the elimination tree,
  /// the same fill, so that the legs' columns alternate); A°'s columns, the Newton step and the
  /// solution rows are in this order.
  std::vector<int> loop_elimination;
  /// Structure of L in N = L D L^T: the rows (elimination positions, increasing) that column k may
  /// fill are loop_factor_rows[loop_factor_start[k] .. loop_factor_start[k + 1]).
  std::vector<int> loop_factor_start, loop_factor_rows;
  /// The same entries row by row (for the forward solve): row i's are loop_factor_row_entries
  /// [loop_factor_row_start[i] .. loop_factor_row_start[i + 1]) (indices into L's entries), in
  /// the columns loop_factor_row_columns (increasing).
  std::vector<int> loop_factor_row_start, loop_factor_row_entries, loop_factor_row_columns;
  /// The passive columns (elimination positions, increasing) each loop's rows involve:
  /// loop_members[loop_member_start[i] .. loop_member_start[i + 1]) for loop i.
  std::vector<int> loop_member_start, loop_members;
  std::vector<int> loop_row_start;  ///< loop i's rows: loop_row_start[i] .. loop_row_start[i + 1]
  /// Loop i's Jacobian columns are those of the joints from its frames' links up to (not
  /// including) the link loop_path_stop[i]: 0 (the root), or for a planar_point loop the frames'
  /// deepest common ancestor (the joints from it up move both frames together: zero columns).
  std::vector<int> loop_path_stop;
  /// Those joints (with a coordinate) listed per loop, each once: loop i's are
  /// loop_path_joints[loop_path_joint_start[i] .. loop_path_joint_start[i + 1]), frame A's path
  /// first, with the paths they are on (bit 1: A's, bit 2: B's; a common ancestor's on both), so
  /// that the loop's columns come from a list instead of two walks up the tree per evaluation.
  /// (`first`: the first of the loop's joints on its coordinate, which sets the column's rows
  /// instead of adding to them; the joint's type and coordinate ratio copied from the model)
  struct LoopPathJoint {
    int link = 0, coordinate = 0;
    unsigned char sides = 0;
    bool first = true, revolute = true;
    double ratio = 1.0;
  };
  std::vector<LoopPathJoint> loop_path_joints;
  std::vector<int> loop_path_joint_start;
  /// Each loop's slice of A, fixed at construction: its rows (row .. row + rows), its passive
  /// columns (loop_members[member .. member + count]: elimination positions, increasing) with
  /// their block of A° (loop_passive_blocks from `block`: rows x count, column-major; A°'s
  /// structural nonzeros), and the columns of A# that move it (loop_actuated_members[actuated ..
  /// actuated + actuated_count]: indices into loop_actuated_columns) with their block
  /// (loop_actuated_blocks from `actuated_block`, the same layout).
  struct LoopBlockInfo {
    int row = 0, rows = 0, member = 0, count = 0, block = 0, actuated = 0, actuated_count = 0, actuated_block = 0;
  };
  std::vector<LoopBlockInfo> loop_blocks;
  std::vector<int> loop_actuated_members;
  Eigen::VectorXd loop_passive_blocks, loop_actuated_blocks;
  /// N = A°^T A° + damping, then its factors N = L D L^T: the np pivots (D after the
  /// factorisation), then the entries of L's columns in loop_factor_rows' order (np + nnz(L)).
  Eigen::VectorXd loop_factor_values;
  Eigen::VectorXd loop_pivot_inverse;  ///< 1 / D, 0 where a pivot is not positive (np)
  /// Symbolic factorisation (construction), as flat lists:
  /// - loop_normal_targets: per loop, its column pairs a <= b in order, three ints each: the entry
  ///   of loop_factor_values their product adds into (~entry for the entry's first product, which
  ///   is stored instead), the offsets of columns a and b in the loop's block;
  /// - loop_factor_updates: per entry e of loop_factor_values (pivot or entry of L, from
  ///   loop_factor_update_start[e]), the pairs (p, r) of L's entries in an earlier column whose
  ///   products l_p u_r it is reduced by (l: scaled by the pivot, u: loop_factor_unscaled);
  /// - loop_factor_clear: the entries no product of the assembly reaches (fill), cleared first.
  std::vector<int> loop_normal_targets, loop_factor_updates, loop_factor_update_start, loop_factor_clear;
  Eigen::VectorXd loop_factor_unscaled;  ///< L's entries before the division by their pivot (nnz)
  /// Each named frame in its link's joint-aligned frame L (model.hpp): the loop equations place the
  /// closure frames with one product each.
  std::vector<Mat3> frame_rotation_in_link;
  std::vector<Vec3> frame_position_in_link;
  Eigen::VectorXd loop_step, loop_trial;   ///< np, n
  RowMajorMatrix loop_solution;            ///< np x nla (elimination order)
  Eigen::MatrixXd loop_reduced_work;       ///< n x na
  Eigen::VectorXd loop_vector_work;        ///< n
  /// The warm start's third- and fourth-order terms (loops.cpp, solve_positions): after a
  /// warm-started solve, the solution minus the second-order prediction it started from (n), the
  /// same one tick earlier, the solution they are valid at, the step parameters s of those
  /// predictions, the largest |entry| of the last error and how many of the two errors are
  /// consecutive (0 to 2).
  Eigen::VectorXd loop_prediction_error, loop_prediction_error_old, loop_prediction_origin;
  double loop_prediction_step = 0.0, loop_prediction_step_old = 0.0, loop_prediction_size = 0.0;
  int loop_prediction_depth = 0;
  Eigen::VectorXd loop_prediction_offset;  ///< np: a Newton step from the last solution, when it took none
  bool loop_prediction_offset_valid = false;
  /// loop_prediction_offset holds the step's right-hand side, not the step yet (loops.cpp: solved
  /// with C's columns by the projection that follows the solve)
  bool loop_prediction_offset_pending = false;
  /// closed_shaking_wrench's field of the accelerations' actuated-and-passive part (loops.cpp):
  /// per link, the angular then the origin acceleration (in L_i) that a alone gives, with no
  /// velocity (2 per link; a closed model only).
  std::vector<Vec3> loop_acceleration_field;

  // ---- internal buffers (per link, in the joint-aligned frames L_i of model.hpp) ----
  // Field order: what one pass touches sits together (the placement, relative and in O, then the
  // motion and wrench of the Newton-Euler passes), so that a pass over a long chain that no longer
  // fits in the cache loads as few cache lines per link as it can.
  struct LinkWork {
    Mat3 rotation;     ///< L_i relative to L_parent at the current q
    Vec3 translation;  ///< origin of L_i in L_parent
    Mat3 world_rotation;   ///< L_i -> O
    Vec3 world_position;   ///< origin of L_i in O
    Vec3 w, alpha, acc;    ///< angular velocity, angular acceleration, origin acceleration (in L_i)
    Vec3 vel;              ///< origin velocity (in L_i)
    Vec3 force, moment;    ///< wrench from the parent on link i (moment about L_i's origin)
    double composite_mass;
    Vec3 composite_first_moment;
    Mat3 composite_inertia;
    /// detail::place's bookkeeping: the joint position rotation / translation were computed at
    /// (NaN: never), world_* not yet updated after a local-only placement, world_* recomputed
    /// by the last placement in O (its children's poses in O must follow).
    double placed_at;
    bool world_stale;
    bool world_moved;
    /// composite_* are those of the current placements of the links below (composite_inertias)
    bool composite_current;
    /// momentum_matrix holds this link's column term at its current pose in O and composite
    /// (momentum_matrix_placed recomputes only the columns of links that moved or whose subtree did)
    bool momentum_current;
  };
  std::vector<LinkWork, detail::LargeBufferAllocator<LinkWork>> work;  ///< huge pages for big trees
  Eigen::MatrixXd link_regressor;           ///< dof x 10 scratch: one link's torque regressor
  Eigen::MatrixXd link_momentum_regressor;  ///< 6 x 10 scratch: one link's momentum regressor
  std::vector<unsigned char> momentum_column_stale;  ///< dof scratch of momentum_matrix_placed
};

}  // namespace mechbal
