#pragma once
// Every algorithm of the general model called on one state, for the tests of the real-time
// contract on any model (random trees in test_mechanism.cpp, a URDF in test_urdf.cpp).
#include <gtest/gtest.h>

#include <cstddef>

#include "alloc_counter.hpp"
#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/algorithm/inverse_dynamics.hpp"
#include "mechbal/algorithm/jacobian.hpp"
#include "mechbal/algorithm/kinematics.hpp"
#include "mechbal/algorithm/mass_matrix.hpp"
#include "mechbal/algorithm/momentum.hpp"
#include "mechbal/algorithm/regressor.hpp"
#include "mechbal/algorithm/shaking_wrench.hpp"

namespace mechbal::test {

/// Sizes the quadratic results by their first call (data.hpp: the mass matrix, the torque and
/// gravity regressors), as a real-time user does at set-up, then calls every algorithm three times
/// at (q, v, a) (the Jacobian and the placement of `frame`), expecting Status::ok from each.
/// Returns the number of heap allocations of those calls (0 is the contract).
inline std::size_t allocations_of_every_algorithm(const MechanismModel& model, MechanismData& data,
                                                  const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                                  const Eigen::VectorXd& a, int frame) {
  data.reserve_mass_matrix();
  torque_regressor(model, data, q, v, a);
  gravity_regressor(model, data, q);
  AllocationScope scope;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(forward_kinematics(model, data, q, v, a), Status::ok);
    EXPECT_EQ(center_of_mass(model, data, q), Status::ok);
    EXPECT_EQ(momentum(model, data, q, v), Status::ok);
    EXPECT_EQ(momentum_matrix(model, data, q), Status::ok);
    EXPECT_EQ(shaking_wrench(model, data, q, v, a), Status::ok);
    EXPECT_EQ(base_reaction(model, data, q, v, a), Status::ok);
    EXPECT_EQ(inverse_dynamics(model, data, q, v, a), Status::ok);
    EXPECT_EQ(gravity_torque(model, data, q), Status::ok);
    EXPECT_EQ(bias_torque(model, data, q, v), Status::ok);
    EXPECT_EQ(mass_matrix(model, data, q), Status::ok);
    EXPECT_EQ(frame_jacobian(model, data, q, frame), Status::ok);
    EXPECT_EQ(frame_placement(model, data, q, frame), Status::ok);
    EXPECT_EQ(torque_regressor(model, data, q, v, a), Status::ok);
    EXPECT_EQ(gravity_regressor(model, data, q), Status::ok);
    EXPECT_EQ(momentum_regressor(model, data, q, v), Status::ok);
  }
  return scope.count();
}

}  // namespace mechbal::test
