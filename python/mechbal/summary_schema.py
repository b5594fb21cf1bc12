"""The JSON Schema of ``summary.json``: one documented format for every case and command.

Every ``summary.json`` that mechbal writes (``mechbal run`` of every case kind, ``mechbal
balance``, ``mechbal verify``, ``mechbal sweep``) starts with ``schema_version`` and ``command``
(``mechbal.export.write_summary`` puts them there) and follows the schema shipped as
``mechbal/cases/summary.schema.json`` (JSON Schema 2020-12), generated from this module:

    python -m mechbal.summary_schema > python/mechbal/cases/summary.schema.json

Conventions (docs/summary.md):

- SI units, named once here (each property's ``unit`` and ``description``), never in the keys:
  ``peak_shaking_force``, not ``peak_shaking_force_N``. Values kept in a paper's own non-SI unit
  (the Orthoglide's mm and N/mm) and percentages say so in their key (``_mm``, ``_N_per_mm``,
  ``_pct``), so that nobody reads them as SI; an echo of a case-file setting keeps the case
  file's key (``rate_hz``).
- The metric names are the sweeps' (`mechbal.sweep.metrics`): ``<statistic>_<quantity>`` with
  statistic ``peak`` or ``rms`` and quantity ``shaking_force``, ``shaking_moment``,
  ``joint_torque``, ``gravity_torque``, ``static_torque``, ``base_reaction_force``,
  ``base_reaction_moment``. In a run's summary they are given per variant (``nominal``,
  ``unbalanced``, ``balanced``, ...) and per component (x, y, z) or per actuated joint: the peak
  of each absolute value; a sweep's column is the norm's.
- Unknown top-level keys are errors (``unevaluatedProperties: false``): a key that is not in the
  schema is a key that a reader cannot rely on.

**Extending it.** A new field of a general summary goes into the tables below; a case kind with
its own summary (a paper's runner) registers its top-level fields with `register_summary` from
its ``schema.py``:

    register_summary("run", "my_kind", {
        "peak_shaking_force": PER_VARIANT_FORCE,          # a shared metric
        "counterweight_masses": number_map("kg", "sized counterweights by name"),
        "closed_form": detail("the paper's closed form beside the general method"),
    })

then regenerate the file (above); ``tests/python/test_summary_schema.py`` checks that the shipped
file is the generated one and validates every summary.json the test suite writes.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import copy
import json
import sys
from typing import Any

from mechbal.export.bodies import SUMMARY_COMMANDS, SUMMARY_SCHEMA_VERSION

Schema = dict[str, Any]

NUMBER: Schema = {"type": ["number", "null"]}


# ---- building blocks --------------------------------------------------------------------------

def number(unit: str | None = None, description: str = "") -> Schema:
    """A number (``null`` where it was not finite: listed under ``non_finite_values``)."""
    out: Schema = {"type": ["number", "null"]}
    if description:
        out["description"] = description
    if unit:
        out["unit"] = unit
    return out


def integer(description: str = "") -> Schema:
    return {"type": "integer", "description": description} if description else {"type": "integer"}


def string(description: str = "") -> Schema:
    return {"type": "string", "description": description} if description else {"type": "string"}


def boolean(description: str = "") -> Schema:
    return {"type": "boolean", "description": description} if description else {"type": "boolean"}


def strings(description: str = "") -> Schema:
    out: Schema = {"type": "array", "items": {"type": "string"}}
    if description:
        out["description"] = description
    return out


def numbers(unit: str | None = None, description: str = "") -> Schema:
    """A list of numbers (a vector: x, y, z components, or one value per joint)."""
    out: Schema = {"type": "array", "items": NUMBER}
    if description:
        out["description"] = description
    if unit:
        out["unit"] = unit
    return out


def number_map(unit: str | None = None, description: str = "") -> Schema:
    """An object of named numbers (by body, by joint, by variant)."""
    out: Schema = {"type": "object", "additionalProperties": NUMBER}
    if description:
        out["description"] = description
    if unit:
        out["unit"] = unit
    return out


def per_variant(unit: str | None, description: str, *, vector: bool = True) -> Schema:
    """``{variant: value}``: a vector (components or joints) or a number per variant."""
    return {"type": "object", "description": description + " Per variant (nominal, unbalanced, "
            "balanced, ...).", **({"unit": unit} if unit else {}),
            "additionalProperties": {"type": "array", "items": NUMBER} if vector else NUMBER}


def detail(description: str) -> Schema:
    """A nested object whose inner keys are the runner's (documented in its docstring and the
    paper's derivation page); its numbers follow the same rules (SI, no unit in the key)."""
    return {"type": "object", "description": description}


