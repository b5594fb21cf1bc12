#pragma once
/// \file rnea.hpp
/// RneChainDynamics: a serial ChainModel's dynamics by recursive Newton-Euler and the composite
/// rigid body algorithm. Since the general model landed this is MechanismDynamics over the chain's
/// MechanismDescription (chain_description): one implementation of the algorithms
/// (detail/tree.hpp), kept under this name for the chain API and the benchmarks.
#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/model/serial_chain.hpp"

namespace mechbal {

class RneChainDynamics final : public MechanismDynamics {
 public:
  explicit RneChainDynamics(const ChainModel& chain) : MechanismDynamics(MechanismModel(chain_description(chain))) {}
};

}  // namespace mechbal
