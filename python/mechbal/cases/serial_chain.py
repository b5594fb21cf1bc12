"""Runner for ``kind = "serial_chain"``: a chain from its TOML description moving along a
rest-to-rest trajectory; shaking force and moment, base reaction (with gravity) and joint torques."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbal import progress, report
from mechbal.cases import register
from mechbal.config import chain_from_config, require, trajectory_from_config
from mechbal.export import write_bodies, write_summary
from mechbal.simulate import run_chain


@register("serial_chain", stages=3)
def run(config: dict, out: Path) -> dict:
    model = chain_from_config(require(config, "mechanism", ""))
    traj, t = trajectory_from_config(require(config, "trajectory", ""), model.dof)
    progress.stage("kinematics, shaking wrench, inverse dynamics")
    r = run_chain(model, traj, t)
    F, M = r.wrench["force"], r.wrench["moment"]
    progress.stage("bodies file and plots")
    # the wrench the base exerts on the chain (KDL, gravity included, moment about O)
    R_F, R_M = r.support_force, r.support_moment
    write_bodies(out / "bodies_nominal.npz", t=t, names=r.names, mass=r.mass,
                 inertia_body=r.inertia_body, com=r.bodies["com"], rotation=r.bodies["rotation"],
                 shaking_force=F, shaking_moment=M, q=r.q, qd=r.qd, qdd=r.qdd, torque=r.torque,
                 base_reaction_force=R_F, base_reaction_moment=R_M)
    title = config["case"].get("title", config["case"]["name"])
    report.plot_wrench(out / "shaking_wrench.png", t, {"nominal": (F, M)}, title=title,
                       caption="Shaking force dP/dt and shaking moment dH_O/dt (about the base "
                               "origin O, inertial part only: no gravity) of all links along the "
                               "trajectory, from mechbal's rigid-body kinematics.")
    report.plot_wrench(out / "base_reaction.png", t, {"with gravity": (R_F, R_M),
                                                      "shaking wrench (no gravity)": (F, M)},
                       title=f"{title}: base reaction", force="base reaction force",
                       moment="base reaction moment",
                       caption="Wrench the base exerts on the chain (KDL recursive Newton-Euler, "
                               "gravity included, moment about O) against the shaking wrench "
                               "(inertial only): they differ by the weight, -m g and -sum m_i "
                               "c_i x g.")
    types = [j.type.name for j in model.joints]
    report.plot_series(out / "joint_torques.png", t, {"KDL RNE": r.torque},
                       [f"{n} ({ty})" for n, ty in zip(r.names, types)],
                       ["torque [N m]" if ty == "revolute" else "force [N]" for ty in types],
                       title=f"{title}: joint torques",
                       caption="Actuator torque (revolute) or force (prismatic) of each joint "
                               "along the trajectory, gravity included (KDL recursive "
                               "Newton-Euler).")
    progress.stage("summary")
    summary = {
        "case": config["case"]["name"],
        "kind": "serial_chain",
        "dof": model.dof,
        "duration_s": float(traj.duration),
        "samples": int(len(t)),
        "law": traj.law.name,
        "variants": ["nominal"],
        "peak_shaking_force_N": {"nominal": report.peak_abs(F)},
        "peak_shaking_moment_Nm": {"nominal": report.peak_abs(M)},
        "peak_joint_torque": {"nominal": report.peak_abs(r.torque)},
        "rms_joint_torque": {"nominal": np.sqrt(np.mean(r.torque ** 2, axis=0))},
        "peak_base_reaction_force_N": {"nominal": report.peak_abs(R_F)},
        "peak_base_reaction_moment_Nm": {"nominal": report.peak_abs(R_M)},
        "base_reaction": "wrench the base exerts on the chain, gravity included, moment about O",
        "total_mass_kg": float(np.sum(r.mass)),
        "files": ["bodies_nominal.npz", "shaking_wrench.png", "base_reaction.png",
                  "joint_torques.png"],
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
