"""Run data shared by every case study: bodies files and summary.json.

``bodies_<variant>.npz`` holds, for N instants and B bodies:
``t`` (N,), ``names`` (B,), ``mass`` (B,), ``inertia_body`` (B,3,3) about each centre of mass in
the body frame, ``com`` (N,B,3) and ``rotation`` (N,B,3,3) (body -> base) in the base frame, and
mechbal's own ``shaking_force`` (N,3) and ``shaking_moment`` (N,3) about the base origin O.
From these arrays alone the shaking wrench can be recomputed by finite differences
(`shaking_wrench_by_finite_differences`).

``summary.json`` is strict JSON (`write_summary`): non-finite numbers are written as null and
listed under ``non_finite_values``.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

BODY_FIELDS = ("t", "names", "mass", "inertia_body", "com", "rotation", "shaking_force",
               "shaking_moment")


def write_bodies(path: str | Path, *, t: np.ndarray, names: Sequence[str], mass: np.ndarray,
                 inertia_body: np.ndarray, com: np.ndarray, rotation: np.ndarray,
                 shaking_force: np.ndarray, shaking_moment: np.ndarray,
                 **extra: np.ndarray) -> Path:
    """Write one variant's bodies file after checking every shape against the schema."""
    t = np.asarray(t, float)
    N, B = t.shape[0], len(names)
    expected = {
        "mass": (B,), "inertia_body": (B, 3, 3), "com": (N, B, 3), "rotation": (N, B, 3, 3),
        "shaking_force": (N, 3), "shaking_moment": (N, 3),
    }
    arrays = dict(mass=mass, inertia_body=inertia_body, com=com, rotation=rotation,
                  shaking_force=shaking_force, shaking_moment=shaking_moment)
    for key, shape in expected.items():
        a = np.asarray(arrays[key], float)
        if a.shape != shape:
            raise ValueError(f"{key} must have shape {shape}, got {a.shape}")
        arrays[key] = a
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, t=t, names=np.array(list(names), dtype=str), **arrays, **extra)
    return path


def read_bodies(path: str | Path) -> dict[str, np.ndarray]:
    with np.load(path) as data:
        out = {k: data[k] for k in data.files}
    missing = [k for k in BODY_FIELDS if k not in out]
    if missing:
        raise ValueError(f"{path}: missing fields {missing}")
    return out


def _derivative(x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Central differences in the interior, second-order one-sided at the ends."""
    return np.gradient(x, t, axis=0, edge_order=2)


def momenta_by_finite_differences(data: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Linear momentum P and angular momentum H_O (N, 3) from poses alone: velocities and angular
    velocities by central differences of ``com`` and ``rotation`` (w^ = dR/dt R^T)."""
    t, m, Ib = data["t"], data["mass"], data["inertia_body"]
    com, R = data["com"], data["rotation"]
    v = _derivative(com, t)
    dR = _derivative(R, t)
    W = np.einsum("nbij,nbkj->nbik", dR, R)  # skew(w)
    w = np.stack([W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0],
                  W[..., 1, 0] - W[..., 0, 1]], axis=-1) / 2.0
    I_world = np.einsum("nbij,bjk,nblk->nbil", R, Ib, R)
    P = np.einsum("b,nbi->ni", m, v)
    H = np.einsum("b,nbi->ni", m, np.cross(com, v)) + np.einsum("nbij,nbj->ni", I_world, w)
    return P, H


def shaking_wrench_by_finite_differences(data: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Shaking force dP/dt and moment dH_O/dt (N, 3) recomputed from the exported poses only."""
    P, H = momenta_by_finite_differences(data)
    return _derivative(P, data["t"]), _derivative(H, data["t"])


def _jsonable(x: Any, path: str = "", notes: list | None = None) -> Any:
    """Plain JSON types; a non-finite float becomes None and, when ``notes`` is given, a note
    ``{"field": dotted path, "value": "NaN" | "Infinity" | "-Infinity"}`` is appended."""
    if isinstance(x, Mapping):
        return {str(k): _jsonable(v, f"{path}.{k}" if path else str(k), notes) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v, f"{path}[{i}]", notes) for i, v in enumerate(x)]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist(), path, notes)
    if isinstance(x, (np.bool_, bool)):
        return bool(x)
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, (np.floating, float)):
        v = float(x)
        if not math.isfinite(v):
            if notes is not None:
                notes.append({"field": path, "value": "NaN" if v != v else
                              ("Infinity" if v > 0 else "-Infinity")})
            return None
        return v
    if isinstance(x, (str, int)) or x is None:
        return x
    if isinstance(x, Path):
        return str(x)
    raise TypeError(f"{path or 'summary'}: cannot be written to JSON ({type(x).__name__})")


def to_json(summary: Mapping[str, Any]) -> tuple[str, list[dict]]:
    """Strict JSON text of ``summary`` (RFC 8259: no NaN or Infinity) and the notes on the
    non-finite values it replaced by null."""
    notes: list[dict] = []
    data = _jsonable(summary, "", notes)
    if notes:
        data["non_finite_values"] = notes
    return json.dumps(data, indent=2, sort_keys=False, allow_nan=False) + "\n", notes


#: the version of summary.json's schema (``mechbal/cases/summary.schema.json``): every file
#: starts with ``schema_version`` and ``command``
SUMMARY_SCHEMA_VERSION = 2
SUMMARY_COMMANDS = ("run", "balance", "verify", "sweep", "identify")


def write_summary(path: str | Path, summary: Mapping[str, Any], command: str = "run") -> Path:
    """Write ``summary`` as strict JSON, headed by ``schema_version`` and ``command`` (the
    mechbal command that writes it: run, balance, verify, sweep); its keys follow
    ``mechbal/cases/summary.schema.json`` (docs/summary.md). A non-finite number (NaN, +-inf:
    e.g. a paper value the case does not give) is written as ``null`` and listed under
    ``non_finite_values`` with its dotted field. The header and the notes go both into the file
    and (when ``summary`` is a dict) into ``summary`` itself, so that the caller can warn."""
    if command not in SUMMARY_COMMANDS:
        raise ValueError(f"command: must be one of {', '.join(SUMMARY_COMMANDS)} (got {command!r})")
    header = {"schema_version": SUMMARY_SCHEMA_VERSION, "command": command}
    body = {k: v for k, v in summary.items() if k not in header}
    if isinstance(summary, dict):
        summary.clear()
        summary.update(header)
        summary.update(body)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text, notes = to_json({**header, **body})
    path.write_text(text)
    if notes and isinstance(summary, dict):
        summary["non_finite_values"] = notes
    return path
