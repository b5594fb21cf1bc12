"""Runner for ``kind = "serial_chain"`` (and its alias ``kind = "mechanism"``): a chain from its
TOML description (:mod:`mechbal.spec`) moving along a rest-to-rest trajectory; shaking force and
moment, base reaction and joint torques."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbal import report
from mechbal.cases import register
from mechbal.config import chain_model, trajectory_from_config
from mechbal.export import write_bodies, write_summary
from mechbal.schema import validate_case
from mechbal.simulate import run_chain


@register("mechanism")
@register("serial_chain")
def run(config, out: Path) -> dict:
    case = validate_case(config, warn=False)
    model = chain_model(case.spec)
    traj, t = trajectory_from_config(case.trajectory, model.dof)
    r = run_chain(model, traj, t)
    F, M = r.wrench["force"], r.wrench["moment"]
    write_bodies(out / "bodies_nominal.npz", t=t, names=r.names, mass=r.mass,
                 inertia_body=r.inertia_body, com=r.bodies["com"], rotation=r.bodies["rotation"],
                 shaking_force=F, shaking_moment=M, q=r.q, qd=r.qd, qdd=r.qdd, torque=r.torque)
    report.plot_wrench(out / "shaking_wrench.png", t, {"nominal": (F, M)},
                       title=case.case.title or case.case.name)
    report.plot_series(out / "joint_torques.png", t, {"KDL RNE": r.torque}, r.names, "torque",
                       title="joint torques")
    summary = {
        "case": case.case.name,
        "kind": case.case.kind,
        "dof": model.dof,
        "duration_s": float(traj.duration),
        "samples": int(len(t)),
        "law": traj.law.name,
        "variants": ["nominal"],
        "peak_shaking_force_N": {"nominal": report.peak_abs(F)},
        "peak_shaking_moment_Nm": {"nominal": report.peak_abs(M)},
        "peak_joint_torque": {"nominal": report.peak_abs(r.torque)},
        "rms_joint_torque": {"nominal": np.sqrt(np.mean(r.torque ** 2, axis=0))},
        "total_mass_kg": float(np.sum(r.mass)),
        "files": ["bodies_nominal.npz", "shaking_wrench.png", "joint_torques.png"],
    }
    write_summary(out / "summary.json", summary)
    print(report.table(
        [["peak shaking force [N]", *report.peak_abs(F)],
         ["peak shaking moment about O [N m]", *report.peak_abs(M)]],
        ["quantity", "x", "y", "z"]))
    print(report.table([["peak torque", *report.peak_abs(r.torque)],
                        ["RMS torque", *np.sqrt(np.mean(r.torque ** 2, axis=0))]],
                       ["joint torque [N m or N]", *r.names]))
    return summary
