#pragma once
/// \file algorithm/center_of_mass.hpp
/// Centre of mass of all bodies (the base's included) in O: data.center_of_mass, data.mass.
#include <Eigen/Core>

#include "mechbal/model/data.hpp"
#include "mechbal/model/model.hpp"
#include "mechbal/status.hpp"

namespace mechbal {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

Status center_of_mass(const MechanismModel& model, MechanismData& data, const ConstVector& q) noexcept;

}  // namespace mechbal
