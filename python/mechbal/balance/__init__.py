"""Balancing by method, for any mechanism.

Each method is a module with a function ``balance(mechanism, design, samples) -> BalanceResult``
over any `mechbal.Mechanism` (serial, tree or closed-loop), built on the C++ regressors:

| method | module | what it makes zero (or least) |
|---|---|---|
| static | `mechbal.balance.static` | gravity torque over a workspace sample (counterweights) |
| force | `mechbal.balance.force` | shaking force (centre of mass stationary) for all motions |
| moment | `mechbal.balance.moment` | shaking moment (counter-rotating discs, gear ratios) |
| springs | `mechbal.balance.springs` | gravity torque through springs (constant potential energy) |
| rms | `mechbal.balance.rms` | RMS or peak actuator torque over a trajectory |

The design variables (which bodies or springs may be added or changed, where, with which bounds
and mass budget) are `CounterweightSlot` /
`SpringSlot` / `DiscSlot` /
`InertiaSlot` objects (or the ``[balance]`` table of a case file);
a result names what limited it (rank, an active bound, an impossibility).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any, Protocol, cast

from mechbal.balance.result import (
    BalanceResult, CounterweightDesign, CounterweightSlot, DiscDesign, DiscSlot, InertiaDesign,
    InertiaSlot, SlotDesign, SpringDesign, SpringSlot)  # noqa: F401 (SlotDesign: the union)

if TYPE_CHECKING:
    from mechbal.balance import force, moment, rms, springs, static
    from mechbal.balance.fronts import Front

__all__ = ["METHODS", "BalanceResult", "CounterweightSlot", "DiscSlot", "InertiaSlot", "SpringSlot",
           "CounterweightDesign", "SpringDesign", "DiscDesign", "InertiaDesign",
           "BalancingMethod", "method", "static", "force", "moment", "springs", "rms", "front"]

#: method name -> module path; each module has ``balance(mechanism, design, samples, **options)``
METHODS = {
    "static": "mechbal.balance.static",
    "force": "mechbal.balance.force",
    "moment": "mechbal.balance.moment",
    "springs": "mechbal.balance.springs",
    "rms": "mechbal.balance.rms",
}


class BalancingMethod(Protocol):
    """What `method` returns: a method's module, with its ``balance`` function."""

    def balance(self, mechanism: Any, design: Any, samples: Any, /, *args: Any,
                **options: Any) -> BalanceResult[Any]: ...


def method(name: str) -> BalancingMethod:
    """The module of a balancing method by name (ValueError with the known names otherwise)."""
    if name not in METHODS:
        from mechbal.schema import did_you_mean

        raise ValueError(f"method: unknown balancing method '{name}'{did_you_mean(name, list(METHODS))} "
                         f"(known: {', '.join(METHODS)})")
    return cast(BalancingMethod, importlib.import_module(METHODS[name]))


def front(mechanism: Any, design: Any, points: int = 20, **options: Any) -> "Front":
    """The trade-off front between added mass and residual (`mechbal.balance.fronts.front`)."""
    from mechbal.balance.fronts import front as _front

    return _front(mechanism, design, points, **options)


def __getattr__(name: str) -> Any:
    # the method modules load on first use (``mechbal.balance.static`` after ``import mechbal``)
    if name in METHODS:
        return importlib.import_module(METHODS[name])
    raise AttributeError(f"module 'mechbal.balance' has no attribute {name!r}")
