"""The files of an identification: the identified model (URDF and case file), summary.json, plots.

* ``identified.urdf``: the mechanism with the identified bodies (`mechbal.export.urdf`: names,
  frames, limits kept; one ``<inertial>`` per moving link);
* ``identified.toml``: the same model as a case file's ``[mechanism]`` table;
* ``summary.json``: `IdentificationResult.summary` under the common header (command
  ``identify``; docs/summary.md);
* ``validation.png``: measured and predicted torques of the first validation log, per joint, for
  the identified, CAD and CAD-with-friction models; ``parameters.png``: the base parameters
  with their standard deviations.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbal.identify.fitting import IdentificationResult

__all__ = ["write_identified", "plot_validation", "plot_parameters"]


def plot_validation(result: IdentificationResult, path: str | Path) -> Path:
    from mechbal.report import _pyplot

    plt = _pyplot()

    v = result.validation
    tr = v.trace
    n = len(v.joint_names)
    fig, axes = plt.subplots(n, 1, figsize=(9, 1.7 * n + 0.8), sharex=True, squeeze=False)
    styles = {"identified": ("C0", "-"), "cad": ("C3", ":"), "cad_friction": ("C2", "--")}
    for j, ax in enumerate(axes[:, 0]):
        ax.plot(tr["t"], tr["measured"][:, j], color="0.6", lw=1.0, label="measured")
        for key, (color, ls) in styles.items():
            rms = v.rms_torque_error[key][v.joint_names[j]]
            ax.plot(tr["t"], tr[key][:, j], color=color, ls=ls, lw=1.0, label=f"{key} (RMS {rms:.3g})")
        ax.set_ylabel(f"{v.joint_names[j]}\n[N m]", fontsize=7)
        ax.legend(fontsize=6, loc="upper right", ncol=4)
    axes[-1, 0].set_xlabel("t [s]")
    title = "held-out log" if v.held_out else "identification log (no held-out log given)"
    fig.suptitle(f"{result.mechanism.name}: measured and predicted joint torques, {title} "
                 f"{Path(v.logs[0]).name}", fontsize=9)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_parameters(result: IdentificationResult, path: str | Path) -> Path:
    from mechbal.report import _pyplot

    plt = _pyplot()

    names = result.base.names
    x = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(max(6.0, 0.18 * len(names) + 2), 4))
    ax.bar(x, result.base_values, yerr=3 * result.base_std, color="C0", ecolor="k", capsize=1.5,
           label="identified (error bars: 3 standard deviations)")
    ax.plot(x, result.base.project(np.concatenate([result.cad_parameters,
                                                   np.zeros(len(result.parameter_names) - result.cad_parameters.size)])),
            "r.", label="CAD (friction 0)")
    ax.set_xticks(x)
    ax.set_xticklabels(names, rotation=90, fontsize=5)
    ax.set_ylabel("base parameter [SI]")
    ax.legend(fontsize=7)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def write_identified(result: IdentificationResult, out: str | Path, *, plots: bool = True) -> dict:
    """Write the files of the module docstring into the folder ``out`` (created); returns the
    summary written."""
    from mechbal.export.toml import mechanism_table, toml_text
    from mechbal.export.bodies import write_summary

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    mech = result.mechanism
    files = []
    mech.to_urdf(out / "identified.urdf", name=mech.name)
    files.append("identified.urdf")
    header = (f"{mech.name}: identified by `mechbal identify` from {', '.join(Path(s).name for s in result.data_notes)}"
              f"\nInertial parameters physically consistent (pseudo-inertia >= 0); friction in summary.json.")
    case = {"case": {"name": mech.name, "kind": "mechanism", "title": f"{mech.name} (identified)"},
            "mechanism": mechanism_table(mech)}
    (out / "identified.toml").write_text(toml_text(case, header))
    files.append("identified.toml")
    if plots:
        plot_validation(result, out / "validation.png")
        plot_parameters(result, out / "parameters.png")
        files += ["validation.png", "parameters.png"]
    summary = {"case": mech.name, "files": files, "kind": "identify", **result.summary()}
    write_summary(out / "summary.json", summary, command="identify")
    return summary
