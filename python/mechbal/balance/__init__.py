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

from mechbal.balance.result import BalanceResult, CounterweightSlot, DiscSlot, InertiaSlot, SpringSlot

__all__ = ["METHODS", "BalanceResult", "CounterweightSlot", "DiscSlot", "InertiaSlot", "SpringSlot", "method"]

#: method name -> module path; each module has ``balance(mechanism, design, samples, **options)``
METHODS = {
    "static": "mechbal.balance.static",
    "force": "mechbal.balance.force",
    "moment": "mechbal.balance.moment",
    "springs": "mechbal.balance.springs",
    "rms": "mechbal.balance.rms",
}


def method(name: str):
    """The module of a balancing method by name (ValueError with the known names otherwise)."""
    import importlib

    if name not in METHODS:
        from mechbal.schema import did_you_mean

        raise ValueError(f"method: unknown balancing method '{name}'{did_you_mean(name, list(METHODS))} "
                         f"(known: {', '.join(METHODS)})")
    return importlib.import_module(METHODS[name])
