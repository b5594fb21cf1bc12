"""Statically balance an arm: size two counterweights so that gravity needs no joint torque.

mechbal.balance.static writes the gravity torque as linear in the bodies' mass moments (the
gravity regressor, G(q) = Y(q) pi), solves the counterweights' masses and positions by least
squares over a workspace sample, within each slot's bounds, and returns the balanced mechanism.

Run: python docs/examples/balance_arm.py
"""
from pathlib import Path

import numpy as np

import mechbal
from mechbal.balance import CounterweightSlot, static

HERE = Path(__file__).resolve().parent
arm = mechbal.Mechanism.from_urdf(HERE / "two_link_arm.urdf")

# Where counterweights may go: at most 0.15 m from the shoulder axis, 0.10 m from the elbow axis.
slots = [CounterweightSlot("shoulder_counterweight", link="upper_arm", mass_max=20.0, max_radius=0.15),
         CounterweightSlot("elbow_counterweight", link="forearm", mass_max=5.0, max_radius=0.10)]
result = static.balance(arm, slots, samples=200)
for name, cw in result.design.items():
    print(f"{name}: {cw.mass:.4f} kg at {np.round(cw.position, 4)} m in {cw.frame}")
print(f"RMS gravity torque over the sample: {result.residual_before:.3f} N m before, "
      f"{result.residual:.1e} N m after (exact: {result.exact})")

# Check on the balanced arm, elsewhere in the workspace: no gravity torque (to rounding).
q = np.random.default_rng(1).uniform(-np.pi, np.pi, (500, arm.dof))
before = np.abs(arm.gravity_torque(q)).max()
after = np.abs(result.balanced.gravity_torque(q)).max()
print(f"peak gravity torque: {before:.3f} N m unbalanced, {after:.1e} N m balanced")
assert result.exact and after < 1e-9 * before

# The closed form of a two-link arm (Arakelian, Le Baron & Mottu 2011, eqs 21-22): the elbow's
# counterweight puts the forearm's centre of mass on the elbow axis, the shoulder's puts that of
# everything on the shoulder axis. Link masses 2.0 / 1.0 kg at 0.2 / 0.15 m, upper arm 0.4 m.
m_elbow = 1.0 * 0.15 / 0.10
m_shoulder = (2.0 * 0.2 + (1.0 + m_elbow) * 0.4) / 0.15
assert abs(result.design["elbow_counterweight"].mass - m_elbow) < 1e-9
assert abs(result.design["shoulder_counterweight"].mass - m_shoulder) < 1e-9
print(f"closed form: {m_shoulder:.4f} kg and {m_elbow:.4f} kg: agree")
