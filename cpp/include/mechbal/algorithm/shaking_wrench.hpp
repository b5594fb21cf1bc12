#pragma once
/// \file algorithm/shaking_wrench.hpp
/// The shaking wrench of a mechanism: the rates of its momenta about O (Briot & Arakelian 2009,
/// eqs 1-4), F = dP/dt and M_O = dH_O/dt, which the mechanism exerts on its base (with the sign
/// convention of rigid_body.hpp), and the full base reaction with gravity.
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// data.shaking: momenta and their rates (force, moment about O) for the motion (q, v, a).
Status shaking_wrench(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                      const ConstVector& v, const ConstVector& a) noexcept;
/// data.base_reaction: the wrench the base exerts on the mechanism, gravity included:
/// force = dP/dt - m g, moment about O = dH_O/dt - (m c) x g. Also fills data.shaking,
/// data.center_of_mass.
Status base_reaction(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                     const ConstVector& v, const ConstVector& a) noexcept;

}  // namespace mechbal