def anything(description: str) -> Schema:
    return {"description": description}


# ---- the shared metrics -------------------------------------------------------------------------

PER_VARIANT_FORCE = per_variant("N", "Peak of each component (x, y, z in O) of the shaking force "
                                "dP/dt along the trajectory.")
PER_VARIANT_MOMENT = per_variant("N m", "Peak of each component of the shaking moment dH_O/dt "
                                 "about the base origin O along the trajectory.")
METRICS: dict[str, Schema] = {
    "peak_shaking_force": PER_VARIANT_FORCE,
    "peak_shaking_moment": PER_VARIANT_MOMENT,
    "rms_shaking_force": per_variant("N", "RMS of each component of the shaking force."),
    "rms_shaking_moment": per_variant("N m", "RMS of each component of the shaking moment about O."),
    "peak_joint_torque": per_variant("N m or N", "Peak |tau| of each actuated joint along the "
                                     "trajectory (gravity included; N for a prismatic joint)."),
    "rms_joint_torque": per_variant("N m or N", "RMS of tau of each actuated joint along the "
                                    "trajectory."),
    "peak_gravity_torque": per_variant("N m or N", "Peak |gravity torque| of each actuated joint "
                                       "(over the poses the case samples)."),
    "peak_static_torque": per_variant("N m or N", "Peak |torque that holds each pose still| "
                                      "(gravity plus springs) of each actuated joint."),
    "peak_base_reaction_force": per_variant("N", "Peak of each component of the force the base "
                                            "exerts on the mechanism, gravity included."),
    "peak_base_reaction_moment": per_variant("N m", "Peak of each component of the base reaction "
                                             "moment about O, gravity included."),
}

# ---- the header every summary has ------------------------------------------------------------------

HEADER: dict[str, Schema] = {
    "schema_version": {"const": SUMMARY_SCHEMA_VERSION,
                       "description": "Version of this schema (integer; a new one renames or "
                                      "removes keys, docs/summary.md lists the changes)."},
    "command": {"enum": list(SUMMARY_COMMANDS), "description": "The mechbal command that wrote "
                "the file (``run`` also for ``demo`` and ``run --engine mujoco``)."},
    "case": string("Case name (built-in name or the file's [case] name)."),
    "files": strings("Files written beside summary.json."),
    "non_finite_values": {"type": "array", "description": "Numbers that were not finite, written "
                          "as null: their dotted field and value.",
                          "items": {"type": "object", "required": ["field", "value"],
                                    "additionalProperties": False,
                                    "properties": {"field": string(), "value": string()}}},
    "notes": anything("What the run says about itself (free text or an object of texts)."),
}

# ---- general summaries --------------------------------------------------------------------------

