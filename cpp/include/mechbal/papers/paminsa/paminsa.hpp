#pragma once
/// \file paminsa.hpp
/// PAMINSA 6-DOF: three pantograph legs carrying a translating platform, plus a z-x-z serial wrist
/// (Briot & Arakelian 2009, "Complete shaking force and shaking moment balancing of the
/// position-orientation decoupled PAMINSA manipulator", AIM 2009, Section II).
///
/// The paper's figures are lost; the geometry is reconstructed from its text, link lengths and the
/// mass coefficients of eqs 6-16 (assumptions A1-A11, one parameter each, documented in
/// python/mechbal/cases/paminsa.toml). In short:
///  - leg i: pantograph A-E-D-F parallelogram (AE = DF, AF = ED = CE/k), link E-C carries D,
///    link D-F carries B, with B = ((k-1) A + C)/k. C_i = J_i - l_CJ e_z is attached to the
///    platform. A_i slides in the guide of link 5_i that turns about the vertical axis through M_i
///    (revolute actuators at M_1, M_3; M_2 passive, legs 1 and 2 parallel); B_i rides a fixed
///    vertical line, all three driven by one linear actuator (z_B).
///  - correction: the paper writes k = B_iF_i/D_iF_i; it must be k = D_iF_i/B_iF_i (else BF = 1.26 m).
///  - bodies per leg: link 1 (E-C), 2 (D-F), 3 (A-E), 4 (A-F), 5 (guide, turning about M_i),
///    6 (vertical column on B, turning with the leg plane), 7 (slider at B, translating),
///    8 (point mass at F), then the counterweights CP1 (at A_i), CP2 (at F_i), CP3 (at L_i,
///    M_iL_i = r M_iS_5i; eq 13 printed "OL_i = OO_i + r OS_5i" is garbled).
///  - the vertical counter-mass of the "supplementary system" moves as -z_P on a fixed vertical.
///  - wrist link COMs are at P and their masses are in the platform mass.
/// Everything is closed form in (P, Pdot, Pddot) and the wrist angles, rates and accelerations.
#include <array>
#include <cstddef>
#include <cstdint>

#include "mechbal/model/data.hpp"
#include "mechbal/model/rigid_body.hpp"
#include "mechbal/papers/paminsa/reactionless_wrist.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

/// Counterweight masses [kg] (point masses). Zero = absent.
struct PaminsaCounterweights {
  std::array<double, 3> at_A{{0.0, 0.0, 0.0}};  ///< m_CP1,i at A_i (eq 14)
  std::array<double, 3> at_F{{0.0, 0.0, 0.0}};  ///< m_CP2,i at F_i (eq 15)
  std::array<double, 3> at_L{{0.0, 0.0, 0.0}};  ///< m_CP3,i at L_i on link 5 (eq 16)
  double vertical = 0.0;  ///< vertical counter-mass, moving as -z_P (eq 11, with m8)
};

/// Every number of Section II.A plus the reconstruction choices (defaults = the paper / A1-A11).
struct PaminsaParameters {
  double k = 3.0;  ///< pantograph magnification, k = D_iF_i / B_iF_i (corrected)
  double a = 0.1, b = 0.175, c = 0.42, d = 0.1;  ///< layout (A8): J_i offsets and guide length
  double e = 0.05, f = 0.12;                      ///< given by the paper, meaning lost: unused
  double length_BG = 0.442, length_AE = 0.42, length_DF = 0.42, length_CE = 0.63,
         length_AF = 0.21, length_CJ = 0.0275, length_MS5 = 0.15, length_MO = 0.308;
  double platform_mass = 4.41;  ///< platform + wrist (wrist COMs at P)
  std::array<double, 8> link_mass{{0.622, 0.406, 0.406, 0.107, 0.436, 0.921, 1.2, 0.305}};
  /// principal inertias (J_XX along the link, J_YY, J_ZZ) about each COM [kg m^2]; J_ZZ = J_YY (A7)
  std::array<Vec3, 8> link_inertia{{Vec3(0.0012, 0.048, 0.048), Vec3(0.0038, 0.02, 0.02),
                                    Vec3(0.0038, 0.02, 0.02), Vec3(0.0008, 0.003, 0.003),
                                    Vec3(0.0006, 0.02, 0.02), Vec3(0.003, 0.071, 0.071),
                                    Vec3(0.0, 0.0, 0.0), Vec3(0.0, 0.0, 0.0)}};
  std::array<Vec3, 3> wrist_inertia{
      {Vec3(0.019, 0.337, 0.337), Vec3(0.039, 2.63, 2.63), Vec3(0.088, 3.35, 3.35)}};
  Vec3 nominal_platform{0.48, 0.05, 0.6775};  ///< P at which the layout is built (A8)
  double nominal_rho = 0.15;                  ///< |A_h - B_h| at the nominal pose (A8)
  double z_A = 0.0;                           ///< height of the A_i plane (A1)
  double elbow = 1.0;                         ///< +1: elbow E outward and up (A6)
  bool vertical_mass_at_centroid = true;      ///< (A9) else at vertical_mass_xy
  Eigen::Vector2d vertical_mass_xy{0.0, 0.0};
  double vertical_mass_z0 = 0.2;  ///< its height when P is at the nominal pose
  double cp3_ratio = -1.0;        ///< r of M_iL_i = r M_iS_5i
  PaminsaCounterweights counterweights;
};

