"""The built-in paper cases that ``mechbal balance`` reads besides the general kinds: PAMINSA
(``kind = "paminsa"``) and the disc cases (``kind = "discs"``), each as a
:class:`mechbal.balance.run.BalanceCase` on the general model.

* ``paminsa``: the mechanism of :func:`mechbal.papers.paminsa.paminsa_mechanism` built from the
  case's ``[geometry]``, ``[masses]``, ``[inertias]``, unbalanced and without the zero-mass
  placeholder counterweights (so the ``[balance]`` slots may carry the paper's names
  ``leg1.CP1_atA`` ...); the trajectory rest-to-rest in the actuated joints between the actuator
  positions of the case's start and end platform positions, wrist still at its initial angles
  (as ``cases/paminsa-linkage.toml``), 501 samples, the closed form's assembly as initial guess.
* ``discs`` (``discs-3r``, ``discs-spatial``, ``scara``): the statically balanced arm of
  :func:`mechbal.papers.discs.disc_design_mechanism` without discs, its links' inertias as the
  case gives them (``[inertia]``: the spatial arm's J_y2, J_y3 are then what the moment method's
  inertia slots choose); ``five-bar``: the leg-wise statically balanced parallelogram 5R of
  :func:`mechbal.papers.five_bar.five_bar_design_mechanism`. The trajectory is the case's quintic.
* ``rpsp``: the 3(RPSP)-S robot with its extra linkage and without the counterweight bodies of
  ``[balancing]``, driven by the platform's spherical joint (the loop solve is then its inverse
  kinematics); the default design variables (without a ``[balance]`` table) are those bodies as
  fixed-position slots (their centres of mass: only the masses are unknown); the trajectory is
  the paper's platform motion of ``[motion]`` over ``duration``. ``balanced.toml`` is the case
  itself with the sized masses (``mechbal run`` runs it).

* ``orthoglide``: the Orthoglide 5-axis (Martini et al. 2015) as the runner builds it
  (:class:`mechbal.cases.orthoglide.Orthoglide`: the case's ``[mechanism]`` without its springs,
  the ``[[springs]]`` anchors as named frames, the ``[roles]`` initial guess as assembly mode).
  Without a ``[balance]`` table, ``--method springs`` sizes the ``[[springs]]`` slots (zero free
  length; a ``rate`` given there stays fixed) exactly as the runner does
  (:meth:`~mechbal.cases.orthoglide.Orthoglide.sizing`): static balance C^T (G + K) = 0 at the
  sliders' positions (eq 1) of the ``[workspace]`` grid, loops closed to the runner's
  ``CLOSURE_TOLERANCE``; the rates are then eqs 18-19 (2.510052 / 11.130577 N/mm). The
  trajectory is a rest-to-rest quintic move of the three actuated sliders from the positions of
  the workspace cube's corner C - edge/2 (1, 1, 1) to those of the opposite corner C + edge/2
  (1, 1, 1) in 2 s, 201 samples (the platform moves near the cube's diagonal). ``balanced.toml``
  is the case itself (kind ``orthoglide``) with the sized rates as ``rate`` of its ``[[springs]]``
  (``mechbal run`` puts them on the model as fixed rates); a design the kind cannot carry
  (``--design`` springs that are not the case's ``[[springs]]`` with zero free length, one spring,
  no pulley, their anchors) is written as a kind ``mechanism`` case instead (the mechanism with
  its springs as ``[[mechanism.springs]]`` and the trajectory).

A ``--design FILE`` replaces the ``[balance]`` table (and its ``[trajectory]``, in actuated
joints, the case's trajectory).
"""
from __future__ import annotations

import copy
from typing import Any

import numpy as np


def _trajectory(bc_mech, design_cfg, default: dict, guess):
    from mechbal.balance.run import _trajectory_motion

    if design_cfg is not None and design_cfg.trajectory is not None:
        tr = design_cfg.trajectory
        g = getattr(tr, "initial_guess", None)
        guess = guess if g is None else np.array(g, float)
        t, motion, tt = _trajectory_motion(bc_mech, tr)
    else:
        t, motion, tt = _trajectory_motion(bc_mech, default)
    if guess is not None:
        tt["initial_guess"] = [float(x) for x in guess]
    return t, motion, tt, guess