_CONTROL = {"type": "object", "additionalProperties": False, "description": "The controller of a case "
            "with [control] (its settings echo the case file's keys): reactionless, or a joint controller "
            "(computed_torque, decoupled) in closed loop.",
            "properties": {
                "kind": string(), "balancing_joints": strings(), "cancel": strings(),
                "integrator": string(), "rate_hz": number("Hz", "controller rate (the case's rate_hz)"),
                "damping": number(None, "damped least squares damping"),
                "ticks": integer(), "singular_ticks": integer(), "saturated_ticks": integer(),
                "max_condition": number(None, "largest condition number of the balancing joints' "
                                        "momentum matrix"),
                "peak_balancing_rate": numbers("rad/s or m/s", "peak |rate| of each balancing joint"),
                "mode": string("operational space (task_frame): the reaction null space"),
                "task_frame": string(), "task_rows": strings(),
                "variants": detail("What each variant is (operational-space mode)."),
                "frame_path_error": detail("Largest distance [m] (and angle [rad], tracked rows) of the "
                                           "task frame from its path, per variant."),
                "peak_joint_rate": detail("Peak |rate| of each joint [rad/s or m/s], per variant."),
                "feed_forward": detail("The acceleration feed-forward against the stored motion's "
                                       "acceleration [rad/s^2] and its predicted moment [N m]."),
                # computed_torque and decoupled: the closed loop
                "sampling": string("zero_order_hold: the torque of a tick is held over the RK4 step"),
                "kp": numbers("1/s^2"), "kd": numbers("1/s"),
                "k": numbers("kg m^2 or kg", "decoupled: the diagonal of the balanced mass matrix"),
                "torque_limit_in_force": {"type": ["array", "null"], "items": NUMBER,
                                          "description": "|tau| limit per joint [N m or N] (declared effort "
                                                         "limits and torque_limit; null: none)"},
                "steps_completed": integer(), "out_of_range_ticks": integer(),
                "peak_tracking_error": numbers("rad or m", "peak |q_des - q| of each actuated joint"),
                "peak_joint_torque": numbers("N m or N", "peak |tau| the controller commanded, per joint")}}

#: the verdict of a controlled run (`mechbal.verdict`): run, run --engine mujoco, verify
VERDICT: dict[str, Schema] = {
    "goal": detail("What the controlled run was asked (mechbal.verdict.goal): kind, statuses, the cancelled "
                   "components with their tolerance (residual, floor), the tracking criteria with theirs, the "
                   "declared limits in force per joint (velocity [rad/s or m/s], effort [N m or N]) and the "
                   "tolerance table in force."),
    "ok": boolean("True only if every criterion of the goal held (every tick ok, no declared limit exceeded, "
                  "each cancelled component and the tracking within tolerance)."),
    "limited_by": {"type": "array", "description": "Each criterion that failed, with its numbers: "
                   "criterion (status, limit, residual, tracking, steps), message, and joint, first_tick, "
                   "ticks, peak_demand, limit, ... as they apply (empty when ok).",
                   "items": {"type": "object"}},
    "feasibility": detail("Reactionless cases, before the run (mechbal.control.feasibility): feasible, duration "
                          "[s], min_duration [s] (the shortest duration of the same motion keeping every declared "
                          "limit), each limit's peak demand against it, the peak velocity, acceleration and torque "
                          "per joint; fitted_duration [s] with --fit-duration."),
    "cancelled_residual": detail("Per cancelled component (force_x ... moment_z): its uncontrolled and controlled "
                                 "peaks [N or N m], their fraction, the reduction [%] and the allowed residual."),
}

