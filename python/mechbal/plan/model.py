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
* ``dW/dq``: the one non-polynomial dependence.

With ``derivatives = "exact"`` (the default where the code generator takes the mechanism) every
partial, positions included, is the forward-mode derivative of the model's expression graph
(`mechbal.plan.exact`), evaluated at the library's solution of the loops; with
``"differences"`` (and where the generator does not apply) the accelerations and rates as
above, each one batched call of the model per actuated joint, and the positions by central
differences of the model (step `Q_STEP`).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

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
    torque: Any            # (N, na), or None where not asked
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    dq: Any = None         # the partials (N, 6, na): None where not asked
    dv: Any = None
    da: Any = None
    torque_dq: Any = None  # (N, na, na): None where not asked
    torque_dv: Any = None
    torque_da: Any = None


class ActuatedModel:
    """``mech`` seen from its actuated joints (see the module docstring); ``q_guess``: the
    assembly at the start of a closed mechanism (`mechbal.assembly`)."""

    def __init__(self, mech: Mechanism, *, q_guess=None, moment_point=(0.0, 0.0, 0.0),
                 derivatives: str = "exact"):
        if derivatives not in ("exact", "differences"):
            raise ValueError(f"derivatives must be 'exact' or 'differences', got {derivatives!r}")
        self.derivatives = derivatives
        self._graphs: dict[bool, Any] = {}
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

    @property
    def exact(self):
        """The compiled exact partials of the wrench and the torques
        (`mechbal.plan.exact.ExactPartials`), or None (differences)."""
        return self.exact_of(True)

    def exact_of(self, torque: bool):
        """The compiled exact partials of the wrench (and with ``torque`` of the torques), or None
        (differences: asked for, or the generator does not take the mechanism)."""
        if self.derivatives != "exact":
            return None
        if torque not in self._graphs:
            from mechbal.plan.exact import exact_partials

            self._graphs[torque] = exact_partials(self.mech, self.moment_point, torque=torque)
        return self._graphs[torque]

    def evaluate(self, qa, va, aa, *, torque: bool = False, partials: bool = False) -> Evaluation:
        qa, va, aa = (np.atleast_2d(np.asarray(x, float)) for x in (qa, va, aa))
        if not partials:
            W, tau, (q, v, a) = self._eval(qa, va, aa, torque)
            return Evaluation(W, tau, q, v, a)
        N, na = qa.shape
        graph = self.exact_of(torque)
        exact = graph is not None
        # every instant with its 1 + 5 na variants, consecutive (one batched call of the model;
        # a closed mechanism's loop solve warm-starts each row from the one before, all nearby):
        # 0: the motion; 1 + j: (q, 0, e_j); 1 + na + j: (q, v +- e_j, 0); 1 + 3 na + j: (q +- h e_j, v, a)
        K = 1 + (3 if exact else 5) * na
        h = Q_STEP * np.maximum(1.0, np.max(np.abs(qa), axis=0))
        E = np.eye(na)
        Q = np.repeat(qa[:, None, :], K, axis=1)
        V = np.zeros((N, K, na))
        A = np.zeros((N, K, na))
        V[:, 0], A[:, 0] = va, aa
        A[:, 1:1 + na] = E
        V[:, 1 + na:1 + 2 * na] = va[:, None, :] + E
        V[:, 1 + 2 * na:1 + 3 * na] = va[:, None, :] - E
        if not exact:
            Q[:, 1 + 3 * na:1 + 4 * na] += h * E
            Q[:, 1 + 4 * na:] -= h * E
            V[:, 1 + 3 * na:], A[:, 1 + 3 * na:] = va[:, None, :], aa[:, None, :]
        W, tau, (q, v, a) = self._eval(Q.reshape(-1, na), V.reshape(-1, na), A.reshape(-1, na), torque)
        W = W.reshape(N, K, 6)
        out = Evaluation(W[:, 0], None, q.reshape(N, K, -1)[:, 0], v.reshape(N, K, -1)[:, 0],
                         a.reshape(N, K, -1)[:, 0])
        # accelerations: W(q, 0, e_j) = A C e_j (no velocity term at v = 0)
        out.da = np.moveaxis(W[:, 1:1 + na], 1, 2)
        # rates: polarisation of the quadratic term
        out.dv = np.moveaxis(0.5 * (W[:, 1 + na:1 + 2 * na] - W[:, 1 + 2 * na:1 + 3 * na]), 1, 2)
        if exact:   # positions: forward mode on the model's graph at the library's q
            d = self._exact_dq(graph, out.q, va, aa)
            out.dq = d["dq"]
        else:       # positions: central differences of the model
            out.dq = np.moveaxis((W[:, 1 + 3 * na:1 + 4 * na] - W[:, 1 + 4 * na:]) / (2.0 * h[:, None]), 1, 2)
        if torque:
            T = tau.reshape(N, K, na)
            out.torque = T[:, 0]
            gravity = self._eval(qa, np.zeros_like(va), np.zeros_like(aa), True)[1]
            out.torque_da = np.moveaxis(T[:, 1:1 + na] - gravity[:, None, :], 1, 2)
            out.torque_dv = np.moveaxis(0.5 * (T[:, 1 + na:1 + 2 * na] - T[:, 1 + 2 * na:1 + 3 * na]), 1, 2)
            if exact:
                out.torque_dq = d["torque_dq"]
            else:
                out.torque_dq = np.moveaxis((T[:, 1 + 3 * na:1 + 4 * na] - T[:, 1 + 4 * na:]) / (2.0 * h[:, None]), 1, 2)
        return out

    #: rows per call of the compiled partials (bounds the memory of its intermediate arrays)
    EXACT_CHUNK = 256

    def _exact_dq(self, graph, q, va, aa) -> dict[str, np.ndarray]:
        parts: dict[str, list] = {}
        q = np.asarray(q)
        for s in range(0, len(q), self.EXACT_CHUNK):
            sl = slice(s, s + self.EXACT_CHUNK)
            for k, x in graph(q[sl], va[sl], aa[sl]).items():
                parts.setdefault(k, []).append(x)
        return {k: np.concatenate(x) for k, x in parts.items()}
