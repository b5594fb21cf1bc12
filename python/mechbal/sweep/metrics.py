"""Metrics of a sweep: the built-in ones (peak and RMS of gravity torque over a workspace sample, of
actuator torque, shaking force and shaking moment over a trajectory) and any callable of a
`mechbal.Mechanism`.

A built-in metric is ``<statistic>_<quantity>`` or ``<statistic>_<quantity>.<joint>`` (the names
of summary.json: ``peak_shaking_force``, ``rms_joint_torque``, ...):

- statistic ``peak`` = max over the samples of the Euclidean norm of the vector (the actuated
  joints' forces, or the 3 components of the wrench), ``rms`` = sqrt(mean over the samples of its
  squared norm); with ``.<joint>`` (torques only) the vector is that one joint's force. (A case
  run's summary.json gives the same quantities per component or per joint: the peak of each
  absolute value.)
- quantity ``gravity_torque`` (the actuated joints' gravity forces holding each pose of the
  workspace sample still, C^T G for a closed mechanism) [N m or N], ``joint_torque`` (the
  actuated joints' forces along the trajectory, gravity included) [N m or N], ``shaking_force``
  (dP/dt) [N], ``shaking_moment`` (dH_O/dt about O) [N m] along the trajectory.

The names before summary.json's schema 1 (``shaking_force_peak``, ``actuator_torque_rms``, ...)
are still read, with a DeprecationWarning (``RENAMED``).

All four quantities are linear in the bodies' inertial parameters pi (Y(q) pi with the gravity,
torque and momentum-rate regressors), which is what lets a sweep over body parameters evaluate
thousands of parameter sets per regressor evaluation.

A callable metric is ``f(mechanism) -> float | dict[str, float]`` (with design variables:
``f(mechanism, design) -> ...`` where ``design`` maps each ``design.<name>`` to its value); a dict
gives one column per key, ``<metric>.<key>``. It is evaluated on the mechanism rebuilt with the
set's parameters, so it can be anything: a balancing method's ``BalanceResult.metrics``, a
closed-form check, a cost. It must be picklable to run on processes or a cluster (a module-level
function or a lambda; cloudpickle handles both).

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, Callable

from mechbal.errors import ConfigError

QUANTITIES = ("gravity_torque", "joint_torque", "shaking_force", "shaking_moment")
STATISTICS = ("peak", "rms")
BUILTIN = tuple(f"{s}_{q}" for q in QUANTITIES for s in STATISTICS)
#: the unit of each built-in metric (``N m`` for a revolute joint, ``N`` for a prismatic one)
UNITS = {f"{s}_{q}": u for q, u in (("gravity_torque", "N m"), ("joint_torque", "N m"), ("shaking_force", "N"),
                                    ("shaking_moment", "N m")) for s in STATISTICS}
#: the built-in names before summary.json's schema 1 -> their names now
RENAMED = {f"{old}_{s}": f"{s}_{new}" for old, new in (("gravity_torque", "gravity_torque"),
                                                        ("actuator_torque", "joint_torque"),
                                                        ("shaking_force", "shaking_force"),
                                                        ("shaking_moment", "shaking_moment"))
           for s in STATISTICS}
#: quantities evaluated over the workspace sample (poses); the others over the trajectory
STATIC = ("gravity_torque",)


@dataclass(frozen=True)
class MetricSpec:
    """A resolved metric: ``name`` (the column), and either a built-in ``quantity``,
    ``statistic`` and optional ``joint``, or a ``function``."""

    name: str
    quantity: str | None = None
    statistic: str | None = None
    joint: str | None = None
    function: Callable[..., Any] | None = None

    @property
    def builtin(self) -> bool:
        return self.function is None


def resolve(metrics: Any, actuated: list[str], field: str = "metrics") -> list[MetricSpec]:
    """MetricSpecs from a list of names and ``(name, callable)`` pairs or a ``{name: callable or
    builtin name}`` dict (ConfigError naming the entry otherwise)."""
    from mechbal.schema import did_you_mean

    if isinstance(metrics, dict):
        items = list(metrics.items())
    elif isinstance(metrics, (list, tuple)):
        items = []
        for x in metrics:
            if isinstance(x, str):
                items.append((x, x))
            elif isinstance(x, tuple) and len(x) == 2:
                items.append(x)
            elif callable(x):
                items.append((getattr(x, "__name__", "metric"), x))
            else:
                raise ConfigError(field, "each metric is a name, a (name, callable) pair or a callable", x)
    else:
        raise ConfigError(field, "must be a list of metric names or a {name: callable} dict", metrics)
    if not items:
        raise ConfigError(field, "must name at least one metric", has_value=False)
    out, seen = [], set()
    for i, (name, what) in enumerate(items):
        f = f"{field}[{i}]"
        if not isinstance(name, str) or not name:
            raise ConfigError(f, "a metric's name must be a non-empty string", name)
        if name in seen:
            raise ConfigError(f, "names a metric twice", name)
        seen.add(name)
        if callable(what):
            out.append(MetricSpec(name, function=what))
            continue
        if not isinstance(what, str):
            raise ConfigError(f, "must be a built-in metric name or a callable", what)
        base, _, joint = what.partition(".")
        if base in RENAMED:
            warnings.warn(f"{f}: metric {base!r} is now called {RENAMED[base]!r} (summary.json schema 1); "
                          "the old name goes in a later release", DeprecationWarning, stacklevel=3)
            base = RENAMED[base]
            if name == what:
                name = base + (f".{joint}" if joint else "")
        if base not in BUILTIN:
            raise ConfigError(f, f"unknown metric{did_you_mean(base, list(BUILTIN))} (built-in: "
                                 f"{', '.join(BUILTIN)}, optionally .<joint>; or give a callable)", what)
        statistic, quantity = base.split("_", 1)
        if joint:
            if quantity not in ("gravity_torque", "joint_torque"):
                raise ConfigError(f, "only torques can be taken per joint", what)
            if joint not in actuated:
                raise ConfigError(f, f"no actuated joint named {joint!r}{did_you_mean(joint, actuated)}", what)
        out.append(MetricSpec(name, quantity, statistic, joint or None))
    return out


__all__ = ["BUILTIN", "MetricSpec", "QUANTITIES", "RENAMED", "STATIC", "STATISTICS", "UNITS", "resolve"]