RUN_MECHANISM: dict[str, Schema] = {
    "kind": string("[case] kind: serial_chain, mechanism or urdf (a URDF file)."),
    "dof": integer("Degrees of freedom (moving joints, gears and loops not counted out)."),
    "actuated": strings("Actuated joints, in the order of the per-joint values."),
    "closed": boolean("True for a mechanism with loop closures."),
    "duration": number("s", "Duration of the trajectory."),
    "samples": integer("Instants along the trajectory."),
    "law": string("Time law of the trajectory (quintic, cycloidal, constant_speed, ...)."),
    "speed": numbers("rad/s or m/s", "Speed of each actuated joint (law constant_speed)."),
    "rpm": numbers("rev/min", "The same speeds in turns per minute (the case file's rpm key)."),
    "revolutions": number(None, "Turns of the fastest joint over the run (law constant_speed)."),
    "variants": strings("The variants the per-variant values name."),
    **{k: METRICS[k] for k in ("peak_shaking_force", "peak_shaking_moment", "peak_joint_torque",
                               "rms_joint_torque", "peak_base_reaction_force",
                               "peak_base_reaction_moment", "peak_static_torque")},
    "base_reaction": string("Definition of the base reaction."),
    "static_torque": string("Definition of the static torque (springs)."),
    "springs": strings("The springs of the model (their forces are in the joint torques)."),
    "total_mass": number("kg", "Mass of every body."),
    "loops": detail("Loop solve along the trajectory: min_rcond, singular_instants, "
                    "max_closure_residual [m], max_newton_iterations."),
    "control": _CONTROL,
    "plan": detail("law = min_shaking (mechbal.plan): objective, weights, moment_point [m], value and "
                   "quintic_value ([N] or [N m]: RMS or peak; weighted: the weighted sum of mean squares), "
                   "reduction (1 - value / quintic_value), ok, message, iterations, control_points, "
                   "active_limits (kind, joint, time [s], value, limit), limits_checked_on (instants), "
                   "metrics (rms_ and peak_shaking_force [N] and _shaking_moment [N m] of the norm, "
                   "rms_joint_torque [N m] of the norm over the actuated joints, of planned and quintic), "
                   "com_law (the centre-of-mass law's profile, joints and the same metrics, or "
                   "not_applicable: why)."),
    "passive": detail("[control] kind = passive: rate_hz, integrator, q0, v0, initial_energy [J], "
                      "max_energy_drift [J], kinetic_energy_swing [J], relative_energy_drift, "
                      "energy (definition), final_q, final_v."),
    "shaking_moment_reduction": detail("Reactionless cases: per_axis (x, y, z: the peak |M_i| [N m] of both "
                                       "variants, their ratio, the reduction [%], whether the axis is cancelled) "
                                       "and whole_moment (peak |M| over all three axes, cancelled or not)."),
    **VERDICT,
    "urdf": string("The URDF file (kind urdf)."),
    "joint_names": strings(), "body_names": strings(),
    "start": numbers("rad or m", "Start pose of the default motion (kind urdf)."),
    "end": numbers("rad or m", "End pose of the default motion (kind urdf)."),
    "default_motion": detail("How the default motion of a URDF file was chosen (limits)."),
}

_BASE_REACTION_PEAKS = {"type": "object", "additionalProperties": False, "properties": {
    "definition": string(),
    "peak_force_mujoco": number("N"), "peak_force_mechbal": number("N"),
    "max_force_difference": number("N"), "peak_moment_mujoco": number("N m"),
    "peak_moment_mechbal": number("N m"), "max_moment_difference": number("N m")}}

MUJOCO_OPTIONS: Schema = {
    "type": "object", "additionalProperties": False,
    "description": "MuJoCo's settings of the co-simulation: integrator, time step, substeps per "
                   "controller tick, solref of the loops and gears, the factor on its inverse weights "
                   "and the mass given to each massless moving link.",
    "properties": {"integrator": string("MuJoCo's integrator (RK4, implicitfast, implicit, Euler)."),
                   "timestep": number("s", "MuJoCo's time step (the tick over substeps)."),
                   "substeps": integer(), "solref": numbers("s, 1", "Time constant and damping ratio."),
                   "constraint_weight": number(None, "Factor on MuJoCo's inverse weights."),
                   "minimum_mass": number("kg", "Mass of the body added to a massless moving link.")}}