/// Body indices: 0 platform; leg i (0-based) link j (0..7) at 1 + 11 i + j, CP1/CP2/CP3 at
/// 1 + 11 i + 8/9/10; 34 vertical counter-mass; 35..37 wrist links 1..3.
struct PaminsaBodyIndex {
  static constexpr std::size_t platform = 0;
  static constexpr std::size_t per_leg = 11;
  static constexpr std::size_t leg(std::size_t i, std::size_t j) { return 1 + per_leg * i + j; }
  static constexpr std::size_t cp1(std::size_t i) { return leg(i, 8); }
  static constexpr std::size_t cp2(std::size_t i) { return leg(i, 9); }
  static constexpr std::size_t cp3(std::size_t i) { return leg(i, 10); }
  static constexpr std::size_t vertical_mass = 34;
  static constexpr std::size_t wrist(std::size_t k) { return 35 + k; }
  static constexpr std::size_t mechanism_count = 35;  ///< bodies entering D (all but the wrist)
  static constexpr std::size_t count = 38;
};

/// Actuator coordinates: revolute actuators alpha_1, alpha_3 (direction of link 5 about M_1, M_3),
/// the common height z_B of the B_i sliders; the passive alpha_2 and guide strokes |M_iA_i|.
struct PaminsaActuators {
  double alpha1 = 0.0, alpha3 = 0.0, z_B = 0.0;
  double alpha2 = 0.0;
  Vec3 stroke = Vec3::Zero();
};

struct PlatformMotion {
  Vec3 position = Vec3::Zero(), velocity = Vec3::Zero(), acceleration = Vec3::Zero();
};
struct WristMotion {
  Vec3 angles = Vec3::Zero(), rates = Vec3::Zero(), accelerations = Vec3::Zero();
};

/// Constant mass data of one leg for the closed-form momentum path (derived at construction):
/// the leg's in-plane masses sit at affine combinations c_j of its points (A, C, E), so their
/// momenta are bilinear forms in (A, C, E) with G = sum m_j c_j c_j^T, mu = sum m_j c_j and
/// nu = the column's (link 6) mass x height offset x c_B; J14 / J23: summed principal inertias of
/// the parallel pantograph links 1, 4 and 2, 3; J6x: the column's inertia about its (vertical)
/// axis; guide_first / guide_second: sum m l and sum m l^2 + J_zz of link 5 and CP3 on the guide.
struct PaminsaLegMass {
  Mat3 G = Mat3::Zero();
  Vec3 mu = Vec3::Zero(), nu = Vec3::Zero(), J14 = Vec3::Zero(), J23 = Vec3::Zero();
  double J6x = 0.0, guide_first = 0.0, guide_second = 0.0;
};

/// Immutable, validated PAMINSA model with its derived layout.
class PaminsaModel {
 public:
  /// Throws std::invalid_argument naming the field (and value) on any invalid parameter.
  explicit PaminsaModel(const PaminsaParameters& parameters);

  const PaminsaParameters& parameters() const noexcept { return p_; }
  const std::array<RigidBody, PaminsaBodyIndex::count>& bodies() const noexcept { return bodies_; }
  static const char* body_name(std::size_t index) noexcept;
  const WristInertias& wrist_inertia() const noexcept { return wrist_; }
  const std::array<PaminsaLegMass, 3>& leg_mass() const noexcept { return leg_mass_; }

