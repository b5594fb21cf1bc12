// The tests' reference sum over a set of bodies (test::body_set_wrench: Briot & Arakelian 2009,
// eqs 1-4), the independent check of the general algorithm/shaking_wrench and of PAMINSA's closed
// forms, against central finite differences of its momenta on random, analytically known
// multi-body motions; and the validation of a rigid body's mass properties.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "mechbal/model/rigid_body.hpp"
#include "test_support.hpp"

using namespace mechbal;

namespace {

Mat3 rot(const Vec3& axis, double angle) { return Eigen::AngleAxisd(angle, axis).toRotationMatrix(); }

// A smooth motion: com(t) = c0 + c1 sin(f t) + c2 t^2, R(t) = Rot(u1, th1(t)) Rot(u2, th2(t)) R0,
// th_k(t) = A_k sin(g_k t + p_k). Closed-form derivatives; independent of any mechbal kinematics.
struct Motion {
  Vec3 c0, c1, c2, u1, u2;
  Mat3 R0;
  double f, A1, g1, p1, A2, g2, p2;
  BodyState at(double t) const {
    BodyState s;
    s.com = c0 + c1 * std::sin(f * t) + c2 * t * t;
    s.com_velocity = c1 * f * std::cos(f * t) + 2.0 * c2 * t;
    s.com_acceleration = -c1 * f * f * std::sin(f * t) + 2.0 * c2;
    const double th1 = A1 * std::sin(g1 * t + p1), th1d = A1 * g1 * std::cos(g1 * t + p1),
                 th1dd = -A1 * g1 * g1 * std::sin(g1 * t + p1);
    const double th2 = A2 * std::sin(g2 * t + p2), th2d = A2 * g2 * std::cos(g2 * t + p2),
                 th2dd = -A2 * g2 * g2 * std::sin(g2 * t + p2);
    const Mat3 R1 = rot(u1, th1);
    s.rotation = R1 * rot(u2, th2) * R0;
    const Vec3 w1 = u1 * th1d;
    const Vec3 u2w = R1 * u2;
    s.angular_velocity = w1 + u2w * th2d;
    s.angular_acceleration = u1 * th1dd + w1.cross(u2w) * th2d + u2w * th2dd;
    return s;
  }
};

Motion random_motion(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Motion m;
  m.c0 = Vec3(u(rng), u(rng), u(rng));
  m.c1 = Vec3(u(rng), u(rng), u(rng)) * 0.3;
  m.c2 = Vec3(u(rng), u(rng), u(rng)) * 0.5;
  m.u1 = Vec3(u(rng), u(rng), u(rng)).normalized();
  m.u2 = Vec3(u(rng), u(rng), u(rng)).normalized();
  m.R0 = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
  m.f = 2.0 + u(rng);
  m.A1 = 1.0 + u(rng) * 0.5;
  m.g1 = 3.0 + u(rng);
  m.p1 = u(rng);
  m.A2 = 0.8 + u(rng) * 0.5;
  m.g2 = 5.0 + u(rng);
  m.p2 = u(rng);
  return m;
}

}  // namespace

TEST(BodySetWrench, MatchesFiniteDifferencesOfMomentum) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const int count = 1 + trial % 7;
    std::vector<RigidBody> bodies;
    std::vector<Motion> motions;
    for (int j = 0; j < count; ++j) {
      bodies.push_back(test::random_body(rng));
      motions.push_back(random_motion(rng));
    }
    auto wrench_at = [&](double t) {
      std::vector<BodyState> s;
      for (const auto& m : motions) s.push_back(m.at(t));
      return test::body_set_wrench(bodies.data(), s.data(), s.size());
    };
    const double t = 0.37 * trial, h = 1e-5;
    const ShakingWrench w = wrench_at(t), wp = wrench_at(t + h), wm = wrench_at(t - h);
    const Vec3 dP = (wp.linear_momentum - wm.linear_momentum) / (2 * h);
    const Vec3 dH = (wp.angular_momentum - wm.angular_momentum) / (2 * h);
    const double scale_f = std::max(1.0, w.force.norm());
    const double scale_m = std::max(1.0, w.moment.norm());
    EXPECT_LT((dP - w.force).norm() / scale_f, 1e-8) << "trial " << trial;
    EXPECT_LT((dH - w.moment).norm() / scale_m, 1e-8) << "trial " << trial;
  }
}

TEST(RigidBodyValidation, ErrorsNameTheField) {
  RigidBody b;
  b.mass = -1.0;
  b.inertia_body = Mat3::Identity();
  try {
    validate_rigid_body(b, "bodies[2]");
    FAIL() << "negative mass accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bodies[2].mass"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("-1"), std::string::npos) << e.what();
  }
  b.mass = 1.0;
  b.inertia_body(0, 1) = 0.5;  // not symmetric
  EXPECT_THROW(validate_rigid_body(b, "x"), std::invalid_argument);
  b.inertia_body = Vec3(1.0, 1.0, 3.0).asDiagonal();  // violates triangle inequality
  EXPECT_THROW(validate_rigid_body(b, "x"), std::invalid_argument);
  b.inertia_body = Vec3(1.0, 1.0, 1.5).asDiagonal();
  EXPECT_NO_THROW(validate_rigid_body(b, "x"));
}