RUN_MUJOCO: dict[str, Schema] = {
    "engine": {"const": "mujoco", "description": "mechbal run --engine mujoco: co-simulation."},
    "mechanism": string("The mechanism (its repr)."),
    "dt": number("s", "Controller and integration step."),
    "mujoco_options": MUJOCO_OPTIONS,
    "controller": string(),
    **VERDICT, "steps_completed": integer(),
    "peak_tracking_error": number("rad or m"),
    "max_constraint_violation": number("m", "Largest loop-closure violation in MuJoCo."),
    "base_reaction": _BASE_REACTION_PEAKS,
    "shaking_wrench": _BASE_REACTION_PEAKS,
    # a case with a reactionless [control]: what `mechbal run` writes for it, of MuJoCo's motion
    **{k: RUN_MECHANISM[k] for k in ("kind", "dof", "actuated", "closed", "duration", "samples", "law",
                                     "variants", "peak_shaking_force", "peak_shaking_moment", "control",
                                     "total_mass")},
    "shaking_moment_reduction": detail("Reactionless cases, of MuJoCo's motion: per_axis (x, y, z: the peak "
                                       "|M_i| [N m] of both variants, their ratio, the reduction [%], whether "
                                       "the axis is cancelled) and whole_moment (peak |M| over all three axes)."),
    "cosimulation": {"type": "object", "description": "Reactionless cases, per variant: MuJoCo's realised "
                     "base reaction and shaking wrench beside mechbal's prediction for the controller's "
                     "command, the tracking and the stored poses' wrench against MuJoCo's.",
                     "additionalProperties": {
                         "type": "object", "additionalProperties": False, "properties": {
                             "ok": boolean(), "steps_completed": integer(),
                             "peak_tracking_error": number("rad or m"),
                             "max_constraint_violation": number("m"),
                             "base_reaction": _BASE_REACTION_PEAKS, "shaking_wrench": _BASE_REACTION_PEAKS,
                             "stored_poses_wrench_difference": detail(
                                 "mechbal's shaking wrench of the stored poses against MuJoCo's realised "
                                 "one: force [N], moment [N m].")}}},
}

_STATS = {"type": "object", "additionalProperties": False,
          "properties": {"peak": numbers(), "rms": numbers()}}
_COMPARISON = {"type": "object", "additionalProperties": False, "properties": {
    "unit": string(), "unbalanced": _STATS, "balanced": _STATS,
    "peak_reduction_pct": numbers("%"), "rms_reduction_pct": numbers("%"),
    "deprecated": string()}}

BALANCE: dict[str, Schema] = {
    "kind": string("[case] kind of the case balanced."),
    "method": string("Balancing method: static, force, moment, springs or rms."),
    "mechanism": string("The unbalanced mechanism (its repr)."),
    "actuated": strings(), "closed": boolean(),
    "balance": detail("BalanceResult.summary(): method, design (by element), residual, "
                      "residual_before, residual_units, rank, unknowns, limited_by, exact, "
                      "active_bounds, undetermined, tied, unconstrained, metrics."),
    "trajectory": detail("The trajectory the comparison runs along (the case's [trajectory] keys)."),
    "before_after": {"type": "object", "description": "Peak and RMS per component or joint, "
                     "unbalanced and balanced, and the reductions [%].",
                     "additionalProperties": False,
                     "properties": {k: _COMPARISON for k in ("static_torque", "joint_torque",
                                                              "shaking_force", "shaking_moment",
                                                              "gravity_torque")}},
    "total_mass": number_map("kg", "Total mass, unbalanced and balanced."),
    "urdf": string("Why no balanced.urdf was written (loops or springs), or its name."),
    "mjcf": string("Why no balanced.xml was written (a part MJCF cannot hold)."),
    "mjcf_validation": detail("balanced.xml loaded in MuJoCo: validated (false without MuJoCo, with a "
                              "note), mujoco (version), max_equality_violation [m or rad] at the keyframe, "
                              "integrator, timestep [s]."),
    "case_notes": detail("What the case's loader says (default motion, paper values)."),
    "optimality": {"type": "object", "description": "The certificate of the convex design (static and "
                   "force methods with the 'optimal' extra, mechbal.balance.optimal): the solver, the "
                   "objective, the lexicographic order, each stage's primal and dual objectives and "
                   "duality gap, the least residual, the objective's value, the residual target and the "
                   "largest bound violation (relative to the mass scale).",
                   "additionalProperties": False, "properties": {
                       "solver": string(), "objective": {"enum": ["mass", "inertia", "torque"]},
                       "lexicographic": string(),
                       "stages": {"type": "array", "items": detail("stage, status, primal_objective, "
                                                                   "dual_objective, duality_gap, relative_gap, "
                                                                   "iterations, unit")},
                       "duality_gap": number("the objective's unit", "Duality gap of the last stage."),
                       "least_residual": number("the residual's unit"),
                       "objective_value": number("kg, kg m^2 or N m"),
                       "residual_target": {"type": ["number", "null"]},
                       "bound_violation": number("", "Largest bound violation / mass scale.")}},
    "front": {"type": "object", "description": "--front N: the trade-off front (front.csv, front.json, "
              "front.png, front/<k>/balanced.toml; mechbal.balance.fronts).", "additionalProperties": False,
              "properties": {"points": integer(), "knee": integer(), "files": strings(),
                             "added_mass_kg": numbers("kg"), "residual": numbers("the residual's unit")}},
    "assembly": detail("Loop assembly: the branch (open or crossed), how it was chosen (branch, "
                       "initial_guess or default) and the branch at the end."),
    "partial": detail("--partial (force, mechbal.plan.partial): the combined design of counterweights "
                      "within balance.mass_budget and the motion that minimises shaking: ok, limited_by, "
                      "added_mass [kg], mass_budget [kg], shaking_target [N], variants (quintic_unbalanced, "
                      "min_shaking_unbalanced, quintic_balanced, min_shaking_balanced: RMS and peak shaking "
                      "force [N], shaking moment [N m], joint torque, added mass [kg]) and the two plans."),
}

