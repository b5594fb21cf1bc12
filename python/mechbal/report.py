"""Reports: plots (matplotlib, Agg) and terminal tables."""
from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

import numpy as np


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _finish(plt, fig, legend_axis, path: str | Path, title: str) -> Path:
    """Legend, title, layout, save as PNG (creating the folder), close."""
    legend_axis.legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_wrench(path: str | Path, t: np.ndarray,
                variants: Mapping[str, tuple[np.ndarray, np.ndarray]], title: str = "") -> Path:
    """Shaking force x, y, z (top row) and moment x, y, z (bottom row) for each variant."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(13, 6.5), sharex=True)
    for name, (F, M) in variants.items():
        for k, axis in enumerate("xyz"):
            axes[0, k].plot(t, F[:, k], label=name)
            axes[1, k].plot(t, M[:, k], label=name)
    for k, axis in enumerate("xyz"):
        axes[0, k].set_title(f"shaking force {axis} [N]")
        axes[1, k].set_title(f"shaking moment {axis} [N m]")
        axes[1, k].set_xlabel("t [s]")
        for r in range(2):
            axes[r, k].grid(True, alpha=0.3)
    return _finish(plt, fig, axes[0, 0], path, title)


def plot_series(path: str | Path, t: np.ndarray, series: Mapping[str, np.ndarray],
                labels: Sequence[str], ylabel: str, title: str = "") -> Path:
    """One subplot per column (e.g. per joint), one line per named series."""
    plt = _pyplot()
    cols = len(labels)
    fig, axes = plt.subplots(1, cols, figsize=(4.5 * cols, 3.6), squeeze=False)
    for name, y in series.items():
        y = np.asarray(y).reshape(len(t), -1)
        for k in range(cols):
            axes[0, k].plot(t, y[:, k], label=name)
    for k, lab in enumerate(labels):
        axes[0, k].set_title(lab)
        axes[0, k].set_xlabel("t [s]")
        axes[0, k].set_ylabel(ylabel)
        axes[0, k].grid(True, alpha=0.3)
    return _finish(plt, fig, axes[0, 0], path, title)


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