  // derived layout (A8)
  const std::array<Vec3, 3>& platform_joint_offset() const noexcept { return c_off_; }  ///< C_i - P
  const std::array<Eigen::Vector2d, 3>& slider_line() const noexcept { return B_h_; }  ///< B_h,i
  const std::array<Eigen::Vector2d, 3>& guide_pivot() const noexcept { return M_h_; }  ///< M_i
  const std::array<Eigen::Vector2d, 3>& nominal_A() const noexcept { return A0_h_; }
  const Eigen::Vector2d& vertical_mass_xy() const noexcept { return vcw_; }

  /// Closed-form inverse kinematics P -> actuators. Non-finite P: Status::non_finite_input; a P
  /// whose strokes overflow: Status::out_of_range and `out` zeroed.
  Status inverse_kinematics(const Vec3& P, PaminsaActuators& out) const noexcept;
  /// Closed-form forward solve (alpha1, alpha3, z_B) -> P. Parallel guides: Status::singular.
  Status forward_kinematics(double alpha1, double alpha3, double z_B, Vec3& P) const noexcept;

 private:
  PaminsaParameters p_;
  std::array<RigidBody, PaminsaBodyIndex::count> bodies_;
  WristInertias wrist_;
  std::array<PaminsaLegMass, 3> leg_mass_;
  std::array<Vec3, 3> c_off_;
  std::array<Eigen::Vector2d, 3> B_h_, M_h_, A0_h_;
  Eigen::Vector2d vcw_;
};

/// Preallocated results of one instant.
struct PaminsaWorkspace {
  std::array<BodyState, PaminsaBodyIndex::count> states;
  /// base-frame points A, B, C, D, E, F of each leg
  std::array<std::array<Vec3, 6>, 3> leg_points;
};

/// Motion of the 35 mechanism bodies (all but the wrist). Non-finite input:
/// Status::non_finite_input and the workspace is untouched; an unreachable pose (pantograph
/// cannot close, or A_i on its guide pivot M_i): Status::singular and the workspace is untouched;
/// finite input whose motion overflows: Status::out_of_range and the workspace is reset to rest.
Status paminsa_mechanism_kinematics(const PaminsaModel& model, const PlatformMotion& platform,
                                    PaminsaWorkspace& ws) noexcept;
/// Motion of the three wrist links (COMs at P).
Status paminsa_wrist_kinematics(const PaminsaModel& model, const PlatformMotion& platform,
                                const WristMotion& wrist, PaminsaWorkspace& ws) noexcept;
/// Every body: mechanism then wrist.
Status paminsa_kinematics(const PaminsaModel& model, const PlatformMotion& platform,
                          const WristMotion& wrist, PaminsaWorkspace& ws) noexcept;

/// D of eq 19 (angular momentum about O of every body but the wrist's rotation; the wrist's
/// translation is in the platform mass) and dD/dt, from the workspace's mechanism bodies.
Status paminsa_mechanism_momentum(const PaminsaModel& model, const PaminsaWorkspace& ws, Vec3& D,
                                  Vec3& D_dot) noexcept;

/// Momenta about O and their rates (shaking force and moment, Briot & Arakelian 2009, eqs 1-4) of
/// all 38 bodies of a workspace filled by paminsa_kinematics: the sum over the bodies' states,
/// PAMINSA's own fast path (the general path is algorithm/shaking_wrench.hpp over
/// papers/paminsa/cases/paminsa-linkage.toml, tested equal). Non-finite states give
/// Status::non_finite_input, an overflowing sum Status::out_of_range; either leaves `out` zero.
Status paminsa_shaking_wrench(const PaminsaModel& model, const PaminsaWorkspace& ws,
                              ShakingWrench& out) noexcept;

/// The 35 mechanism bodies' momenta and their rates (linear momentum, D of eq 19, shaking force,
/// dD/dt) in closed form from the platform motion, without forming the bodies' states (each leg is
/// a planar linkage in a vertical plane turning about z; derivation in paminsa.cpp). Equals the
/// sum over the 35 bodies' states of paminsa_mechanism_kinematics (to rounding). Same statuses as
/// paminsa_mechanism_kinematics; `out` is untouched unless Status::ok.
Status paminsa_mechanism_wrench(const PaminsaModel& model, const PlatformMotion& platform,
                                ShakingWrench& out) noexcept;
/// D only (what the RK4 stages need): positions and rates, no accelerations (the platform's
/// acceleration must still be finite).
Status paminsa_mechanism_angular_momentum(const PaminsaModel& model,
                                          const PlatformMotion& platform, Vec3& D) noexcept;

/// Input range of the platform motion a PaminsaController tick accepts (per component, finite).
/// The position range is the reachable workspace (an unreachable pose is Status::singular).
struct PlatformLimits {
  double max_speed = 10.0;           ///< |Pdot| per component [m/s]
  double max_acceleration = 1000.0;  ///< |Pddot| per component [m/s^2] (~100 g)
};