_PEAKS = {"type": ["number", "null", "array"], "items": NUMBER,
          "description": "A peak, or one per component (x, y, z: reactionless cases)."}
_VERIFY_QUANTITY = {"type": "object", "additionalProperties": False, "properties": {
    "unit": string(), "mechbal_peak": _PEAKS, "mujoco_inverse_peak": _PEAKS, "max_difference": NUMBER,
    "relative_difference": NUMBER, "mujoco_simulated_peak": _PEAKS, "simulated_minus_predicted": NUMBER,
    "simulated_peak_fraction_of_unbalanced": NUMBER}}
VERIFY: dict[str, Schema] = {
    "method": {"type": ["string", "null"], "description": "Balancing method of the balanced variant."},
    "variants": {"type": "object", "description": "Per variant (unbalanced, balanced): MuJoCo "
                 "against mechbal.", "additionalProperties": {
                     "type": "object", "additionalProperties": False, "properties": {
                         "mechanism": string(), "mujoco": anything("MuJoCo model size"),
                         "minimum_bodies": anything(""), "light_bodies": anything(""),
                         "simulation": detail("ok, steps_completed, max_constraint_violation [m], "
                                              "max_tracking_error [rad or m]"),
                         **{k: _VERIFY_QUANTITY for k in ("shaking_force", "shaking_moment",
                                                          "gravity_torque", "actuator_force")}}}},
    "checks": string("What was compared, and how."),
    "mujoco_options": MUJOCO_OPTIONS,
    "kind": string("reactionless: a case checked under its reactionless controller."),
    "mechanism": string("The mechanism (its repr)."), "mujoco": anything("MuJoCo model size"),
    "dt": number("s", "Controller tick and MuJoCo step (reactionless cases)."),
    "duration": number("s", "Horizon of the check (reactionless cases)."),
    "mode": {"enum": ["joint", "task"], "description": "Reactionless cases: balancing joints (joint) or "
             "operational space (task: the reaction null space of task_frame)."},
    "task_frame": string("Operational-space mode: the frame that follows its path."),
    "variant_meaning": detail("Reactionless cases: what the uncontrolled and controlled variants are."),
    "balancing_joints": strings(), "cancel": strings(),
    "residual": detail("Per cancelled component: the uncontrolled peak and the peaks as a fraction "
                       "of it (mechbal controlled, MuJoCo inverse controlled, MuJoCo simulated "
                       "uncontrolled and controlled)."),
    "time_step": detail("The controlled variant co-simulated at dt and dt / 2: the largest cancelled "
                        "component's residual (fraction of its uncontrolled peak) and the largest tracking "
                        "error [rad or m] at each, and their ratios."),
    "residual_limited_by": string("What limits the simulated residual (measured: time_step); for a failed "
                                  "loop, that no residual is reported."),
    "controller": string("A case with a joint [control] (computed_torque, decoupled): the controller of the "
                         "simulated check."),
    **VERDICT,
}

