"""Shaking-force balancing by counterweights: the centre of mass stationary for every motion.

The shaking force is the rate of the linear momentum, F = dP/dt, and P is linear in every body's
mass moments: ``P(q, v) = Y_P(q, v) pi`` (the linear rows of the momentum regressor,
``mechbal/algorithm/regressor.hpp``). So with counterweights (m_k, m_k p_k) on links L_k:

    P(q, v) = P_0(q, v) + sum_k Y_P,L_k(q, v)[:, 0:4] (m_k, m_k p_k) = 0   for sampled (q, v)

(P = 0 for every motion means the total centre of mass does not move, so F = 0 whatever the
accelerations). This is solved as a linear least squares with its rank, residual and
undetermined combinations, then masses and positions under the bounds
(`mechbal.balance.common`). Closed mechanisms: (q, v) come from the loop solve of sampled
actuated states (``Mechanism.closed_motion``: v = C v#), so only the motions the loops allow are
required to be balanced.

It generalises the papers' force-balancing conditions: Briot & Arakelian 2009 (PAMINSA), eqs 6-16
(the counterweights CP1, CP2, CP3 and the vertical counter-mass make the momentum of every leg
zero: ``mechbal.papers.paminsa.closed_form_counterweights``, which checks this method in the
``paminsa`` runner), the Heydari & Enferadi extra-linkage counterweights (eqs 29-31, the ``rpsp``
runner), and the classical conditions of a four-bar (Berkof & Lowen 1969: counterweights on the
crank and rocker), which the tests reproduce.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import numpy.typing as npt

from mechbal.balance import common
from mechbal.balance.result import BalanceResult, CounterweightDesign, CounterweightSlot
from mechbal.mechanism import Mechanism


def motion_sample(mech, samples, *, seed: int = 0, lower=None, upper=None, q_guess=None):
    """(q, v, dropped): ``samples`` an int (random positions in the box of
    `common.sample_box`, velocities standard normal, for the actuated joints of a closed
    mechanism) or a tuple (q, v) of (N, dof) arrays (closed: (q#, v#), (N, na))."""
    closed = mech.is_closed
    width = len(mech.actuated_names) if closed else mech.dof
    if isinstance(samples, (int, np.integer)):
        if samples < 1:
            raise ValueError(f"samples: must be >= 1 (got {samples})")
        lo, hi = common.sample_box(mech, lower, upper, "actuated" if closed else "independent")
        rng = np.random.default_rng(seed)
        q = lo + (hi - lo) * rng.random((int(samples), width))
        v = rng.standard_normal((int(samples), width))
    else:
        try:
            q, v = (np.atleast_2d(np.asarray(x, float)) for x in samples)
        except (TypeError, ValueError):
            raise ValueError("samples: must be an int or a tuple (q, v) of arrays") from None
        if q.shape != v.shape or q.ndim != 2 or q.shape[1] != width:
            raise ValueError(f"samples: q and v must both be (N, {width}) arrays of "
                             f"{'actuated ' if closed else ''}joint positions and velocities "
                             f"(got {q.shape} and {v.shape})")
    if not closed:
        return q, v, 0
    cs = common.closed_samples(mech, q, v, q_guess=q_guess)
    return cs.q, cs.v, cs.dropped


def balance(mechanism: Mechanism, design: Sequence[CounterweightSlot] | CounterweightSlot,
            samples: int | npt.ArrayLike = 200, *, mass_budget: float | None = None, seed: int = 0,
            lower: npt.ArrayLike | None = None, upper: npt.ArrayLike | None = None,
            q_guess: npt.ArrayLike | None = None, objective: str = "mass",
            residual_target: float | None = None,
            certified: bool | None = None) -> BalanceResult[CounterweightDesign]:
    """Counterweights that make the linear momentum zero (least squares) over sampled motions:
    complete shaking-force balance where the residual is zero.

    ``design``: counterweight slots (`CounterweightSlot`); ``samples``: a number of random
    (q, v), or a tuple of arrays (`motion_sample`); ``mass_budget``: bound on the total
    counterweight mass. ``residual``: the RMS linear momentum of the balanced mechanism over the
    samples [kg m/s], recomputed from the balanced model."""
    prob = problem(mechanism, design, samples, seed=seed, lower=lower, upper=upper, q_guess=q_guess,
                   objective=objective)
    return prob.result(prob.solve(mass_budget=mass_budget, residual_target=residual_target, certified=certified))


def problem(mechanism: Mechanism, design: Sequence[CounterweightSlot] | CounterweightSlot,
            samples: int | npt.ArrayLike = 200, *, seed: int = 0, lower: npt.ArrayLike | None = None,
            upper: npt.ArrayLike | None = None, q_guess: npt.ArrayLike | None = None,
            objective: str = "mass") -> common.LinearProblem:
    """The force balance of `balance` as a `mechbal.balance.common.LinearProblem` (built once,
    solved for several budgets or residual targets: `mechbal.balance.front`; a partial force
    balance under a mass budget is ``problem(...).solve(mass_budget=B)``)."""
    mech = mechanism
    slots = common.normalise_slots(mech, design)
    q, v, dropped = motion_sample(mech, samples, seed=seed, lower=lower, upper=upper, q_guess=q_guess)
    probe, col = common.probe_mechanism(mech, slots)
    Y = probe.momentum_regressor(q, v)[:, :3, :]                         # (N, 3, 10 L)
    A = common.user_columns(Y, slots, col)                               # (N, 3, 4K)
    b = mech.momentum(q, v).linear_momentum
    if objective == "torque" and mech.is_closed:
        raise ValueError("objective: 'torque' (the peak static torque) is the static method's for a closed "
                         "mechanism (the force method samples no coupling matrices)")

    def after(balanced):
        p = balanced.momentum(q, v).linear_momentum
        metrics = {
            "samples": int(len(q)), "dropped_samples": int(dropped),
            "linear_momentum_rms_before": np.sqrt(np.mean(b ** 2, axis=0)),
            "linear_momentum_rms_after": np.sqrt(np.mean(p ** 2, axis=0)),
            "total_mass_after": balanced.total_mass,
        }
        return float(np.sqrt(np.mean(p ** 2))), metrics

    # the inertia of a closed mechanism: the trace over all its coordinates
    return common.LinearProblem(
        "force", mech, slots, A.reshape(-1, A.shape[-1]), b.reshape(-1), common.length_scale(mech),
        "the linear momentum (shaking force)", [f"linear momentum {a}" for a in "xyz"],
        common.objective_data(objective, mech, slots, probe, col, q),
        "kg m/s (RMS linear momentum over the sampled motions)", after, q=q, v=v)