def paminsa_case(cfg, raw: dict, table: Any, design_cfg):
    """The BalanceCase of a ``paminsa`` case (module docstring)."""
    from mechbal.balance.run import BalanceCase
    from mechbal.cases.paminsa import parameters_from_config
    from mechbal.papers.paminsa import paminsa_actuated_motion, paminsa_initial_guess, paminsa_mechanism

    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    params = parameters_from_config(cfg)
    full = paminsa_mechanism(params, False, name=f"{name} (unbalanced)")
    # the case file has no counterweights: drop their zero-mass placeholders, keep everything else
    keep = [b for b in full.bodies if not (b.kind == "counterweight" and b.mass == 0.0)]
    mech = full.with_bodies(keep, replace=True)
    tr = cfg.trajectory
    wrist = np.asarray(cfg.wrist.initial_angles, float)
    ends = np.array([tr.start, tr.end], float)
    qa, _, _ = paminsa_actuated_motion(mech, params, ends, np.zeros((2, 3)), np.zeros((2, 3)), np.tile(wrist, (2, 1)))
    guess = paminsa_initial_guess(mech, params, ends[0], wrist)
    default = {"law": tr.law, "start": qa[0].tolist(), "end": qa[1].tolist(), "duration": tr.duration,
               "samples": 501}
    t, motion, tt, guess = _trajectory(mech, design_cfg, default, guess)
    return BalanceCase(name, title, mech, table, t, motion, tt, guess, raw, "paminsa", [])


def discs_case(cfg, raw: dict, table: Any, design_cfg):
    """The BalanceCase of a ``discs`` case (module docstring)."""
    from mechbal.balance.run import BalanceCase
    from mechbal.cases.discs import parameters_from_config
    from mechbal.papers import discs as dz

    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    kind = cfg.case.mechanism
    p = parameters_from_config(kind, cfg)
    d = dict(dz.design(kind, p, True))
    tr = cfg.trajectory
    default = {"law": "quintic", "start": list(tr.start), "end": list(tr.end), "duration": tr.duration,
               "samples": tr.samples}
    if kind == "fivebar":
        from mechbal.papers.five_bar import five_bar_design_mechanism, five_bar_initial_guess

        mech = five_bar_design_mechanism(d, name=f"{name} (statically balanced)")
        start = (design_cfg.trajectory.start if design_cfg is not None and design_cfg.trajectory is not None
                 else tr.start)
        guess = five_bar_initial_guess(mech, d, start)
    else:
        from mechbal.papers.discs import disc_design_mechanism

        d["discs"] = False
        for i in (1, 2, 3):   # the links' inertias as the case gives them (the method may choose some)
            for axis in "xyz":
                d[f"J{axis}{i}"] = p[f"J{axis}{i}"]
        mech = disc_design_mechanism(kind, d, name=f"{name} (statically balanced, no discs)")
        guess = None
    t, motion, tt, guess = _trajectory(mech, design_cfg, default, guess)
    return BalanceCase(name, title, mech, table, t, motion, tt, guess, raw, "discs", [])


def rpsp_case(cfg, raw: dict, table: Any, design_cfg):
    """The BalanceCase of an ``rpsp`` case (module docstring)."""
    from mechbal.balance.run import BalanceCase
    from mechbal.cases import rpsp as runner
    from mechbal.errors import ConfigError
    from mechbal.mechanism import Mechanism

    if design_cfg is not None and design_cfg.trajectory is not None:
        raise ConfigError("trajectory", "the rpsp case moves its platform by the paper's law ([motion]); "
                                        "a --design file gives only [balance]", has_value=False)
    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    mo, bal = cfg.motion, cfg.balancing
    names = [n for key in ("m_P", "m_N", "m_F", "platform") for n in getattr(bal, key)]
    full = Mechanism.from_spec(runner.driven_by_platform(cfg.spec, mo.platform), name=name)
    slots, bare = runner.counterweight_slots(full, cfg.spec, names)
    bare.name = f"{name} (without its counterweights)"
    if len(mo.initial_guess) != len(cfg.spec.independent_joints):
        raise ConfigError("motion.initial_guess", "must have one value per joint coordinate", list(mo.initial_guess))
    by_name = dict(zip(cfg.spec.independent_joints, mo.initial_guess))
    guess = np.array([by_name[n] for n in bare.joint_names], float)
    t = np.linspace(0.0, mo.duration, mo.samples)
    phi, dphi, ddphi = runner.platform_motion(mo, t)
    order = {f"{mo.platform}_z": 0, f"{mo.platform}_y": 1, f"{mo.platform}_x": 2}
    cols = [order[n] for n in bare.actuated_names]
    motion = (phi[:, cols], dphi[:, cols], ddphi[:, cols])
    # the sample box of static / force: the range the motion sweeps
    tt = {"law": "paper: phi_x = A sin(2 pi t / T), phi_y = 0, phi_z = B sin(f pi t / T)",
          "start": motion[0].min(axis=0).tolist(), "end": motion[0].max(axis=0).tolist(),
          "duration": mo.duration, "samples": mo.samples, "initial_guess": guess.tolist()}
    return BalanceCase(name, title, bare, table, t, motion, tt, guess, raw, "rpsp", slots)