SWEEP: dict[str, Schema] = {
    "sweep": string("Sweep name."), "title": string(),
    "kind": {"enum": ["monte_carlo", "sensitivity", "grid"]},
    "seed": integer(), "evaluations": integer(), "chunk_size": integer(),
    "poses": {"type": ["integer", "null"], "description": "Workspace sample size."},
    "trajectory_samples": {"type": ["integer", "null"]},
    "parameters": {"type": "array", "items": {"type": "object"}},
    "failed_evaluations": integer(),
    "failure_reasons": {"type": "object", "additionalProperties": {"type": "integer"}},
    "units": {"type": "object", "additionalProperties": {"type": "string"},
              "description": "Unit of each built-in metric column."},
    "metrics": {"type": "object", "description": "Per metric column (built-in: "
                "<peak|rms>_<quantity>[.<joint>], the names of run summaries): nominal value and "
                "the statistics of the sweep kind.",
                "additionalProperties": {"type": "object", "properties": {"nominal": NUMBER}}},
}

_RMS_BY_JOINT = number_map("N m or N", "RMS torque error per joint against the measured torques.")
IDENTIFY: dict[str, Schema] = {
    "kind": {"const": "identify", "description": "mechbal identify: inertial parameters and friction "
             "identified from logs (mechbal.identify)."},
    "goal": string("What ok means: a physically consistent model within the tolerance of least squares."),
    "ok": boolean("The goal was met."),
    "limited_by": strings("Why the goal was not met (empty when ok)."),
    "joint_names": strings(), "segments": strings("The identified bodies: one per moving link."),
    "samples": integer("Instants used (after trimming and decimation)."),
    "cutoff_hz": number("Hz", "Cut-off of the zero-phase low-pass filter."),
    "condition_number": number(None, "Condition number of the base regressor on the identification logs."),
    "base_parameters": {"type": "object", "description": "Per base parameter (named after its leading "
                        "standard parameter, SI): value (weighted least squares), std, relative_std_pct, "
                        "least_squares (ordinary).", "additionalProperties": number_map()},
    "regrouping": {"type": "object", "additionalProperties": {"type": "string"},
                   "description": "The standard parameters each base parameter regroups."},
    "unidentifiable": strings("Standard parameters no joint torque depends on."),
    "full_parameters": detail("Per identified body: mass [kg], com [m], inertia [kg m^2] about the com "
                              "(ixx, iyy, izz, ixy, ixz, iyz) in the link frame, and its 10 parameters."),
    "friction": {"type": "object", "description": "Per joint: viscous [N m s/rad], coulomb [N m], offset "
                 "[N m] (N s/m, N, N for a prismatic joint).", "additionalProperties": number_map()},
    "consistency": detail("Per identified body: mass, principal_moments, min_pseudo_inertia_eigenvalue, "
                          "consistent."),
    "residual_rms": _RMS_BY_JOINT,
    "residual_rms_least_squares": _RMS_BY_JOINT,
    "validation": {"type": "object", "additionalProperties": False, "description": "RMS torque error "
                   "[N m or N] on the validation logs (held_out false: the identification logs).",
                   "properties": {"logs": strings(), "held_out": boolean(),
                                  "rms_torque_error": _RMS_BY_JOINT,
                                  "rms_torque_error_all": number("N m or N"),
                                  "models": detail("identified, least_squares, cad, cad_friction: each "
                                                   "rms_torque_error and rms_torque_error_all.")}},
    "data": detail("Per log: what the signal processing did (gaps, resampling, cut-off, trimming)."),
    "solver": detail("The consistent fit's solver and how it ended."),
}

