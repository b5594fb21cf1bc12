"""Data export shared by every case study.

``bodies_<variant>.npz`` holds, for N instants and B bodies:
``t`` (N,), ``names`` (B,), ``mass`` (B,), ``inertia_body`` (B,3,3) about each centre of mass in
the body frame, ``com`` (N,B,3) and ``rotation`` (N,B,3,3) (body -> base) in the base frame, and
mechbal's own ``shaking_force`` (N,3) and ``shaking_moment`` (N,3) about the base origin O.
From these arrays alone the shaking wrench can be recomputed by finite differences
(:func:`shaking_wrench_by_finite_differences`).
"""
from __future__ import annotations

import json
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


def _jsonable(x: Any) -> Any:
    if isinstance(x, Mapping):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, (np.floating, float)):
        return float(x)
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def write_summary(path: str | Path, summary: Mapping[str, Any]) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(_jsonable(summary), indent=2, sort_keys=False) + "\n")
    return path
