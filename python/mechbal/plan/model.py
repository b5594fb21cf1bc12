"""The shaking wrench and the actuator torques of a motion of the actuated joints, with their
partial derivatives, for any mechanism (open: the actuated joints are the coordinates; closed:
the loops are solved, ``v = C v#``, ``a = C a# + c``).

The shaking wrench ``W = dh/dt`` (momentum rate about O; the moment taken about a chosen point p:
``M_p = M_O - p x F``) and the torques are linear in the accelerations and quadratic in the rates
(Briot & Arakelian 2009, eqs 1-4; ``W = A(q) a + Adot(q, v) v``). So:

* ``dW/da = A C``: the model's momentum matrix (times the coupling matrix of a closed mechanism),
  read exactly as ``W(q, 0, e_j)``; ``dtau/da`` likewise;
* ``dW/dv``: exact by polarisation of the quadratic term, ``(W(q, v + e_j, 0) - W(q, v - e_j,
  0)) / 2`` (a central difference of a quadratic is its derivative, for any step);
* ``dW/dq``: the one non-polynomial dependence, by central differences of the model
  (step `Q_STEP`); the model has no position derivatives of the momentum matrix (yet).

Each is one batched call of the model per actuated joint.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechbal import control
from mechbal.mechanism import Mechanism

#: central-difference step of the position derivatives [rad or m]
Q_STEP = 1e-6


class LoopFailure(ValueError):
    """The loops of a closed mechanism cannot be assembled somewhere along a motion."""


@dataclass
class Evaluation:
    """Wrench (N, 6) [F; M_p], torques (N, na) and, when asked, their partials (N, 6 | na, na)
    with respect to the actuated positions, rates and accelerations; full ``q, v, a`` (N, dof)."""

    wrench: np.ndarray
    torque: np.ndarray | None
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    dq: np.ndarray | None = None
    dv: np.ndarray | None = None
    da: np.ndarray | None = None
    torque_dq: np.ndarray | None = None
    torque_dv: np.ndarray | None = None
    torque_da: np.ndarray | None = None


class ActuatedModel:
    """``mech`` seen from its actuated joints (see the module docstring); ``q_guess``: the
    assembly at the start of a closed mechanism (`mechbal.assembly`)."""

    def __init__(self, mech: Mechanism, *, q_guess=None, moment_point=(0.0, 0.0, 0.0)):
        self.mech = mech
        self.closed = bool(mech.is_closed)
        self.na = len(mech.actuated_names)
        self.q_guess = None if q_guess is None else np.asarray(q_guess, float)
        self.moment_point = np.asarray(moment_point, float).reshape(3)
        self.actuated = list(mech.model.actuated_coordinates) if self.closed else list(range(mech.dof))

    def full(self, qa, va, aa, torque: bool = False):
        """Full (q, v, a, tau or None) of the actuated motion; LoopFailure where the loops fail."""
        if not self.closed:
            tau = self.mech.inverse_dynamics(qa, va, aa) if torque else None
            return qa, va, aa, None if tau is None else np.asarray(tau)
        m = self.mech.closed_motion(qa, va, aa, q_guess=self.q_guess, with_forces=torque)
        bad = (np.atleast_1d(m.status) & ~np.uint32(int(control.Status.singular))) != 0
        if np.any(bad):
            k = int(np.argmax(bad))
            raise LoopFailure(f"the loops cannot be assembled at sample {k} (actuated positions "
                              f"{np.round(np.atleast_2d(qa)[k], 6).tolist()})")
        return m.q, m.v, m.a, m.actuated_force

    def wrench_of(self, q, v, a) -> np.ndarray:
        sw = self.mech.shaking_wrench(q, v, a)
        F, M = np.asarray(sw.shaking_force), np.asarray(sw.shaking_moment)
        return np.concatenate([F, M - np.cross(self.moment_point, F)], axis=-1)

    def _eval(self, qa, va, aa, torque):
        q, v, a, tau = self.full(qa, va, aa, torque)
        return self.wrench_of(q, v, a), tau, (q, v, a)

    def evaluate(self, qa, va, aa, *, torque: bool = False, partials: bool = False) -> Evaluation:
        qa, va, aa = (np.atleast_2d(np.asarray(x, float)) for x in (qa, va, aa))
        W, tau, (q, v, a) = self._eval(qa, va, aa, torque)
        out = Evaluation(W, tau, q, v, a)
        if not partials:
            return out
        N, na = qa.shape
        zeros = np.zeros_like(va)
        dq = np.empty((N, 6, na)); dv = np.empty((N, 6, na)); da = np.empty((N, 6, na))
        tq = tv = ta = None
        if torque:
            tq = np.empty((N, na, na)); tv = np.empty((N, na, na)); ta = np.empty((N, na, na))
            _, tau0, _ = self._eval(qa, zeros, zeros, True)
        for j in range(na):
            e = np.zeros(na)
            e[j] = 1.0
            # accelerations: W(q, 0, e_j) = A C e_j (no velocity term at v = 0)
            Wa, ta_j, _ = self._eval(qa, zeros, zeros + e, torque)
            da[:, :, j] = Wa
            # rates: polarisation of the quadratic term
            Wp, tp, _ = self._eval(qa, va + e, zeros, torque)
            Wm, tm, _ = self._eval(qa, va - e, zeros, torque)
            dv[:, :, j] = 0.5 * (Wp - Wm)
            # positions: central differences of the model
            h = Q_STEP * max(1.0, float(np.max(np.abs(qa[:, j]))))
            Wqp, tqp, _ = self._eval(qa + h * e, va, aa, torque)
            Wqm, tqm, _ = self._eval(qa - h * e, va, aa, torque)
            dq[:, :, j] = (Wqp - Wqm) / (2.0 * h)
            if torque:
                ta[:, :, j] = ta_j - tau0
                tv[:, :, j] = 0.5 * (tp - tm)
                tq[:, :, j] = (tqp - tqm) / (2.0 * h)
        out.dq, out.dv, out.da = dq, dv, da
        out.torque_dq, out.torque_dv, out.torque_da = tq, tv, ta
        return out
