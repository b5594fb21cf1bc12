"""Physically plausible ranges of inputs that are finite and valid but almost surely a mistake.

Outside them the Python API warns (`mechbal.errors.PlausibilityWarning`, once per value)
and the command line refuses the case (exit code 2) unless ``--force``:

- a joint travel (a trajectory's ``end - start``, a joint's limit) beyond `MAX_TRAVEL`
  (1e3 rad, about 160 turns, or 1e3 m);
- a gravity of norm beyond `MAX_GRAVITY` (1e3 m/s^2, about 100 g);
- a mass beyond `MAX_MASS` (1e6 kg, a thousand tonnes).

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import math
import warnings
from typing import Any, Iterator

from mechbal.errors import PlausibilityWarning

MAX_TRAVEL = 1e3     #: rad or m
MAX_GRAVITY = 1e3    #: m/s^2
MAX_MASS = 1e6       #: kg

__all__ = ["MAX_TRAVEL", "MAX_GRAVITY", "MAX_MASS", "PlausibilityWarning", "mechanism_problems",
           "case_problems", "warn"]


def _real(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _vector(x: Any) -> list[float] | None:
    if isinstance(x, (list, tuple)) and x and all(_real(v) for v in x):
        return [float(v) for v in x]
    return None


def mechanism_problems(mechanism) -> list[tuple[str, str]]:
    """(field, message) for each value of a `mechbal.Mechanism` outside the ranges."""
    out = []
    g = [float(v) for v in mechanism.gravity]
    if math.hypot(*g) > MAX_GRAVITY:
        out.append(("gravity", f"|gravity| = {math.hypot(*g):.4g} m/s^2 is beyond the plausible "
                               f"{MAX_GRAVITY:g} m/s^2"))
    for b in mechanism.model.bodies:
        if b.mass > MAX_MASS:
            out.append((f"bodies[{b.name}].mass", f"{b.mass:.4g} kg is beyond the plausible {MAX_MASS:g} kg"))
    for j in mechanism.model.description.joints:
        for key in ("lower", "upper"):
            x = getattr(j, key)
            if math.isfinite(x) and abs(x) > MAX_TRAVEL:
                out.append((f"joints[{j.name}].{key}", f"{x:.4g} (rad or m) is beyond the plausible "
                                                      f"travel {MAX_TRAVEL:g}"))
    return out


def _walk(node: Any, path: str) -> Iterator[tuple[str, Any, Any]]:
    if isinstance(node, dict):
        for k, v in node.items():
            p = f"{path}.{k}" if path else str(k)
            yield p, k, v
            yield from _walk(v, p)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            if isinstance(v, (dict, list)):
                yield from _walk(v, f"{path}[{i}]")


def case_problems(config: Any) -> list[tuple[str, str]]:
    """(field, message) for each value of a case file (the dict read from TOML) outside the
    ranges: any ``gravity`` vector, any ``mass`` / ``mass_max`` number, any table's ``end`` against
    its ``start`` (trajectories), any ``lower`` / ``upper`` joint limit."""
    out = []
    for path, key, value in _walk(config, ""):
        if key == "gravity":
            g = _vector(value)
            if g is not None and math.hypot(*g) > MAX_GRAVITY:
                out.append((path, f"|gravity| = {math.hypot(*g):.4g} m/s^2 is beyond the plausible "
                                  f"{MAX_GRAVITY:g} m/s^2"))
        elif key in ("mass", "mass_max") and _real(value) and value > MAX_MASS:
            out.append((path, f"{value:.4g} kg is beyond the plausible {MAX_MASS:g} kg"))
        elif key in ("lower", "upper") and _real(value) and abs(value) > MAX_TRAVEL:
            out.append((path, f"{value:.4g} (rad or m) is beyond the plausible travel {MAX_TRAVEL:g}"))
        elif isinstance(value, dict) and "start" in value and "end" in value:
            s, e = value["start"], value["end"]
            s = [s] if _real(s) else _vector(s)
            e = [e] if _real(e) else _vector(e)
            if s and e and len(s) == len(e):
                travel = max(abs(b - a) for a, b in zip(s, e))
                if travel > MAX_TRAVEL:
                    out.append((f"{path}.end", f"a travel of {travel:.4g} (rad or m) from start is beyond "
                                               f"the plausible {MAX_TRAVEL:g}"))
    return out


def warn(problems: list[tuple[str, str]], stacklevel: int = 3) -> None:
    """One `PlausibilityWarning` per problem (the CLI turns them into errors)."""
    for field, message in problems:
        warnings.warn(f"{field}: {message} (outside the plausible range; see mechbal.plausibility)",
                      PlausibilityWarning, stacklevel=stacklevel)
