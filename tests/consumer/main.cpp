// A consumer of the installed core that includes only the umbrella header and uses the general
// model (MechanismModel, MechanismData, its algorithms) and every controller (ComputedTorque over
// each inverse-dynamics back end, DecoupledJointController, ReactionlessWrist, PaminsaController). Exit code 0 when every
// result is what it must be; each failure prints one line.
#include <mechbal/mechbal.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {
int failures = 0;
void check(bool ok, const char* what) {
  if (!ok) {
    std::printf("FAILED: %s\n", what);
    ++failures;
  }
}

mechbal::MechanismModel two_link_arm() {
  mechbal::MechanismDescription d;
  std::string parent = d.root_name;
  for (int i = 0; i < 2; ++i) {
    mechbal::Joint j;
    j.name = i == 0 ? "shoulder" : "elbow";
    j.parent = parent;
    j.axis = mechbal::Vec3(0.0, -1.0, 0.0);
    if (i == 1) j.placement.translation() = mechbal::Vec3(0.5, 0.0, 0.0);
    d.joints.push_back(j);
    d.bodies.push_back(mechbal::Body{j.name, "link", j.name, i == 0 ? 4.0 : 2.0, mechbal::Vec3(0.2, 0.0, 0.0),
                                     mechbal::Vec3(0.004, 0.09, 0.09).asDiagonal()});
    parent = j.name;
  }
  return mechbal::MechanismModel(d);
}

// One computed-torque tick at rest on the desired pose: the command is the gravity torque.
void computed_torque_over(mechbal::InverseDynamics& model, const char* name) {
  const Eigen::VectorXd gains = Eigen::VectorXd::Constant(2, 100.0);
  mechbal::ComputedTorque controller(model, gains, gains);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(2, 0.3), zero = Eigen::VectorXd::Zero(2);
  Eigen::VectorXd tau(2), gravity(2);
  const mechbal::Status s = controller.step(q, zero, q, zero, zero, tau);
  model.inverse_dynamics(q, zero, zero, gravity);
  std::printf("ComputedTorque over %s: %s, tau = (%.4f, %.4f) N m\n", name,
              mechbal::status_name(s), tau(0), tau(1));
  check(s == mechbal::Status::ok && tau.allFinite() && (tau - gravity).norm() < 1e-9 &&
            tau.norm() > 1.0,
        name);
}
}  // namespace

int main() {
  std::printf("mechbal %s\n", MECHBAL_VERSION);

  // shaking wrench: one body on a vertical slider accelerating at -9.81 m/s^2 has F = m a
  {
    mechbal::MechanismDescription d;
    mechbal::Joint slider;
    slider.name = "slider";
    slider.type = mechbal::JointType::prismatic;
    slider.parent = d.root_name;
    slider.axis = mechbal::Vec3::UnitZ();
    d.joints.push_back(slider);
    d.bodies.push_back(mechbal::Body{"body", "link", "slider", 2.0, mechbal::Vec3::Zero(),
                                     mechbal::Mat3::Identity() * 0.1});
    const mechbal::MechanismModel model(d);
    mechbal::MechanismData data(model);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1), a = Eigen::VectorXd::Constant(1, -9.81);
    const mechbal::Status s = mechbal::shaking_wrench(model, data, zero, zero, a);
    check(s == mechbal::Status::ok && std::abs(data.shaking.force.z() + 19.62) < 1e-12, "shaking_wrench");
  }

  // ComputedTorque over every back end of the same arm
  const mechbal::MechanismModel arm = two_link_arm();
  mechbal::MechanismDynamics general(arm);
  mechbal::KdlChainDynamics kdl(arm);
  computed_torque_over(general, "MechanismDynamics (two-link arm)");
  computed_torque_over(kdl, "KdlChainDynamics");
#if MECHBAL_WITH_PAPERS  // the papers' closed forms (a build without papers has none)
  mechbal::Arm2DofDynamics arm2dof{mechbal::Arm2DofParameters{}};
  computed_torque_over(arm2dof, "Arm2DofDynamics");
  mechbal::FiveBarParameters fb;
  fb.a1 = fb.a2 = fb.b1 = fb.b2 = 0.3;
  fb.d = 0.1;
  fb.mp1 = fb.mp2 = fb.md1 = fb.md2 = 1.0;
  fb.cp1 = fb.cp2 = fb.cd1 = fb.cd2 = 0.15;
  fb.Jp1 = fb.Jp2 = fb.Jd1 = fb.Jd2 = 0.01;
  mechbal::FiveBarDynamics five_bar(fb);
  {
    const Eigen::VectorXd gains = Eigen::VectorXd::Constant(2, 100.0);
    mechbal::ComputedTorque controller(five_bar, gains, gains);
    Eigen::VectorXd q(2), zero = Eigen::VectorXd::Zero(2), tau(2);
    q << 2.0, 1.0;
    const mechbal::Status st = controller.step(q, zero, q, zero, zero, tau);
    std::printf("ComputedTorque over FiveBarDynamics: %s\n", mechbal::status_name(st));
    check(tau.allFinite(), "ComputedTorque over FiveBarDynamics");
  }
