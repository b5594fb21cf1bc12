// The operational-space reactionless controller (ReactionlessTaskController, issue 21) on the
// Panda of example-robot-data, and the same controller written over Pinocchio (issue 26):
//  - reactionless_panda_{euler,rk4}: the tool frame `panda_hand_tcp` follows a circle (the linear
//    velocity rows of its twist), and the null space of the task (8 coordinates: 7 arm joints and
//    the finger, whose twin follows it by <mimic>) minimises the angular momentum about O (3 rows):
//    frame Jacobian, momentum matrix, J^+ and N = I - J^+ J, the damped least squares in the null
//    space, rate limits; the acceleration feed-forward (J'v and W(q, v, 0) = (dA/dt) v from a
//    forward pass with the rates, a = J^+ (x'' - J'v) + N w with the rates' factorisations) and the
//    predicted shaking wrench; Euler or RK4 (three more rate evaluations).
//  - reactionless_panda_{euler,rk4}_pinocchio: the same tick over Pinocchio: computeFrameJacobian
//    (LOCAL_WORLD_ALIGNED: [v; w] of the frame's origin, world axes) and computeCentroidalMap (A_G,
//    moved to O: A_O = [A_lin; A_ang + c x A_lin]), both times the mimic map G (Pinocchio models the
//    second finger as its own joint: 9 velocities); the feed-forward from one
//    computeCentroidalMomentumTimeVariation(q, v, 0) (its forwardKinematics(q, v, 0) also gives
//    getFrameClassicalAcceleration, J'v; dh_G/dt moved to O), then the very same linear algebra as
//    mechbal's controller (eigenvalues of the 3 x 3 Gram matrices for the conditioning, LLT solves).
// Setup checks that both controllers give the same rates, positions, momenta, accelerations and
// predicted shaking wrenches (1e-9) over 300 ticks. The
// Pinocchio half lives in bench_urdf_pinocchio.cpp (one translation unit of Pinocchio's templates
// fewer to compile).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "bench_registry.hpp"
#include "bench_reactionless_panda.hpp"
#include "bench_support.hpp"
#include "bench_urdf.hpp"
#include "mechbal/control/reactionless.hpp"

namespace mechbal::bench {
namespace {

using namespace panda_reactionless;

struct MechCase {
  std::unique_ptr<ReactionlessTaskController> ctrl;
  TwistSamples x;
  int k = 0;
  Status status = Status::ok;
};

Tick mechbal_case(ReactionlessIntegrator integrator) {
  auto s = std::make_shared<MechCase>();
  s->ctrl = mechbal_controller(integrator);
  for (int n = 0; n < 300; ++n) {
    const auto k = static_cast<std::size_t>(n);
    const Status st = s->ctrl->step(s->x.now[k], s->x.half[k], s->x.next[k]);
    if (st != Status::ok) fail("reactionless Panda: tick not ok", static_cast<double>(st));
    const double err = (s->ctrl->frame_twist().head<3>() - s->x.now[k].head<3>()).cwiseAbs().maxCoeff();
    if (!(err < 1e-9)) fail("reactionless Panda: the tool does not follow its twist", err);
  }
  s->k = 300;
  return [s] {
    const auto k = static_cast<std::size_t>(s->k);
    s->k = s->k + 1 == kTicks ? 0 : s->k + 1;
    s->status = s->ctrl->step(s->x.now[k], s->x.half[k], s->x.next[k]);
    benchmark::DoNotOptimize(s->status);
    benchmark::DoNotOptimize(s->ctrl->v().data());
    benchmark::ClobberMemory();
  };
}

}  // namespace
}  // namespace mechbal::bench

MECHBAL_BENCH_CASE(reactionless_panda_euler) { return mechbal::bench::mechbal_case(mechbal::ReactionlessIntegrator::euler); }
MECHBAL_BENCH_CASE(reactionless_panda_rk4) { return mechbal::bench::mechbal_case(mechbal::ReactionlessIntegrator::rk4); }
