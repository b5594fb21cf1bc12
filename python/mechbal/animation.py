"""A GIF of a mechanism moving, with the shaking force and moment drawn at its base (what a
designer shows a colleague): ``mechbal run CASE --animate`` makes one per bodies file of the run.

The picture is a projection on the plane that the mechanism's points span most (a planar arm in
the x-z plane is seen face on; a spatial one from the side). Links are segments from each link
frame's origin to its parent's and to the named frames on the link (a loop's frames: the links of
a closed linkage meet there), when the bodies file carries ``link_position``, ``link_parent``,
``frame_position`` and ``frame_link``, as the general runner writes them; bodies are discs at their centres of mass
(area proportional to mass), and at the base origin O the shaking force F = dP/dt (red) and the
shaking moment M_O = dH_O/dt (blue, its component normal to the view as a signed arc) are drawn to
their own scale: the longest arrow of the run is a third of the mechanism's reach. A wrench below
`mechbal.report.ROUNDOFF_FLOOR` is drawn as nothing and labelled "0 (below 1e-12)".

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np

from mechbal.report import ROUNDOFF_FLOOR, _pyplot

__all__ = ["animate", "animate_bodies_file", "view_axes"]

_AXES = "xyz"


def view_axes(points: np.ndarray) -> tuple[int, int]:
    """The two coordinate axes (indices, increasing) along which ``points`` (..., 3) spread most:
    the plane the picture is drawn in."""
    p = np.asarray(points, float).reshape(-1, 3)
    p = p[np.all(np.isfinite(p), axis=1)]
    spread = np.ptp(p, axis=0) if len(p) else np.ones(3)
    order = np.argsort(-spread, kind="stable")
    a, b = sorted(int(i) for i in order[:2])
    return a, b


def animate(path: str | Path, t: np.ndarray, com: np.ndarray, mass: np.ndarray,
            shaking_force: np.ndarray, shaking_moment: np.ndarray, *,
            link_position: np.ndarray | None = None, link_parent: np.ndarray | None = None,
            frame_position: np.ndarray | None = None, frame_link: np.ndarray | None = None,
            title: str = "", max_frames: int = 120, fps: int = 20) -> Path:
    """Write the GIF: ``t`` (N,), ``com`` (N, B, 3) and ``mass`` (B,) of every body, the shaking
    force [N] and moment about O [N m] (N, 3); optionally every link frame's origin
    ``link_position`` (N, L, 3) and ``link_parent`` (L,) (-1 for the base) to draw the links, and
    every named frame's origin ``frame_position`` (N, F, 3) on link ``frame_link`` (F,).
    At most ``max_frames`` frames, evenly spread over the run. Returns the path."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    t = np.asarray(t, float)
    com = np.asarray(com, float)
    mass = np.asarray(mass, float)
    F = np.asarray(shaking_force, float)
    M = np.asarray(shaking_moment, float)
    n = len(t)
    if com.shape[:1] != (n,) or F.shape != (n, 3) or M.shape != (n, 3):
        raise ValueError(f"animate: t has {n} instants, com {com.shape}, shaking_force {F.shape}, "
                         f"shaking_moment {M.shape}")
    links = None if link_position is None else np.asarray(link_position, float)
    parents = None if link_parent is None else np.asarray(link_parent, int)
    frames_p = None if frame_position is None or links is None else np.asarray(frame_position, float)
    frames_l = None if frame_link is None else np.asarray(frame_link, int)
    points = com if links is None else np.concatenate([com, links], axis=1)
    if frames_p is not None and frames_p.size:
        points = np.concatenate([points, frames_p], axis=1)
    a, b = view_axes(np.concatenate([points.reshape(-1, 3), np.zeros((1, 3))]))
    normal = ({0, 1, 2} - {a, b}).pop()
    finite = points[..., [a, b]][np.all(np.isfinite(points[..., [a, b]]), axis=-1)]
    lo = np.minimum(finite.min(axis=0), 0.0) if finite.size else np.array([-1.0, -1.0])
    hi = np.maximum(finite.max(axis=0), 0.0) if finite.size else np.array([1.0, 1.0])
    reach = float(max(np.max(hi - lo), 1e-9))
    pad = 0.15 * reach
    lo, hi = lo - pad, hi + pad

    def peak(x: np.ndarray) -> float:
        x = x[np.isfinite(x)]
        return float(np.max(np.abs(x))) if x.size else 0.0

    F_in, M_in = F[:, [a, b]], M[:, [a, b]]
    F_peak = peak(np.linalg.norm(F_in, axis=1))
    M_peak = peak(np.concatenate([np.linalg.norm(M_in, axis=1), np.abs(M[:, normal])]))
    F_scale = reach / 3.0 / F_peak if F_peak >= ROUNDOFF_FLOOR else 0.0
    M_scale = reach / 3.0 / M_peak if M_peak >= ROUNDOFF_FLOOR else 0.0

    frames = np.unique(np.linspace(0, n - 1, min(max_frames, n)).round().astype(int))
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.set_xlabel(f"{_AXES[a]} [m]")
    ax.set_ylabel(f"{_AXES[b]} [m]")
    ax.set_title(title or "mechanism, shaking force and moment", fontsize=11)
    ax.plot([0.0], [0.0], marker="^", color="0.2", markersize=12, zorder=1)   # the base O
    sizes = 20.0 + 180.0 * (mass / mass.max() if mass.size and mass.max() > 0 else np.ones_like(mass))
    (sticks,) = ax.plot([], [], color="0.35", linewidth=3.0, solid_capstyle="round", zorder=2)
    dots = ax.scatter(np.zeros(len(mass)), np.zeros(len(mass)), s=sizes, color="tab:orange",
                      edgecolor="0.2", zorder=3)
    force = ax.quiver([0.0], [0.0], [0.0], [0.0], color="tab:red", angles="xy", scale_units="xy",
                      scale=1.0, width=0.008, zorder=4)
    moment = ax.quiver([0.0], [0.0], [0.0], [0.0], color="tab:blue", angles="xy", scale_units="xy",
                       scale=1.0, width=0.006, zorder=4)
    (arc,) = ax.plot([], [], color="tab:blue", linewidth=2.0, zorder=4)
    label = ax.text(0.02, 0.98, "", transform=ax.transAxes, va="top", ha="left", fontsize=9,
                    family="monospace", bbox=dict(facecolor="white", alpha=0.8, edgecolor="none"))

    def fmt(x: float, unit: str) -> str:
        return f"0 (below {ROUNDOFF_FLOOR:g})" if abs(x) < ROUNDOFF_FLOOR else f"{x:9.3g} {unit}"

    def draw(k: int):
        if links is not None and parents is not None:
            xs: list[float] = []
            ys: list[float] = []
            segments = [(links[k, parent], links[k, child]) for child, parent in enumerate(parents) if parent >= 0]
            if frames_p is not None and frames_l is not None:
                segments += [(links[k, li], frames_p[k, f]) for f, li in enumerate(frames_l) if li >= 0]
            for p, c in segments:
                xs += [p[a], c[a], np.nan]
                ys += [p[b], c[b], np.nan]
            sticks.set_data(xs, ys)
        dots.set_offsets(com[k][:, [a, b]])
        force.set_UVC([F_in[k, 0] * F_scale], [F_in[k, 1] * F_scale])
        moment.set_UVC([M_in[k, 0] * M_scale], [M_in[k, 1] * M_scale])
        # the moment about the view's normal: an arc around O whose sweep is its signed size
        sweep = np.clip(M[k, normal] * M_scale / (0.25 * reach), -1.0, 1.0) * 1.8 * np.pi
        th = np.linspace(0.0, sweep, 40)
        arc.set_data(0.12 * reach * np.cos(th), 0.12 * reach * np.sin(th))
        label.set_text(f"t = {t[k]:6.3f} s\nshaking force  (red)  |F|   = "
                       f"{fmt(float(np.linalg.norm(F[k])), 'N')}\nshaking moment (blue) |M_O| = "
                       f"{fmt(float(np.linalg.norm(M[k])), 'N m')}")
        return sticks, dots, force, moment, arc, label

    anim = FuncAnimation(fig, draw, frames=frames, blit=False)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    anim.save(str(path), writer=PillowWriter(fps=fps))
    plt.close(fig)
    return path


def animate_bodies_file(bodies: Mapping[str, np.ndarray], path: str | Path, *, title: str = "",
                        max_frames: int = 120, fps: int = 20) -> Path:
    """`animate` from a bodies file's arrays (`mechbal.export.read_bodies`)."""
    return animate(path, bodies["t"], bodies["com"], bodies["mass"], bodies["shaking_force"],
                   bodies["shaking_moment"], link_position=bodies.get("link_position"),
                   link_parent=bodies.get("link_parent"), frame_position=bodies.get("frame_position"),
                   frame_link=bodies.get("frame_link"), title=title, max_frames=max_frames, fps=fps)
