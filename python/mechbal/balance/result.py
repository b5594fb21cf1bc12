"""Design variables and results shared by every balancing method."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class CounterweightSlot:
    """A counterweight that a method may add: a point-like body of ``mass`` [kg] at ``position``
    [m] in the frame of the link of joint ``link`` (the frame the user described the link in: the
    URDF link frame, the DH frame of a DH joint). The method chooses what is not fixed:
    ``mass`` within [mass_min, mass_max], ``position`` within ``max_radius`` of ``center``
    (default the link origin), optionally restricted to the line ``direction`` through ``center``.
    ``inertia`` (3, 3) about its centre of mass, link axes (default: a point mass)."""

    name: str
    link: str
    mass_min: float = 0.0
    mass_max: float = math.inf
    max_radius: float = math.inf
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)
    direction: tuple[float, float, float] | None = None
    inertia: Any = None


@dataclass(frozen=True)
class SpringSlot:
    """A spring a method may add between anchor ``anchor_a`` on link ``link_a`` and ``anchor_b``
    on ``link_b`` (positions [m] in those links' frames); ``free_length`` 0 for a zero-free-length
    spring; ``rate`` [N/m] chosen by the method unless fixed; ``pulley_ratio`` of a
    block-and-tackle (the spring stretches ``pulley_ratio`` times the anchor distance change)."""

    name: str
    link_a: str
    anchor_a: tuple[float, float, float]
    link_b: str
    anchor_b: tuple[float, float, float]
    free_length: float = 0.0
    rate: float | None = None
    pulley_ratio: float = 1.0
    rate_max: float = math.inf


@dataclass
class BalanceResult:
    """What a balancing method returns.

    ``design``: the chosen values, per slot name (``{"mass": kg, "position": [m, m, m], ...}``);
    ``residual``: the remaining norm of what the method drives to zero (units in
    ``residual_units``), ``residual_before`` the same quantity unbalanced; ``rank`` and
    ``unknowns`` of the linear problem where there is one; ``limited_by``: human-readable reasons
    the result is not exact (``"rank 4 < 6 unknowns: ..."``, ``"bound: cw1.mass_max"``,
    ``"impossible: ..."``), empty when the balance is exact; ``metrics``: before/after peak and
    RMS values (gravity torque, actuator torque, shaking force and moment) where computed;
    ``balanced``: the balanced :class:`mechbal.Mechanism`; ``active_bounds``: every bound the
    design sits on (``"cw1.max_radius"``, ``"mass_budget"``), whether or not it limited the
    balance (when it did, it is also in ``limited_by``); ``undetermined``: combinations of the
    unknowns that the condition does not determine (the null space of the linear problem)."""

    method: str
    design: dict[str, dict[str, Any]]
    residual: float
    residual_before: float
    residual_units: str
    rank: int | None = None
    unknowns: int | None = None
    limited_by: list[str] = field(default_factory=list)
    metrics: dict[str, Any] = field(default_factory=dict)
    balanced: Any = None
    active_bounds: list[str] = field(default_factory=list)
    undetermined: list[str] = field(default_factory=list)

    @property
    def exact(self) -> bool:
        return not self.limited_by

    def summary(self) -> dict[str, Any]:
        """Plain JSON-able dict (for summary.json)."""
        def plain(x):
            if isinstance(x, dict):
                return {k: plain(v) for k, v in x.items()}
            if isinstance(x, (list, tuple)):
                return [plain(v) for v in x]
            if isinstance(x, np.ndarray):
                return x.tolist()
            if isinstance(x, np.generic):
                return x.item()
            return x

        return plain({"method": self.method, "design": self.design, "residual": self.residual,
                      "residual_before": self.residual_before, "residual_units": self.residual_units,
                      "rank": self.rank, "unknowns": self.unknowns, "limited_by": self.limited_by,
                      "exact": self.exact, "active_bounds": self.active_bounds,
                      "undetermined": self.undetermined, "metrics": self.metrics})
