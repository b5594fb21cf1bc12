"""Balancing by motion, by mass and by both on PAMINSA (Briot & Arakelian 2009): the four-way
table of docs/guide.md ("Balancing by motion").

PAMINSA's legs move along the paper's cycle (rest to rest between the actuator positions of its
start and end platform positions, 0.5 s). Four designs:

(a) no counterweight, quintic motion; (b) no counterweight, the motion that minimises the RMS
shaking force (mechbal.plan.min_shaking); (c) counterweights within a mass budget, quintic;
(d) the same counterweights and the min-shaking motion planned on that mechanism.

The counterweights: the partial force balance of the general method (`mechbal.balance.force`,
the case's [balance] slots: CP1-CP3 on each leg at the paper's points and the vertical
counter-mass) under a mass budget, the least RMS linear momentum that BUDGET kg allow
(``force.problem(...).solve(mass_budget=BUDGET)``, as ``mechbal balance paminsa --method force
--partial`` with ``mass_budget = 10`` runs it); the motions by `mechbal.plan.partial`.

Run: python docs/examples/min_shaking_paminsa.py
"""
import tomllib
from typing import Any

import numpy as np

import mechbal
from mechbal.assembly import assemble
from mechbal.balance.result import CounterweightDesign
from mechbal.balance.run import balance_case, run_method
from mechbal.config import read_case
from mechbal.papers.paminsa import paminsa_case_toml
from mechbal.plan import com_law, min_shaking
from mechbal.plan.model import ActuatedModel
from mechbal.plan.partial import LABELS, combined_design
from mechbal.schema import validate_case

BUDGET = 10.0   # kg of counterweights (the complete balance needs 23.5 kg)

case = validate_case(tomllib.loads(paminsa_case_toml("paminsa", balanced=False)), warn=False)
unbalanced = mechbal.Mechanism.from_spec(case.spec, name="paminsa (unbalanced)")
balanced_case = validate_case(read_case("paminsa-linkage"), warn=False)   # the same, balanced
full = mechbal.Mechanism.from_spec(balanced_case.spec, name="paminsa (balanced)")
full_mass = sum(b.mass for b in full.bodies if b.kind == "counterweight")

# the partial force balance under the budget, and the motions planned with and without it
bc = balance_case("paminsa")
bc.table = bc.table.model_copy(update={"mass_budget": BUDGET})
result = run_method(bc, "force")
added = sum(d.mass for d in result.design.values() if isinstance(d, CounterweightDesign))
tt = bc.trajectory_table
combined = combined_design(bc.mechanism, result.balanced, tt["start"], tt["end"], float(tt["duration"]),
                           added_mass=added, mass_budget=BUDGET, q_guess=bc.q_guess, samples=len(bc.t),
                           budget_active="mass_budget" in result.active_bounds)

tr = case.trajectory
t = np.linspace(0.0, tr.duration, tr.samples)


def rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.trapezoid(np.sum(x ** 2, axis=1), t) / tr.duration))


def peak(x: np.ndarray) -> float:
    return float(np.max(np.linalg.norm(x, axis=1)))


def metrics(mech: mechbal.Mechanism, motion: Any, q_guess: Any = None) -> list[float]:
    qg = assemble(mech, np.asarray(tr.start), initial_guess=tr.initial_guess).q if q_guess is None else q_guess
    am = ActuatedModel(mech, q_guess=qg)
    ev = am.evaluate(*motion.evaluate(t), torque=True)
    assert ev.torque is not None
    legs = ev.torque[:, [mech.actuated_names.index(n) for n in ("leg1_slider", "leg1_guide", "leg3_guide")]]
    return [rms(ev.wrench[:, :3]), peak(ev.wrench[:, :3]), rms(ev.wrench[:, 3:]), peak(ev.wrench[:, 3:]),
            float(np.max(np.abs(legs[:, 0]))), float(np.max(np.abs(legs[:, 1:])))]


rows: list[tuple[str, float, list[float]]] = []
for which, mech, mass in (("unbalanced", bc.mechanism, 0.0), ("balanced", result.balanced, added)):
    plan = combined.plans[which]
    assert plan.ok, plan.message
    rows.append((LABELS[f"quintic_{which}"], mass, metrics(mech, plan.quintic, bc.q_guess)))
    rows.append((LABELS[f"min_shaking_{which}"], mass, metrics(mech, plan.trajectory, bc.q_guess)))
qg = assemble(unbalanced, np.asarray(tr.start), initial_guess=tr.initial_guess).q
com = com_law(unbalanced, tr.start, tr.end, tr.duration, q_guess=qg, samples=tr.samples)
rows.append(("no counterweight, centre-of-mass law (bang-bang)", 0.0, metrics(unbalanced, com.trajectory)))
rows.append((f"complete force balance ({full_mass:.1f} kg), quintic", full_mass,
             metrics(full, min_shaking(full, tr.start, tr.end, tr.duration, samples=tr.samples,
                                       q_guess=assemble(full, np.asarray(tr.start), initial_guess=tr.initial_guess).q).quintic)))

print(f"combined design: {added:.3g} kg of counterweights within {BUDGET:g} kg, verdict "
      + ("ok" if combined.ok else "NOT ok: " + "; ".join(combined.limited_by)))
print("| design and motion | added mass [kg] | RMS force [N] | peak force [N] | RMS moment [N m] | "
      "peak moment [N m] | peak M_v force [N] | peak M_1, M_3 torque [N m] |")
print("|---|---|---|---|---|---|---|---|")
for label, added, m in rows:
    print(f"| {label} | {added:.1f} | " + " | ".join(f"{x:.3g}" for x in m) + " |")
