"""A user's script, checked by `mypy --strict` in the tests (tests/python/test_typing.py): it
touches Mechanism, every balancing method, control, simulate, trajectory and sweep the way the
docs show them, and must type-check without an error or an ignore. It also runs (the test runs
it once, on a short motion, so that what it claims is true)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt

import mechbal
from mechbal import control, simulate, trajectory
from mechbal.papers.discs import FiveBarDynamics, FiveBarMotion, FiveBarParameters, FiveBarTerms
from mechbal.balance import (
    BalanceResult, CounterweightDesign, CounterweightSlot, DiscDesign, DiscSlot, InertiaDesign,
    SpringDesign, SpringSlot, force, method, moment, rms, springs, static)
from mechbal.sweep import Parameter, Sweep

CASE = Path(mechbal.__file__).parent / "cases" / "arm2link.toml"


def peak(x: npt.ArrayLike) -> float:
    return float(np.max(np.abs(np.asarray(x, dtype=float))))


def main() -> None:
    # ---- Mechanism ---------------------------------------------------------------------------
    arm = mechbal.Mechanism.from_toml(CASE)
    motion: trajectory.Motion = trajectory.quintic([0.0, 0.0], [1.2, -0.9], 1.0).evaluate(
        np.linspace(0.0, 1.0, 51))
    q, v, a = motion
    tau: npt.NDArray[np.float64] = arm.inverse_dynamics(q, v, a)
    wrench: mechbal.ShakingWrench = arm.shaking_wrench(motion.q, motion.v, motion.a)
    energy = arm.potential_energy(q)
    # single samples give plain results, batches carry their per-instant status (issue 38)
    rest = np.zeros(arm.dof)
    poses = np.zeros((4, arm.dof))
    e0: float = arm.potential_energy(rest)
    e1: float = arm.potential_energy([0.3, -0.2])
    energies: mechbal.BatchArray = arm.potential_energy(poses)
    flags: npt.NDArray[np.uint32] = energies.status
    good: npt.NDArray[np.bool_] = energies.ok
    torques = arm.inverse_dynamics(poses, poses, poses)
    gravity: npt.NDArray[np.float64] = arm.gravity_torque(rest)
    print("energy", e0, e1, energies.shape, int(flags.sum()), bool(good.all()), torques.status.shape,
          torques.ok.all(), gravity.shape)
    M = arm.mass_matrix(q[0])
    print("peak torque", peak(tau), "peak shaking force", peak(wrench.shaking_force),
          "energy span", peak(energy), "M", M.shape)

    # ---- every balancing method --------------------------------------------------------------
    cws = [CounterweightSlot("cw1", "shoulder", max_radius=0.5),
           CounterweightSlot("cw2", "elbow", max_radius=0.5)]
    by_static: BalanceResult[CounterweightDesign] = static.balance(arm, cws, samples=50)
    by_force = force.balance(arm, cws, samples=50)
    by_rms = rms.balance(arm, cws, (q, v, a), starts=1)
    masses: list[float] = [d.mass for d in by_static.design.values()]
    print("static", masses, "force", by_force.residual, "rms", by_rms.design["cw1"].position)
    balanced: mechbal.Mechanism = by_static.balanced
    print("gravity torque left", peak(balanced.gravity_torque(q)))

    spring = SpringSlot("s1", "shoulder", (0.0, 0.0, 0.0), "elbow", (0.1, 0.0, 0.0))
    by_springs = springs.balance(arm, [spring], q)
    sized: SpringDesign = by_springs.design["s1"]
    print("spring rate", sized.rate)

    disc = DiscSlot("d1", carrier="shoulder", joint="elbow", axis=(0.0, -1.0, 0.0))
    by_moment = moment.balance(arm, [disc], q)
    for name, chosen in by_moment.design.items():
        if isinstance(chosen, DiscDesign):
            print(name, "disc inertia", chosen.inertia, "ratio", chosen.ratio)
        elif isinstance(chosen, InertiaDesign):
            print(name, chosen.components)
    any_method = method("static").balance(arm, cws, 20)
    print("by name:", any_method.method, any_method.exact)

    # ---- control and simulate ----------------------------------------------------------------
    ct = control.ComputedTorque(arm, kp=[100.0, 100.0], kd=[20.0, 20.0])
    cmd: control.JointCommand = ct.step(q[0], v[0], q[1], v[1], a[1])
    out = np.zeros(arm.dof)
    status: int = ct.step_into(q[0], v[0], q[1], v[1], a[1], out)
    batch: control.ControlRun = ct.run(q, v, q, v, a)
    dyn = control.MechanismDynamics(arm.model)
    inv: control.InverseDynamicsResult = dyn.inverse_dynamics(q, v, a)
    acc = dyn.forward_dynamics(q[0], v[0], cmd.joint_torque)
    print("tick", cmd.status, status, batch.status.shape, peak(inv.joint_torque), acc.shape)

    ct.reset()
    run: simulate.ClosedLoopResult = simulate.closed_loop(
        arm, ct, trajectory.quintic([0.0, 0.0], [0.3, -0.2], 0.2), v0=[0.0, 0.0], dt=1e-3)
    print("tracking", peak(run.tracking_error), run.ok, run.v.shape)

    # ---- a paper's closed form: the parallelogram five-bar ------------------------------------
    five_bar = FiveBarDynamics(FiveBarParameters(
        a1=0.3, a2=0.25, b1=0.25, b2=0.3, mp1=1.0, mp2=1.0, md1=0.8, md2=0.8, mP=0.5, cp1=0.1,
        cp2=0.1, cd1=0.1, cd2=0.1, Jp1=0.01, Jp2=0.01, Jd1=0.01, Jd2=0.01))
    q5 = np.array([[0.6, 1.9], [0.7, 2.0]])
    tau5: npt.NDArray[np.float64] = five_bar.inverse_dynamics(q5, q5 * 0.0, q5 * 0.0)
    terms: FiveBarTerms = five_bar.evaluate(q5, q5 * 0.0)
    legs: FiveBarMotion = five_bar.motion(q5[0], q5[0] * 0.0, q5[0] * 0.0)
    print("five-bar", peak(tau5 - terms.gravity_torque), terms.ok.all(), legs.end_effector)

    # ---- trajectory --------------------------------------------------------------------------
    via = trajectory.ViaPoints([0.0, 0.5, 1.0], [[0.0, 0.0], [0.6, -0.2], [1.2, -0.9]])
    sampled = trajectory.Sampled(np.linspace(0.0, 1.0, 11), np.linspace(0.0, 1.0, 11)[:, None])
    one: trajectory.Motion = via.evaluate(0.25)
    print("via", one.v, "sampled", sampled.evaluate([0.5, 0.6]).a.shape)

    # ---- sweep -------------------------------------------------------------------------------
    sweep = Sweep(str(CASE), [Parameter("bodies.shoulder.mass", tolerance=0.05)],
                  ["gravity_torque_peak"], kind="sensitivity", pose_count=10)
    result = sweep.run("serial", progress=False)
    print("sweep rows", len(result.table))


if __name__ == "__main__":
    main()
