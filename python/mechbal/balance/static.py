"""Static balancing by counterweights: gravity torque zero over a workspace sample.

The gravity torque is linear in every body's mass moments, ``G(q) = Y_g(q) pi`` (the gravity
regressor, ``mechbal/algorithm/regressor.hpp``), so with counterweights of masses m_k at p_k on
links L_k:

    G(q) = G_0(q) + sum_k Y_g,L_k(q)[:, 0:4] (m_k, m_k p_k) = 0   for every sampled q

is a linear least-squares problem in the mass moments (m_k, m_k p_k), solved exactly (rank,
residual, minimum-norm solution, undetermined combinations), then the masses and positions are
chosen under the slots' bounds and the mass budget (`mechbal.balance.common`). For a closed
mechanism the condition is on the actuated joints, C(q)^T G(q) = 0, with C the coupling matrix of
the loop solve (v = C v#).

This generalises the static-balancing conditions of the papers' counterweights, e.g.
Arakelian, Le Baron & Mottu 2011, eqs 21-22 / 30-31 (m_CW2 r_CW2 = m2 l_S2 and
m_CW1 r_CW1 = m1 l_S1 + (m2 + m_CW2) l1 for the 2-DOF arm), which the tests reproduce.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import numpy.typing as npt

from mechbal.balance import common
from mechbal.balance.result import BalanceResult, CounterweightDesign, CounterweightSlot
from mechbal.mechanism import Mechanism


def workspace_sample(mech, samples, *, seed: int = 0, lower=None, upper=None, q_guess=None):
    """(q, C) of the sample: ``samples`` an int (that many uniform random configurations in the
    box `common.sample_box`: joint limits, else +-pi / +-0.5 m) or an (N, dof) array of
    configurations (of the actuated joints, (N, na), for a closed mechanism). C is None for an
    open mechanism, the coupling matrices (N, dof, na) for a closed one (unassemblable samples
    are dropped). Returns (q, C, q_actuated, dropped)."""
    closed = mech.is_closed
    if isinstance(samples, (int, np.integer)):
        if samples < 1:
            raise ValueError(f"samples: must be >= 1 (got {samples})")
        lo, hi = common.sample_box(mech, lower, upper, "actuated" if closed else "independent")
        rng = np.random.default_rng(seed)
        q = lo + (hi - lo) * rng.random((int(samples), len(lo)))
    else:
        q = np.atleast_2d(np.asarray(samples, float))
        width = len(mech.actuated_names) if closed else mech.dof
        if q.ndim != 2 or q.shape[1] != width:
            raise ValueError(f"samples: must be an int or an (N, {width}) array of "
                             f"{'actuated ' if closed else ''}joint positions (got shape {q.shape})")
    if not closed:
        return q, None, q, 0
    cs = common.closed_samples(mech, q, q_guess=q_guess)
    return cs.q, cs.C, cs.q_actuated, cs.dropped


def gravity_rows(mech, q, C=None) -> np.ndarray:
    """Gravity torques (N, dof), or C^T G (N, na) of a closed mechanism."""
    G = mech.gravity_torque(q)
    return G if C is None else np.einsum("nij,ni->nj", C, G)


def balance(mechanism: Mechanism, design: Sequence[CounterweightSlot] | CounterweightSlot,
            samples: int | npt.ArrayLike = 1000, *, mass_budget: float | None = None, seed: int = 0,
            lower: npt.ArrayLike | None = None, upper: npt.ArrayLike | None = None,
            q_guess: npt.ArrayLike | None = None, objective: str = "mass",
            residual_target: float | None = None,
            certified: bool | None = None) -> BalanceResult[CounterweightDesign]:
    """Counterweights that make the gravity torque zero (least squares) over a workspace sample.

    ``design``: the counterweight slots (`CounterweightSlot`: link, mass range, distance
    ``max_radius`` from ``center``, optional line ``direction``; positions in the frame the user
    described the link in). ``samples``: a number of random configurations or an array of them
    (`workspace_sample`; ``lower``/``upper`` bound the random box, ``q_guess`` picks the
    assembly mode of a closed mechanism). ``mass_budget``: bound on the total counterweight mass.

    Among the least-squares solutions that meet the bounds, the lightest is returned; when no
    least-squares solution meets them, the constrained least squares, with the active bounds in
    ``limited_by``. ``residual`` is the RMS gravity torque of the balanced mechanism over the
    sample [N m], recomputed from the balanced model."""
    prob = problem(mechanism, design, samples, seed=seed, lower=lower, upper=upper, q_guess=q_guess,
                   objective=objective)
    return prob.result(prob.solve(mass_budget=mass_budget, residual_target=residual_target, certified=certified))


def problem(mechanism: Mechanism, design: Sequence[CounterweightSlot] | CounterweightSlot,
            samples: int | npt.ArrayLike = 1000, *, seed: int = 0, lower: npt.ArrayLike | None = None,
            upper: npt.ArrayLike | None = None, q_guess: npt.ArrayLike | None = None,
            objective: str = "mass") -> common.LinearProblem:
    """The static balance of `balance` as a `mechbal.balance.common.LinearProblem` (built once,
    solved for several budgets or residual targets: `mechbal.balance.front`)."""
    mech = mechanism
    slots = common.normalise_slots(mech, design)
    q, C, qa, dropped = workspace_sample(mech, samples, seed=seed, lower=lower, upper=upper, q_guess=q_guess)
    probe, col = common.probe_mechanism(mech, slots)
    Y = probe.gravity_regressor(q)                                      # (N, dof, 10 L)
    A = common.user_columns(Y, slots, col)                              # (N, dof, 4K)
    b = gravity_rows(mech, q)
    if C is not None:
        A = np.einsum("nij,nik->njk", C, A)
        b = np.einsum("nij,ni->nj", C, b)

    def after(balanced):
        g = gravity_rows(balanced, q, C)
        metrics = {
            "samples": int(len(q)), "dropped_samples": int(dropped),
            "gravity_torque_rms_before": np.sqrt(np.mean(b ** 2, axis=0)),
            "gravity_torque_rms_after": np.sqrt(np.mean(g ** 2, axis=0)),
            "gravity_torque_peak_before": np.max(np.abs(b), axis=0),
            "gravity_torque_peak_after": np.max(np.abs(g), axis=0),
        }
        return float(np.sqrt(np.mean(g ** 2))), metrics

    return common.LinearProblem(
        "static", mech, slots, A.reshape(-1, A.shape[-1]), b.reshape(-1), common.length_scale(mech),
        "the gravity torque", [f"gravity torque of joint '{n}'" for n in
                               (mech.joint_names if C is None else mech.actuated_names)],
        common.objective_data(objective, mech, slots, probe, col, q, C),
        "N m (RMS gravity torque over the sample)", after, q=q, C=C)
