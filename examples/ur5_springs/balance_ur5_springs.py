"""Spring balancing of a UR5-like arm (examples/ur5_springs/ur5_like.toml): three zero-free-length
springs (shoulder, forearm, elbow coupling) sized by mechbal.balance.springs over 2000 random poses,
then a catalogue cluster for each; plots the static joint torques before and after along the
case's quintic motion.

    .venv/bin/python examples/ur5_springs/balance_ur5_springs.py [--out DIR]
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mechbal  # noqa: E402
from mechbal.balance import SpringSlot  # noqa: E402
from mechbal.balance import springs  # noqa: E402

HERE = Path(__file__).resolve().parent
SLOTS = [  # anchors in the DH frames named in the TOML file
    SpringSlot("shoulder", "dh1", (0.0, 0.15, 0.0), "dh2", (0.225, 0.0, 0.0)),   # 0.15 m above the shoulder axis -> upper arm
    SpringSlot("forearm", "dh1", (0.0, 0.10, 0.0), "dh3", (0.19225, 0.0, 0.0)),  # 0.10 m above it -> forearm
    SpringSlot("elbow", "dh2", (0.325, 0.0, 0.0), "dh3", (0.49225, 0.0, 0.0)),   # upper arm -> behind the elbow
]


def main(out: Path) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    arm = mechbal.Mechanism.from_toml(HERE / "ur5_like.toml")
    rng = np.random.default_rng(0)
    workspace = rng.uniform(-np.pi, np.pi, (2000, arm.dof))
    result = springs.balance(arm, SLOTS, workspace)
    clusters = springs.select_for_result(arm, result, workspace, offsets={"shoulder": ("a", 1), "forearm": ("a", 1)},
                                         rate_tolerance=0.03)
    # the case's quintic motion, statically
    t = np.linspace(0.0, 1.0, 201)
    s = 10 * t ** 3 - 15 * t ** 4 + 6 * t ** 5
    start, end = np.array([0.0, -1.2, 1.0, 0.0, 0.0, 0.0]), np.array([1.0, -0.2, -0.8, 0.5, 0.5, 0.0])
    q = start + np.outer(s, end - start)
    before = arm.gravity_torque(q)
    after = before + springs.spring_torque(arm, result.elements, q)
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), sharex=True)
    for ax, j in zip(axes, (1, 2, 3)):
        ax.plot(t * 2.0, before[:, j], label="unbalanced (gravity)")
        ax.plot(t * 2.0, after[:, j], "--", label="with the 3 springs")
        ax.set_title(arm.joint_names[j])
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("static joint torque [N m]")
    axes[0].legend(loc="best", fontsize=8)
    fig.suptitle("UR5-like arm: static torque on its quintic motion, before and after spring balancing "
                 "(residual: the wrist's off-axis centres of mass)", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "ur5_springs.png", dpi=110)
    summary = result.summary()
    summary["clusters"] = {k: [c.summary() for c in v[:3]] for k, v in clusters.items()}
    summary["trajectory_static_torque_peak"] = {"before": np.max(np.abs(before), 0).tolist(),
                                                "after": np.max(np.abs(after), 0).tolist()}
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    return summary


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=HERE / "out")
    s = main(ap.parse_args().out)
    for name, d in s["design"].items():
        print(f"{name:9s} rate {d['rate_N_per_mm']:.4f} N/mm  peak tension {d['peak_tension']:.1f} N")
    print("static torque peak before", np.round(s["trajectory_static_torque_peak"]["before"], 3))
    print("static torque peak after ", np.round(s["trajectory_static_torque_peak"]["after"], 3))
    print("workspace residual", s["residual"], "of", s["residual_before"], s["limited_by"])
    for name, c in s["clusters"].items():
        print(name, c[:1])
