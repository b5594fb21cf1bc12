#pragma once
/// \file algorithm/shaking_wrench.hpp
/// The shaking wrench of a mechanism: the rates of its momenta about O (Briot & Arakelian 2009,
/// eqs 1-4), F = dP/dt and M_O = dH_O/dt (the mechanism pushes on its base with -F, -M_O), and
/// the base reaction with gravity. The only shaking wrench of the general layer; a paper's closed
/// form is a fast path tested against it.
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

/// data.shaking: momenta and their rates (force, moment about O) for the motion (q, v, a).
Status shaking_wrench(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                      const ConstVector& v, const ConstVector& a) noexcept;
/// data.base_reaction: the wrench the base exerts on the moving mechanism, gravity included:
/// force = dP/dt - m g, moment about O = dH_O/dt - (m c) x g, where m and m c sum the bodies that
/// move: the bodies on the root link and on links joined to it by fixed joints only (a URDF's
/// `base_link` of 4 kg) are the base's own, their weight carried by the base, not by the
/// mechanism's joints. data.support_reaction: the same with every body of the model (the wrench
/// the ground exerts on the base with what it carries, the base's own bodies being the only
/// ones fixed). Also fills data.shaking, data.mass and data.center_of_mass (all bodies).
Status base_reaction(const MechanismModel& model, MechanismData& data, const ConstVector& q,
                     const ConstVector& v, const ConstVector& a) noexcept;

}  // namespace mechbal
