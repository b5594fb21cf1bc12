"""Reports: plots (matplotlib, Agg) and terminal tables.

Layer: Python core (docs/architecture.md)."""
from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

import numpy as np


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


#: successive series: solid, then dashed, dotted, dash-dot, each thinner and drawn above the
#: previous one, so that coinciding lines all stay visible (a dashed line over a solid one)
_STYLES = [dict(linestyle="-", linewidth=2.6), dict(linestyle="--", linewidth=1.9),
           dict(linestyle=":", linewidth=1.9), dict(linestyle="-.", linewidth=1.3),
           dict(linestyle=(0, (5, 1, 1, 1)), linewidth=1.1)]


def _style(i: int) -> dict:
    return dict(_STYLES[i % len(_STYLES)], zorder=2 + i)


def grid_shape(panels: int) -> tuple[int, int]:
    """(rows, columns) of a grid of ``panels`` panels: one column up to 1, two up to 4, three
    beyond (a 6-joint plot is 2 x 3, a 12-joint plot 4 x 3)."""
    cols = 1 if panels <= 1 else 2 if panels <= 4 else 3
    return -(-panels // cols), cols


def _finish(plt, fig, axes, path: str | Path, title: str, caption: str) -> Path:
    """One legend for the figure (above the panels), title, caption (below), save as PNG."""
    import textwrap

    handles, labels = axes[0].get_legend_handles_labels()
    top = 0.96 if title else 0.995
    if title:
        fig.suptitle(title, y=0.995, va="top", fontsize=12)
    if len(labels) > 1 or labels and not labels[0].startswith("_"):
        fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, top),
                   ncol=min(len(labels), 4), fontsize=9, frameon=False)
        top -= 0.035 * (1 + (len(labels) - 1) // 4) * (6.5 / fig.get_figheight())
    bottom = 0.0
    if caption:
        width = int(fig.get_figwidth() * 17)
        text = "\n".join(textwrap.wrap(caption, width))
        fig.text(0.01, 0.005, text, ha="left", va="bottom", fontsize=8.5, color="0.25")
        bottom = (0.03 + 0.022 * text.count("\n")) * (6.5 / fig.get_figheight())
    fig.tight_layout(rect=(0.0, bottom, 1.0, top))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_wrench(path: str | Path, t: np.ndarray,
                variants: Mapping[str, tuple[np.ndarray, np.ndarray]], title: str = "",
                caption: str = "", force: str = "shaking force",
                moment: str = "shaking moment") -> Path:
    """Force x, y, z (top row) [N] and moment x, y, z (bottom row) [N m], one line per variant
    (successive variants dashed, dotted, ... over the previous ones)."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(13, 6.8), sharex=True)
    for i, (name, (F, M)) in enumerate(variants.items()):
        for k in range(3):
            axes[0, k].plot(t, F[:, k], label=name, **_style(i))
            axes[1, k].plot(t, M[:, k], label=name, **_style(i))
    for k, axis in enumerate("xyz"):
        axes[0, k].set_title(f"{force} {axis}", fontsize=10)
        axes[1, k].set_title(f"{moment} {axis}", fontsize=10)
        axes[0, k].set_ylabel("force [N]")
        axes[1, k].set_ylabel("moment [N m]")
        for r in range(2):
            axes[r, k].set_xlabel("t [s]")
            axes[r, k].xaxis.set_tick_params(labelbottom=True)
            axes[r, k].grid(True, alpha=0.3)
    return _finish(plt, fig, axes.ravel(), path, title, caption)


def plot_series(path: str | Path, t: np.ndarray, series: Mapping[str, np.ndarray],
                labels: Sequence[str], ylabel: str | Sequence[str], title: str = "",
                caption: str = "") -> Path:
    """One panel per column (e.g. per joint) in a grid (:func:`grid_shape`), one line per named
    series; ``ylabel`` with its unit, one for all panels or one per panel."""
    plt = _pyplot()
    n = len(labels)
    ylabels = [ylabel] * n if isinstance(ylabel, str) else list(ylabel)
    if len(ylabels) != n:
        raise ValueError(f"ylabel: {len(ylabels)} labels for {n} panels")
    rows, cols = grid_shape(n)
    width = 6.5 if cols == 1 else 4.6 * cols
    fig, axes = plt.subplots(rows, cols, figsize=(width, 2.9 * rows + 1.3), squeeze=False,
                             sharex=True)
    flat = axes.ravel()
    for i, (name, y) in enumerate(series.items()):
        y = np.asarray(y).reshape(len(t), -1)
        if y.shape[1] != n:
            raise ValueError(f"series {name!r} has {y.shape[1]} columns for {n} panels")
        for k in range(n):
            flat[k].plot(t, y[:, k], label=name, **_style(i))
    for k, lab in enumerate(labels):
        flat[k].set_title(lab, fontsize=10)
        flat[k].set_xlabel("t [s]")
        flat[k].set_ylabel(ylabels[k])
        flat[k].grid(True, alpha=0.3)
        flat[k].xaxis.set_tick_params(labelbottom=True)
    for ax in flat[n:]:
        ax.set_visible(False)
    return _finish(plt, fig, flat[:n], path, title, caption)


def table(rows: Sequence[Sequence[object]], header: Sequence[str]) -> str:
    """A plain-text table with aligned columns (numbers formatted to 4 significant digits)."""
    def fmt(x):
        if isinstance(x, (float, np.floating)):
            return f"{x:.4g}"
        if isinstance(x, (list, tuple, np.ndarray)):
            return "[" + ", ".join(fmt(v) for v in x) + "]"
        return str(x)

    cells = [[fmt(c) for c in r] for r in rows]
    widths = [max(len(h), *(len(r[i]) for r in cells)) for i, h in enumerate(header)]
    line = "  ".join(h.ljust(w) for h, w in zip(header, widths))
    out = [line, "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.ljust(w) for c, w in zip(r, widths)) for r in cells]
    return "\n".join(out)


def peak_abs(x: np.ndarray) -> np.ndarray:
    """Peak absolute value of each column of an (N, k) array."""
    return np.max(np.abs(np.asarray(x)), axis=0)
