"""Balancing by motion, by mass and by both on PAMINSA (Briot & Arakelian 2009): the four-way
table of docs/guide.md ("Balancing by motion").

PAMINSA's legs move along the paper's cycle (rest to rest between the actuator positions of its
start and end platform positions, 0.5 s). Four designs:

(a) no counterweight, quintic motion; (b) no counterweight, the motion that minimises the RMS
shaking force (mechbal.plan.min_shaking); (c) counterweights with a mass budget, quintic;
(d) the same counterweights and the min-shaking motion planned on that mechanism.

The counterweights: the complete force balance (counterweights CP1-CP3 on each leg and the
vertical counter-mass: the closed form, which the general force method `mechbal.balance.force`
reproduces in the paminsa runner) scaled to a mass budget: every counterweight's mass times
BUDGET / (its full mass), at the same place. mechbal has no partial force balance yet; with a
scaled set of counterweights at fixed places the linear momentum is exactly (1 - s) times the
unbalanced one, so the shaking force is too, for every motion.

Run: python docs/examples/min_shaking_paminsa.py
"""
import tomllib
from typing import Any

import numpy as np

import mechbal
from mechbal.assembly import assemble
from mechbal.config import read_case
from mechbal.papers.paminsa import paminsa_case_toml
from mechbal.plan import com_law, min_shaking
from mechbal.plan.model import ActuatedModel
from mechbal.schema import validate_case

BUDGET = 10.0   # kg of counterweights (the complete balance needs 23.5 kg)

case = validate_case(tomllib.loads(paminsa_case_toml("paminsa", balanced=False)), warn=False)
unbalanced = mechbal.Mechanism.from_spec(case.spec, name="paminsa (unbalanced)")
balanced_case = validate_case(read_case("paminsa-linkage"), warn=False)   # the same, balanced
full = mechbal.Mechanism.from_spec(balanced_case.spec, name="paminsa (balanced)")
full_mass = sum(b.mass for b in full.bodies if b.kind == "counterweight")
s = BUDGET / full_mass
bodies = [mechbal.Body(b.name, b.link, b.mass * (s if b.kind == "counterweight" else 1.0), b.com, b.inertia, b.kind)
          for b in full.bodies]
partial = full.with_bodies(bodies, replace=True)

tr = case.trajectory
t = np.linspace(0.0, tr.duration, tr.samples)


def rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.trapezoid(np.sum(x ** 2, axis=1), t) / tr.duration))


def peak(x: np.ndarray) -> float:
    return float(np.max(np.linalg.norm(x, axis=1)))


def metrics(mech: mechbal.Mechanism, motion: Any) -> list[float]:
    qg = assemble(mech, np.asarray(tr.start), initial_guess=tr.initial_guess).q
    am = ActuatedModel(mech, q_guess=qg)
    ev = am.evaluate(*motion.evaluate(t), torque=True)
    assert ev.torque is not None
    legs = ev.torque[:, [mech.actuated_names.index(n) for n in ("leg1_slider", "leg1_guide", "leg3_guide")]]
    return [rms(ev.wrench[:, :3]), peak(ev.wrench[:, :3]), rms(ev.wrench[:, 3:]), peak(ev.wrench[:, 3:]),
            float(np.max(np.abs(legs[:, 0]))), float(np.max(np.abs(legs[:, 1:])))]


rows: list[tuple[str, float, list[float]]] = []
for label, mech, added in (("no counterweight", unbalanced, 0.0), (f"counterweights, {BUDGET:g} kg", partial, BUDGET)):
    qg = assemble(mech, np.asarray(tr.start), initial_guess=tr.initial_guess).q
    plan = min_shaking(mech, tr.start, tr.end, tr.duration, q_guess=qg, samples=tr.samples)
    rows.append((f"{label}, quintic", added, metrics(mech, plan.quintic)))
    rows.append((f"{label}, min_shaking", added, metrics(mech, plan.trajectory)))
qg = assemble(unbalanced, np.asarray(tr.start), initial_guess=tr.initial_guess).q
com = com_law(unbalanced, tr.start, tr.end, tr.duration, q_guess=qg, samples=tr.samples)
rows.append(("no counterweight, centre-of-mass law (bang-bang)", 0.0, metrics(unbalanced, com.trajectory)))
rows.append(("complete force balance (23.5 kg), quintic", full_mass,
             metrics(full, min_shaking(full, tr.start, tr.end, tr.duration, samples=tr.samples,
                                       q_guess=assemble(full, np.asarray(tr.start), initial_guess=tr.initial_guess).q).quintic)))

print("| design and motion | added mass [kg] | RMS force [N] | peak force [N] | RMS moment [N m] | "
      "peak moment [N m] | peak M_v force [N] | peak M_1, M_3 torque [N m] |")
print("|---|---|---|---|---|---|---|---|")
for label, added, m in rows:
    print(f"| {label} | {added:.1f} | " + " | ".join(f"{x:.3g}" for x in m) + " |")
