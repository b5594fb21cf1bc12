"""Reports: plots (matplotlib, Agg) and terminal tables.

Plots follow three rules. A panel whose every series stays below `ROUNDOFF_FLOOR` (SI units:
N, N m, rad, ...) is round-off, not a signal: it is drawn as a flat zero marked "0 (below 1e-12)"
instead of being autoscaled to look like one. A wrench plot shows only the components that carry a
signal, and its caption names those left out. A legend is drawn only when it tells series apart
(two or more); a single series is named in the title or caption.

Layer: Python core (docs/architecture.md)."""
from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

import numpy as np


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    # text is text: a name with '$' (a joint "a$b$") is drawn as written, never parsed as
    # mathtext (whose parse errors would fail the plot); no mechbal label uses mathtext
    matplotlib.rcParams["text.parse_math"] = False
    import matplotlib.pyplot as plt

    return plt


#: successive series: solid, then dashed, dotted, dash-dot, each thinner and drawn above the
#: previous one, so that coinciding lines all stay visible (a dashed line over a solid one)
_STYLES = [dict(linestyle="-", linewidth=2.6), dict(linestyle="--", linewidth=1.9),
           dict(linestyle=":", linewidth=1.9), dict(linestyle="-.", linewidth=1.3),
           dict(linestyle=(0, (5, 1, 1, 1)), linewidth=1.1)]


#: the largest value still drawn as round-off zero (absolute, in the plotted SI unit)
ROUNDOFF_FLOOR = 1e-12


def _is_roundoff(*arrays: np.ndarray) -> bool:
    """Every finite value of every array is below `ROUNDOFF_FLOOR` in magnitude."""
    for a in arrays:
        a = np.asarray(a, float)
        finite = a[np.isfinite(a)]
        if finite.size and np.max(np.abs(finite)) >= ROUNDOFF_FLOOR:
            return False
    return True


def _zero_panel(ax) -> None:
    """A panel whose series are all round-off: a fixed scale and the note, not an autoscale."""
    for line in ax.get_lines():
        line.set_ydata(np.zeros_like(np.asarray(line.get_ydata(), float)))
    ax.set_ylim(-1.0, 1.0)
    ax.text(0.5, 0.5, f"0 (below {ROUNDOFF_FLOOR:g})", transform=ax.transAxes, ha="center",
            va="center", fontsize=10, color="0.3")


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
    if len(labels) > 1:
        fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, top),
                   ncol=min(len(labels), 4), fontsize=9, frameon=False)
        top -= 0.035 * (1 + (len(labels) - 1) // 4) * (6.5 / fig.get_figheight())
    bottom = 0.0
    if caption:
        width = int(fig.get_figwidth() * 14)   # characters of 8.5 pt per inch, with a margin
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
    """Force x, y, z [N] and moment x, y, z [N m], one line per variant (successive variants
    dashed, dotted, ... over the previous ones), one panel per component that carries a signal in
    some variant; the components that are round-off (below `ROUNDOFF_FLOOR`) in every
    variant are named in the caption instead of drawn (a planar case: force z, moment x, y)."""
    plt = _pyplot()
    comps = [(f"{force} {axis}", "force [N]", 0, k) for k, axis in enumerate("xyz")] + \
        [(f"{moment} {axis}", "moment [N m]", 1, k) for k, axis in enumerate("xyz")]
    shown, zero = [], []
    for c in comps:
        (zero if _is_roundoff(*(v[c[2]][:, c[3]] for v in variants.values())) else shown).append(c)
    if not shown:   # everything balanced to round-off: one panel says so
        shown = comps[:1]
    left_out = [c for c in zero if c not in shown]
    if left_out:
        caption = (f"{caption} " if caption else "") + (
            ", ".join(c[0] for c in left_out) + f": 0 (below {ROUNDOFF_FLOOR:g}) in every variant, not drawn.")
    # forces on the first row, moments on the second (a row only when it has a panel)
    by_row = [[c for c in shown if c[2] == r] for r in (0, 1)]
    by_row = [r for r in by_row if r]
    cols = max(len(r) for r in by_row)
    fig, axes = plt.subplots(len(by_row), cols, figsize=(4.4 * cols + 0.2, 3.2 * len(by_row) + 0.4),
                             sharex=True, squeeze=False)
    slots = [axes[i, j] for i, r in enumerate(by_row) for j in range(len(r))]
    shown = [c for r in by_row for c in r]
    for ax in axes.ravel():
        ax.set_visible(any(ax is s for s in slots))
    for ax, (name, ylabel, row, k) in zip(slots, shown):
        for i, (vname, FM) in enumerate(variants.items()):
            ax.plot(t, FM[row][:, k], label=vname, **_style(i))
        ax.set_title(name, fontsize=10)
        ax.set_ylabel(ylabel)
        ax.set_xlabel("t [s]")
        ax.xaxis.set_tick_params(labelbottom=True)
        ax.grid(True, alpha=0.3)
        if (name, ylabel, row, k) in zero:
            _zero_panel(ax)
    return _finish(plt, fig, slots, path, title, caption)


def plot_series(path: str | Path, t: np.ndarray, series: Mapping[str, np.ndarray],
                labels: Sequence[str], ylabel: str | Sequence[str], title: str = "",
                caption: str = "") -> Path:
    """One panel per column (e.g. per joint) in a grid (`grid_shape`), one line per named
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
        if _is_roundoff(*(np.asarray(y).reshape(len(t), -1)[:, k] for y in series.values())):
            _zero_panel(flat[k])
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