#else
  mechbal::MechanismDynamics& arm2dof = general;  // the closed loop below runs on the general model
#endif

  // the general model: the same arm as a MechanismModel, its algorithms and a controller over it
  {
    mechbal::MechanismDescription d;
    for (int i = 0; i < 2; ++i) {
      mechbal::Joint j;
      j.name = i == 0 ? "shoulder" : "elbow";
      j.parent = i == 0 ? "base" : "shoulder";
      j.axis = mechbal::Vec3(0.0, -1.0, 0.0);
      if (i == 1) j.placement.translation() = mechbal::Vec3(0.5, 0.0, 0.0);
      d.joints.push_back(j);
      mechbal::Body b;
      b.name = j.name + "_link";
      b.link = j.name;
      b.mass = i == 0 ? 4.0 : 2.0;
      b.com = mechbal::Vec3(0.2, 0.0, 0.0);
      b.inertia = mechbal::Vec3(0.004, 0.09, 0.09).asDiagonal();
      d.bodies.push_back(b);
    }
    mechbal::Joint disc;  // a counter-rotating disc on the shoulder link, geared to the elbow
    disc.name = "disc";
    disc.parent = "shoulder";
    disc.axis = mechbal::Vec3(0.0, -1.0, 0.0);
    disc.mimic_joint = "elbow";
    disc.mimic_ratio = -1.0;
    d.joints.push_back(disc);
    d.bodies.push_back(mechbal::Body{"disc", "disc", "disc", 0.0, mechbal::Vec3::Zero(),
                                     mechbal::Vec3(0.005, 0.01, 0.005).asDiagonal()});
    const mechbal::MechanismModel model(d);
    mechbal::MechanismData data(model);
    const Eigen::VectorXd q = Eigen::VectorXd::Constant(2, 0.3), v = Eigen::VectorXd::Ones(2),
                          a = Eigen::VectorXd::Constant(2, -0.5);
    mechbal::Status st = mechbal::inverse_dynamics(model, data, q, v, a);
    st |= mechbal::shaking_wrench(model, data, q, v, a);
    st |= mechbal::base_reaction(model, data, q, v, a);
    // R = dP/dt - m g: the base reaction is the shaking force plus the weight
    const double weight_gap =
        (data.base_reaction.force - data.shaking.force + data.mass * model.gravity()).norm();
    std::printf("MechanismModel: %d dof, %s, tau = (%.4f, %.4f) N m, |R - (F - m g)| = %.1e N\n",
                model.dof(), mechbal::status_name(st), data.joint_torque(0), data.joint_torque(1),
                weight_gap);
    check(st == mechbal::Status::ok && weight_gap < 1e-9 && data.joint_torque.allFinite(),
          "MechanismModel algorithms");
    mechbal::MechanismDynamics dynamics(model);
    computed_torque_over(dynamics, "MechanismDynamics");
  }

  // decoupled joint control: tau = k (qdd_d + kp e + kd e')
  {
    const Eigen::VectorXd k = Eigen::VectorXd::Constant(2, 0.5);
    const Eigen::VectorXd gains = Eigen::VectorXd::Constant(2, 10.0);
    mechbal::DecoupledJointController controller(k, gains, gains);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2), q_des = Eigen::VectorXd::Ones(2);
    Eigen::VectorXd tau(2);
    const mechbal::Status st = controller.step(zero, zero, q_des, zero, zero, tau);
    std::printf("DecoupledJointController: %s, tau = (%.3f, %.3f)\n", mechbal::status_name(st),
                tau(0), tau(1));
    check(st == mechbal::Status::ok && std::abs(tau(0) - 5.0) < 1e-12, "DecoupledJointController");
  }

  // no controller: zero effort (a passive simulation's command)
  {
    mechbal::PassiveController passive(2);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2), q = Eigen::VectorXd::Ones(2);
    Eigen::VectorXd tau = Eigen::VectorXd::Ones(2);
    const mechbal::Status st = passive.step(q, q, zero, zero, zero, tau);
    std::printf("PassiveController: %s\n", mechbal::status_name(st));
    check(st == mechbal::Status::ok && tau.isZero(0.0), "PassiveController");
  }

  // closed loop on the closed-form arm (on the general model in a build without papers)
  {
    const Eigen::VectorXd gains = Eigen::VectorXd::Constant(2, 100.0);
    mechbal::ComputedTorque controller(arm2dof, gains, gains);
    Eigen::VectorXd start = Eigen::VectorXd::Zero(2), end = Eigen::VectorXd::Ones(2);
    mechbal::RestToRestTrajectory desired(start, end, 0.5, mechbal::TimeLaw::quintic);
    mechbal::ClosedLoopOptions options;
    options.duration = 0.5;
    options.sampling = mechbal::ControlSampling::every_rk4_stage;  // exact model, no hold: e = 0
    const mechbal::ClosedLoopLog log = mechbal::simulate_computed_torque(
        arm2dof, controller, desired, start, Eigen::VectorXd::Zero(2), options);
    const double error = (log.q.bottomRows(1) - end.transpose()).cwiseAbs().maxCoeff();
    std::printf("simulate_computed_torque: %s, final error %.2e rad\n",
                mechbal::status_name(log.status), error);
    check(log.status == mechbal::Status::ok && error < 1e-6, "simulate_computed_torque");
  }

