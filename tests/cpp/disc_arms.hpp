#pragma once
// Serial arms with counter-rotating discs on the general model (test and bench support): each disc
// a massless link on a revolute joint geared to a coordinate (a gear coupling, URDF mimic), as
// mechbal.papers.discs builds them from the case files (Coutinho & Hess Coelho).
#include <string>
#include <vector>

#include "mechbal/model/model.hpp"
#include "mechbal/model/serial_chain.hpp"

namespace mechbal::test {

/// A disc on link `carrier` (0-based joint index), spinning about the carrier's x axis through its
/// origin at ratio * q[joint] relative to the carrier; central inertia diag(J, J/2, J/2) (a thin
/// disc; its mass is lumped into the carrier).
struct Disc {
  int carrier = 0;
  int joint = 0;
  double ratio = 1.0;
  double J = 0.0;
};

inline MechanismModel disc_arm(const ChainModel& chain, const std::vector<Disc>& discs) {
  MechanismDescription d = chain_description(chain);
  const std::size_t links = d.joints.size();
  for (std::size_t i = 0; i < discs.size(); ++i) {
    const Disc& s = discs[i];
    Joint j;
    j.name = "disc" + std::to_string(i + 1);
    j.parent = d.joints[static_cast<std::size_t>(s.carrier) % links].name;
    j.axis = Vec3::UnitX();
    j.mimic_joint = d.joints[static_cast<std::size_t>(s.joint) % links].name;
    j.mimic_ratio = s.ratio;
    d.joints.push_back(j);
    d.bodies.push_back(Body{j.name, "disc", j.name, 0.0, Vec3::Zero(), Vec3(s.J, s.J / 2, s.J / 2).asDiagonal()});
  }
  return MechanismModel(d);
}

/// Planar 3R of the discs-3r case: vertical y-z plane, axes x, link frames y along the link.
struct Planar3R {
  double l1 = 0.4, l2 = 0.3, m1 = 6.0, m2 = 3.0, m3 = 1.0;
  double J1 = 0.25, J2 = 0.06, J3 = 0.005, J4 = 0.002, J5 = 0.024, J6 = 0.001, J7 = 0.004;

  /// X of eqs 13-14 (the inertia disc 5 must cancel at joint 2).
  double X() const { return J2 + J3 + J4 + J6 + J7 + m3 * l2 * l2 + m3 * m3 * l2 * l2 / m2; }
};

inline JointSpec planar_link(const char* name, double offset, double m, double lg, double Jx) {
  JointSpec j;
  j.name = name;
  j.origin = Eigen::Isometry3d(Eigen::Translation3d(0.0, offset, 0.0));
  j.axis = Vec3::UnitX();
  j.link.mass = m;
  j.link.inertia_body = Vec3(Jx, 0.6 * Jx, 0.6 * Jx).asDiagonal();  // thin plate, physical
  j.com = Vec3(0.0, lg, 0.0);
  return j;
}

/// The balanced planar 3R, eqs 8 and 14 written here from the paper (independently of Python):
/// link centres of mass for static balance, disc gear ratios beta (x beta_scale) and gamma for
/// dynamic balance.
inline MechanismModel balanced_planar_3r(const Planar3R& p = {}, double beta_scale = 1.0) {
  const double lg1 = -p.l1 * (p.m2 + p.m3) / p.m1, lg2 = -p.l2 * p.m3 / p.m2;
  const double beta = -p.X() / p.J5 * beta_scale, gamma = -(p.J3 + p.J6) / p.J7;
  const ChainModel chain({planar_link("j1", 0.0, p.m1, lg1, p.J1), planar_link("j2", p.l1, p.m2, lg2, p.J2),
                          planar_link("j3", p.l2, p.m3, 0.0, p.J3)});
  return disc_arm(chain, {{0, 1, 1.0, p.J4}, {0, 1, beta, p.J5}, {1, 2, 1.0, p.J6}, {1, 2, gamma, p.J7}});
}

/// Eq 16: the constant diagonal of the balanced planar 3R's mass matrix.
inline Eigen::Vector3d planar_3r_k(const Planar3R& p = {}) {
  const double X = p.X();
  const double k1 = p.J1 + p.J2 + p.J3 + p.J4 + p.J5 + p.J6 + p.J7 + p.m2 * p.l1 * p.l1 +
                    p.m3 * (p.l1 * p.l1 + p.l2 * p.l2) + p.l1 * p.l1 * (p.m2 + p.m3) * (p.m2 + p.m3) / p.m1 +
                    p.l2 * p.l2 * p.m3 * p.m3 / p.m2;
  return {k1, X * (X + p.J5) / p.J5, (p.J3 + p.J6) * (p.J3 + p.J6 + p.J7) / p.J7};
}

}  // namespace mechbal::test