#: (command, kind or None) -> top-level properties; kind None: every kind of that command
_SUMMARIES: dict[tuple[str, str | None], dict[str, Schema]] = {
    ("run", "serial_chain"): RUN_MECHANISM,
    ("run", "mechanism"): RUN_MECHANISM,
    ("run", "urdf"): RUN_MECHANISM,
    ("run", None): {},
    ("balance", None): BALANCE,
    ("verify", None): VERIFY,
    ("sweep", None): SWEEP,
    ("identify", None): IDENTIFY,
}
_MUJOCO_KEY = ("run", "engine:mujoco")
_SUMMARIES[_MUJOCO_KEY] = RUN_MUJOCO


def register_summary(command: str, kind: str, properties: dict[str, Schema]) -> None:
    """Register the top-level fields of the summary.json of ``command`` for case kind ``kind``
    (a paper's runner: ``register_summary("run", "paminsa", {...})`` in its ``schema.py``),
    on top of the header. Use the shared metrics (`METRICS`) for the quantities they name."""
    if command not in SUMMARY_COMMANDS:
        raise ValueError(f"command: must be one of {', '.join(SUMMARY_COMMANDS)} (got {command!r})")
    _SUMMARIES[(command, kind)] = dict(properties)


def json_schema() -> Schema:
    """The whole schema (every registered kind: the papers are loaded first)."""
    from mechbal.registry import papers

    papers()
    defs: Schema = {"metrics": {"description": "The shared metrics (per variant).",
                                "properties": copy.deepcopy(METRICS)}}
    branches = []
    for (command, kind), props in sorted(_SUMMARIES.items(), key=lambda x: (x[0][0], x[0][1] or "")):
        name = f"{command}.{kind or 'any'}"
        props = copy.deepcopy(props)
        if kind is not None and not kind.startswith("engine:") and "kind" not in props:
            props = {"kind": {"const": kind, "description": "[case] kind."}, **props}
        defs[name] = {"type": "object", "properties": props}
        if (command, kind) == _MUJOCO_KEY:
            cond = {"properties": {"command": {"const": command}}, "required": ["command", "engine"]}
        elif kind is None:
            others = sorted(k for c, k in _SUMMARIES if c == command and k is not None and
                            not k.startswith("engine:"))
            cond = {"properties": {"command": {"const": command}}, "required": ["command"]}
            if others:  # a kind registered on its own is validated by its own branch only
                cond = {"allOf": [cond, {"not": {"properties": {"kind": {"enum": others}},
                                                 "required": ["kind"]}},
                                  {"not": {"required": ["engine"]}}]}
        else:
            cond = {"properties": {"command": {"const": command}, "kind": {"const": kind}},
                    "required": ["command", "kind"]}
        branches.append({"if": cond, "then": {"$ref": f"#/$defs/{name}"}})
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://mechbal.invalid/summary.schema.json",
        "title": "mechbal summary.json",
        "description": "What every mechbal command writes as DIR/summary.json (docs/summary.md). "
                       "SI units, named in each property's 'unit', never in the keys.",
        "type": "object",
        "required": ["schema_version", "command"],
        "properties": copy.deepcopy(HEADER),
        "allOf": branches,
        "unevaluatedProperties": False,
        "$defs": defs,
    }


def schema_text() -> str:
    return json.dumps(json_schema(), indent=1, sort_keys=False) + "\n"


def main(argv: list[str] | None = None) -> int:
    # run as ``python -m``, this file is ``__main__``: the papers register into the imported
    # ``mechbal.summary_schema``, so ask that one
    import importlib

    sys.stdout.write(importlib.import_module("mechbal.summary_schema").schema_text())
    return 0


__all__ = ["METRICS", "PER_VARIANT_FORCE", "PER_VARIANT_MOMENT", "anything", "boolean", "detail",
           "integer", "json_schema", "number", "number_map", "numbers", "per_variant",
           "register_summary", "schema_text", "string", "strings"]

if __name__ == "__main__":
    raise SystemExit(main())