#if MECHBAL_WITH_PAPERS
  // reactionless wrist: keeps the total angular momentum at its target
  {
    mechbal::WristInertias inertia = {mechbal::Vec3(0.019, 0.337, 0.337).asDiagonal(),
                                      mechbal::Vec3(0.039, 2.63, 2.63).asDiagonal(),
                                      mechbal::Vec3(0.088, 3.35, 3.35).asDiagonal()};
    mechbal::ReactionlessWristConfig config;
    config.integrator = mechbal::WristIntegrator::rk4;
    const mechbal::Vec3 angles(0.1, 0.8, 0.2), D(0.05, -0.02, 0.1);
    mechbal::ReactionlessWrist wrist(inertia, config, angles, mechbal::Vec3::Zero());
    const mechbal::Status st = wrist.step(D, mechbal::Vec3::Zero(), D, D);
    const mechbal::Vec3 H = D + mechbal::wrist_momentum_matrix(inertia, angles) * wrist.command().rates;
    std::printf("ReactionlessWrist: %s, |H - H_target| = %.1e\n", mechbal::status_name(st), H.norm());
    check(st == mechbal::Status::ok && H.norm() < 1e-12, "ReactionlessWrist");
  }

  // the whole PAMINSA tick, at rest at the nominal pose
  {
    const mechbal::PaminsaModel paminsa{mechbal::PaminsaParameters{}};
    mechbal::PaminsaController controller(paminsa, mechbal::ReactionlessWristConfig{},
                                          mechbal::Vec3(0.1, 0.8, 0.2));
    mechbal::PlatformMotion rest;
    rest.position = paminsa.parameters().nominal_platform;
    const mechbal::Status r = controller.reset(rest, mechbal::Vec3(0.1, 0.8, 0.2));
    const mechbal::Status st = controller.tick(rest, rest, rest);
    std::printf("PaminsaController: reset %s, tick %s, |F| = %.1e N\n", mechbal::status_name(r),
                mechbal::status_name(st), controller.wrench().force.norm());
    check(r == mechbal::Status::ok && st == mechbal::Status::ok &&
              controller.wrench().force.norm() < 1e-9,
          "PaminsaController");
  }
#endif

  std::printf("%d failure(s)\n", failures);
  // a URDF read through urdfdom, linked through the installed CMake package
  const mechbal::MechanismModel urdf_arm = mechbal::model_from_urdf_string(
      "<robot name='arm'><link name='base'/><link name='arm'><inertial><mass value='1'/>"
      "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link>"
      "<joint name='shoulder' type='continuous'><parent link='base'/><child link='arm'/></joint>"
      "</robot>");
  std::printf("URDF: %d coordinate(s), %d body(ies)\n", urdf_arm.dof(), urdf_arm.num_bodies());
  check(urdf_arm.dof() == 1 && urdf_arm.num_bodies() == 1, "model_from_urdf_string");
  return failures == 0 ? 0 : 1;
}