/// One controller tick of the fully balanced PAMINSA: kinematics at t_n, D, the reactionless-wrist
/// step, then every body's motion (with the wrist following the command) and the shaking wrench.
class PaminsaController {
 public:
  /// Throws std::invalid_argument naming the field on a bad configuration or limit.
  PaminsaController(const PaminsaModel& model, const ReactionlessWristConfig& config,
                    const Vec3& initial_wrist_angles, const PlatformLimits& limits = {});

  /// Restart at rest-state `initial` (wrist at rest): H_target = D(initial). On any failure
  /// (non-finite, out of range, unreachable, wrist refusal) nothing changes and the status says
  /// why.
  Status reset(const PlatformMotion& initial, const Vec3& wrist_angles) noexcept;
  /// One tick: platform motion at t_n, t_n + dt/2 and t_n + dt (the last two from the planned
  /// trajectory; the Euler integrator ignores them). Bad input holds the wrist (zero rates, same
  /// angles) and keeps the workspace and wrench of the last good tick: non-finite input
  /// Status::non_finite_input; a speed or acceleration beyond limits() (or an overflowing
  /// result) Status::out_of_range; an unreachable pose Status::singular. The wrist's own statuses
  /// (singular, saturated, out_of_range) pass through.
  Status tick(const PlatformMotion& now, const PlatformMotion& half,
              const PlatformMotion& next) noexcept;
  const PlatformLimits& limits() const noexcept { return limits_; }

  const PaminsaModel& model() const noexcept { return model_; }
  const PaminsaWorkspace& workspace() const noexcept { return ws_; }
  const ReactionlessWrist& wrist() const noexcept { return wrist_; }
  const ShakingWrench& wrench() const noexcept { return wrench_; }  ///< all 38 bodies
  const Vec3& D() const noexcept { return D_; }
  const Vec3& D_dot() const noexcept { return D_dot_; }

 private:
  bool in_range(const PlatformMotion& m) const noexcept;

  PaminsaModel model_;
  PlatformLimits limits_;
  PaminsaWorkspace ws_;
  ReactionlessWrist wrist_;
  ShakingWrench wrench_;
  Vec3 D_ = Vec3::Zero(), D_dot_ = Vec3::Zero();
};

/// Row-major output arrays for batch runs over N instants (any pointer may be null):
/// com, com_velocity, com_acceleration, angular_velocity, angular_acceleration (N, 38, 3);
/// rotation (N, 38, 3, 3); force, moment, D, D_dot (N, 3); wrist_angles, wrist_rates,
/// wrist_accelerations (N, 3); condition (N,); status (N,).
struct PaminsaBatchOutput {
  double* com = nullptr;
  double* com_velocity = nullptr;
  double* com_acceleration = nullptr;
  double* rotation = nullptr;
  double* angular_velocity = nullptr;
  double* angular_acceleration = nullptr;
  double* force = nullptr;
  double* moment = nullptr;
  double* D = nullptr;
  double* D_dot = nullptr;
  double* wrist_angles = nullptr;
  double* wrist_rates = nullptr;
  double* wrist_accelerations = nullptr;
  double* condition = nullptr;
  std::uint32_t* status = nullptr;
};

/// Kinematics + shaking wrench with prescribed wrist motion at N instants: P, Pd, Pdd, q, qd, qdd
/// each (N, 3) row-major. Returns the OR of the statuses.
Status paminsa_kinematics_batch(const PaminsaModel& model, std::size_t instants, const double* P,
                                const double* Pd, const double* Pdd, const double* q,
                                const double* qd, const double* qdd,
                                const PaminsaBatchOutput& out) noexcept;

/// Fully balanced run with the reactionless wrist: platform motion sampled on the half-step grid
/// t_j = j dt/2, j = 0..2 steps, each (2 steps + 1, 3) row-major; outputs at the steps + 1 full
/// samples t_n = n dt. H_target = D(t_0) (start at rest). Returns the OR of the statuses.
/// Not real time (builds a PaminsaController): throws std::invalid_argument on a bad config.
Status paminsa_reactionless_run(const PaminsaModel& model, const ReactionlessWristConfig& config,
                                const Vec3& initial_wrist_angles, std::size_t steps,
                                const double* P_half, const double* Pd_half,
                                const double* Pdd_half, const PaminsaBatchOutput& out);

}  // namespace mechbal
