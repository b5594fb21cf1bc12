"""Draw the figure of each example of docs/examples.md into docs/images/example_<name>.png.

Each example script in docs/examples/ is run as it is (runpy, its output hidden) and its figure is
drawn from what it computed, so the picture beside the code is that code's result. The PNGs are
small and checked in: the site is built without running anything (no compiler, no network).
tests/python/test_examples.py runs this script into a temporary folder.

Run after changing an example: python docs/make_example_figures.py [--out docs/images]
"""
from __future__ import annotations

import argparse
import contextlib
import io
import runpy
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE / "examples"
SIZE, DPI = (7.0, 2.8), 80
plt.rcParams.update({"axes.titlesize": 9, "axes.labelsize": 8, "xtick.labelsize": 8,
                     "ytick.labelsize": 8})


def _run(name: str) -> dict:
    with contextlib.redirect_stdout(io.StringIO()):
        return runpy.run_path(str(EXAMPLES / f"{name}.py"), run_name="__main__")


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def shaking_wrench_from_urdf(out: Path) -> Path:
    g = _run("shaking_wrench_from_urdf")
    t, w = g["t"], g["wrench"]
    fig, (a, b) = plt.subplots(1, 2, figsize=SIZE)
    for k, c in enumerate("xyz"):
        if np.abs(w.shaking_force[:, k]).max() > 1e-12:
            a.plot(t, w.shaking_force[:, k], label=f"F{c}")
        if np.abs(w.shaking_moment[:, k]).max() > 1e-12:
            b.plot(t, w.shaking_moment[:, k], label=f"M{c}")
    a.set(xlabel="t [s]", ylabel="shaking force [N]", title="shaking force dP/dt")
    b.set(xlabel="t [s]", ylabel="shaking moment [N m]", title="shaking moment dH_O/dt")
    a.legend(fontsize=8)
    b.legend(fontsize=8)
    return _save(fig, out / "example_shaking_wrench_from_urdf.png")


def balance_arm(out: Path) -> Path:
    g = _run("balance_arm")
    arm, balanced = g["arm"], g["result"].balanced
    q1 = np.linspace(-np.pi, np.pi, 181)
    q = np.column_stack([q1, np.full_like(q1, 0.5)])   # the shoulder turning, the elbow at 0.5 rad
    before, after = arm.gravity_torque(q), balanced.gravity_torque(q)
    fig, ax = plt.subplots(figsize=SIZE)
    for j, name in enumerate(arm.joint_names):
        ax.plot(q1, before[:, j], label=f"{name}, unbalanced")
        ax.plot(q1, after[:, j], "--", label=f"{name}, balanced")
    ax.set(xlabel="shoulder angle [rad] (elbow at 0.5 rad)", ylabel="gravity torque [N m]",
           title="gravity torque before and after the two counterweights")
    ax.legend(fontsize=8, ncol=2)
    return _save(fig, out / "example_balance_arm.png")


def control_against_simulation(out: Path) -> Path:
    g = _run("control_against_simulation")
    run = g["run"]   # the closed loop along the user's sampled motion
    fig, (a, b) = plt.subplots(1, 2, figsize=SIZE)
    for j in range(run.q.shape[1]):
        a.plot(run.t, run.q_des[:, j], "k--", lw=0.8)
        a.plot(run.t, run.q[:, j], label=f"joint {j + 1}")
        b.plot(run.t, run.tracking_error[:, j], label=f"joint {j + 1}")
    a.set(xlabel="t [s]", ylabel="q [rad]", title="desired (dashed) and simulated q")
    b.set(xlabel="t [s]", ylabel="q_des - q [rad]", title="tracking error (1 kHz computed torque)")
    a.legend(fontsize=8)
    b.legend(fontsize=8)
    return _save(fig, out / "example_control_against_simulation.png")


def run_paper_case(out: Path) -> Path:
    import json

    import mechbal.cases

    with tempfile.TemporaryDirectory() as tmp, contextlib.redirect_stdout(io.StringIO()):
        mechbal.cases.run_case("arm2link", Path(tmp) / "arm2link")
        summary = json.loads((Path(tmp) / "arm2link" / "summary.json").read_text())
    peaks = summary["peak_joint_torque"]["nominal"]
    rms = summary["rms_joint_torque"]["nominal"]
    names = summary["actuated"]
    fig, ax = plt.subplots(figsize=SIZE)
    x = np.arange(len(names))
    ax.bar(x - 0.2, peaks, 0.4, label="peak_joint_torque")
    ax.bar(x + 0.2, rms, 0.4, label="rms_joint_torque")
    ax.set_xticks(x, names)
    ax.set(ylabel="torque [N m]", title="arm2link: joint torques read from summary.json")
    ax.legend(fontsize=8)
    return _save(fig, out / "example_run_paper_case.png")


def min_shaking_paminsa(out: Path) -> Path:
    g = _run("min_shaking_paminsa")
    rows = g["rows"]
    labels = [label for label, _, _ in rows]
    fig, ax = plt.subplots(figsize=SIZE)
    y = np.arange(len(rows))
    ax.barh(y - 0.2, [m[0] for _, _, m in rows], 0.4, label="RMS shaking force [N]")
    ax.barh(y + 0.2, [m[1] for _, _, m in rows], 0.4, label="peak shaking force [N]")
    ax.set_yticks(y, labels, fontsize=7)
    ax.invert_yaxis()
    ax.set(title="PAMINSA: balancing by motion, by mass and by both")
    ax.legend(fontsize=7)
    return _save(fig, out / "example_min_shaking_paminsa.png")


FIGURES = {f.__name__: f for f in (shaking_wrench_from_urdf, balance_arm, control_against_simulation,
                                   run_paper_case, min_shaking_paminsa)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE / "images")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name, draw in FIGURES.items():
        path = draw(args.out)
        print(f"{name}: {path} ({path.stat().st_size // 1024} kB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