def orthoglide_case(cfg, raw: dict, table: Any, design_cfg):
    """The BalanceCase of an ``orthoglide`` case (module docstring)."""
    from mechbal.balance.run import BalanceCase
    from mechbal.cases import orthoglide as runner
    from mechbal.papers import orthoglide as paper

    name, title = cfg.case.name, cfg.case.title or cfg.case.name
    o = runner.Orthoglide(cfg)
    mech = o.mech
    mech.name = f"{name} (without its springs)"
    ws = cfg.workspace
    grid = runner.workspace_grid(ws.center, ws.edge, ws.grid)
    slots, rho, options = o.sizing(grid)
    corners = np.asarray(ws.center, float) + np.outer([-1.0, 1.0], np.full(3, ws.edge / 2))
    ends = o.rho(corners)
    default = {"law": "quintic", "start": ends[0].tolist(), "end": ends[1].tolist(), "duration": 2.0,
               "samples": 201}
    t, motion, tt, guess = _trajectory(mech, design_cfg, default, o.q_guess)
    t1 = paper.PAPER_TABLE1["theoretical"]
    notes = {
        "trajectory": ("rest-to-rest quintic of the actuated sliders (rho_x, rho_y, rho_z) between their positions "
                       "(eq 1) at the workspace cube's corners C - edge/2 (1, 1, 1) and C + edge/2 (1, 1, 1)"
                       if design_cfg is None or design_cfg.trajectory is None else "the --design file's [trajectory]"),
        "sizing_samples": (f"the runner's: the sliders' positions of the {ws.grid}^3 workspace grid (centre "
                           f"{list(ws.center)} m, edge {ws.edge} m), closure tolerance {runner.CLOSURE_TOLERANCE:g} m"
                           if table is None else "the [balance] table's"),
        "paper_spring_rates_N_per_mm": {"K_D": t1["K_D_N_per_mm"], "K_P": t1["K_P_N_per_mm"]},
        "roles": {"K_D": cfg.roles.distal_spring, "K_P": cfg.roles.proximal_spring},
    }
    return BalanceCase(name, title, mech, table, t, motion, tt, guess, raw, "orthoglide", [],
                       default_design={"springs": (slots, rho, options)}, notes=notes)


def orthoglide_written_back(bc, result) -> dict | None:
    """The case itself with the sized rates as ``[[springs]]`` ``rate`` (the TOML data), or None
    when the sized springs are not the case's (module docstring)."""
    data = copy.deepcopy(bc.raw)
    data.pop("balance", None)
    by_name = {s["name"]: s for s in data.get("springs", [])}
    slots = {s.name: s for s in (bc.default_design or {}).get("springs", ([],))[0]}
    sized = [sp for sp in result.balanced.springs if sp.name not in set(bc.mechanism.spring_names)]
    if not sized or {sp.name for sp in sized} != set(by_name):
        return None
    for sp in sized:
        slot = slots.get(sp.name)
        if (slot is None or sp.free_length != 0.0 or sp.preload != 0.0 or sp.count != 1 or sp.pulley_ratio != 1.0
                or sp.link_a != slot.link_a or sp.link_b != slot.link_b
                or not np.allclose(sp.anchor_a, slot.anchor_a, rtol=0, atol=1e-15)
                or not np.allclose(sp.anchor_b, slot.anchor_b, rtol=0, atol=1e-15)):
            return None
        by_name[sp.name]["rate"] = float(sp.rate)
    return data
