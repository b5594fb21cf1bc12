"""Design variables and results shared by every balancing method.

Layer: methods (docs/architecture.md)."""
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
    ``inertia`` (3, 3) about its centre of mass, link axes (default: a point mass).

    ``position``: the counterweight's centre is given (user frame), only its mass is chosen (one
    unknown, exact: no ``center``, ``direction`` or ``max_radius`` with it; ``max_radius = 0``
    is the same). ``tie``: the name of another slot of the design whose mass and position (in
    each slot's own link frame: identical legs of a parallel mechanism) this one shares; a tied
    slot gives no bounds of its own, it takes them from the slot it is tied to."""

    name: str
    link: str
    mass_min: float = 0.0
    mass_max: float = math.inf
    max_radius: float = math.inf
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)
    direction: tuple[float, float, float] | None = None
    inertia: Any = None
    position: tuple[float, float, float] | None = None
    tie: str | None = None


@dataclass(frozen=True)
class SpringSlot:
    """A spring a method may add between anchor ``anchor_a`` on link ``link_a`` and ``anchor_b``
    on ``link_b`` (positions [m] in those links' frames; ``link_a``/``link_b`` may also name a
    frame of the mechanism, e.g. a DH frame, and the anchor is then in that frame);
    ``free_length`` [m] the anchor distance at which each spring carries only its ``preload``
    (0 and no preload: a zero-free-length spring); ``rate`` [N/m] of each spring, chosen by the
    method unless fixed (within ``rate_min``..``rate_max``); ``count`` identical springs in
    parallel; ``pulley_ratio`` k of a block and tackle: the anchor distance changes k times as
    much as the springs' length, so (virtual work) the tension at the anchors is count * spring
    force / k and the equivalent rate there is count * rate / k**2 (Martini et al. 2015, Tables
    1-2); ``anchor_a_bounds`` / ``anchor_b_bounds`` ((lower xyz), (upper xyz)) let the method move
    an anchor within a box (None: fixed)."""

    name: str
    link_a: str
    anchor_a: tuple[float, float, float]
    link_b: str
    anchor_b: tuple[float, float, float]
    free_length: float = 0.0
    rate: float | None = None
    pulley_ratio: float = 1.0
    rate_max: float = math.inf
    preload: float = 0.0
    count: int = 1
    rate_min: float = 0.0
    anchor_a_bounds: Any = None
    anchor_b_bounds: Any = None


@dataclass(frozen=True)
class DiscSlot:
    """A counter-rotating disc a method may add (shaking-moment balancing, Coutinho & Hess
    Coelho): an axle on link ``carrier`` through ``position`` [m] along ``axis`` (carrier frame),
    the disc turning relative to the carrier by ``ratio`` times the rate of coordinate ``joint``
    (a gear train; ratio 1: the disc turns with the next link). Its mass is part of the
    carrier's; it adds its axial ``inertia`` J_a [kg m^2] about the axle and
    ``transverse_inertia`` (None: J_a / 2, a thin disc). ``ratio`` and ``inertia`` None are
    chosen by the method (inertia within ``inertia_min``..``inertia_max``; a chosen ratio
    outside ``ratio_min``..``ratio_max`` is reported)."""

    name: str
    carrier: str
    joint: str
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    ratio: float | None = None
    inertia: float | None = None
    transverse_inertia: float | None = None
    inertia_min: float = 0.0
    inertia_max: float = math.inf
    ratio_min: float = -math.inf
    ratio_max: float = math.inf


@dataclass(frozen=True)
class InertiaSlot:
    """Central principal inertias of an existing body that a method may choose (``components``
    among ``"Ixx", "Iyy", "Izz"``, about the body's centre of mass in its link's axes, each >=
    ``minimum``): e.g. the cross-bar of the spatial arm's link 2 (corrected eq 25 of the discs
    paper)."""

    name: str
    body: str
    components: tuple[str, ...] = ("Iyy",)
    minimum: float = 0.0


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
    ``balanced``: the balanced `mechbal.Mechanism`; ``elements``: balancing elements that
    are not bodies of the mechanism (the sized `SpringSlot` objects of the spring method);
    ``active_bounds``: every bound the design sits on (``"cw1.max_radius"``, ``"mass_budget"``),
    whether or not it limited the balance (when it did, it is also in ``limited_by``);
    ``undetermined``: combinations of the unknowns that the condition does not determine (the
    null space of the linear problem); ``tied``: groups of counterweight slots that share one
    mass and position (``{slot tied to: [every slot of the group]}``)."""

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
    elements: list = field(default_factory=list)
    active_bounds: list[str] = field(default_factory=list)
    undetermined: list[str] = field(default_factory=list)
    tied: dict[str, list[str]] = field(default_factory=dict)
    #: the design without bounds (counterweights: the minimum-norm least-squares solution per
    #: slot; springs: the least-squares rates and anchors), what ``limited_by`` compares with
    unconstrained: dict[str, Any] = field(default_factory=dict)

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
                      "undetermined": self.undetermined, "tied": self.tied,
                      "unconstrained": self.unconstrained, "metrics": self.metrics})
