"""Statically balance an arm: size two counterweights so that gravity needs no joint torque.

Gravity torque is linear in the bodies' inertial parameters, G(q) = Y(q) pi (the gravity
regressor). With a counterweight of unknown mass m_k at a chosen place on each link, its parameters
are m_k times those of a unit mass there, so G(q) = G_arm(q) + sum_k m_k Y(q) phi_k: the masses
that make G zero over the workspace are a linear least-squares problem. (The balancing methods of
mechbal.balance generalise this: bounds, budgets, springs, discs.)

Run: python docs/examples/balance_arm.py
"""
import numpy as np

import mechbal

ARM = """<?xml version="1.0"?>
<robot name="arm_with_counterweights">
  <link name="base_link"/>
  <joint name="shoulder" type="revolute">
    <parent link="base_link"/> <child link="upper_arm"/>
    <origin xyz="0 0 0.1"/> <axis xyz="0 -1 0"/>
    <limit lower="-3" upper="3" effort="200" velocity="5"/>
  </joint>
  <link name="upper_arm">
    <inertial><origin xyz="0.2 0 0"/><mass value="2.0"/>
      <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.03"/></inertial>
  </link>
  <joint name="elbow" type="revolute">
    <parent link="upper_arm"/> <child link="forearm"/>
    <origin xyz="0.4 0 0"/> <axis xyz="0 -1 0"/>
    <limit lower="-3" upper="3" effort="100" velocity="5"/>
  </joint>
  <link name="forearm">
    <inertial><origin xyz="0.15 0 0"/><mass value="1.0"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <!-- counterweights behind each joint (point masses, mass to be sized) -->
  <joint name="cw1_mount" type="fixed"><parent link="upper_arm"/><child link="cw1"/>
    <origin xyz="-0.15 0 0"/></joint>
  <link name="cw1"><inertial><mass value="{m1}"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="cw2_mount" type="fixed"><parent link="forearm"/><child link="cw2"/>
    <origin xyz="-0.1 0 0"/></joint>
  <link name="cw2"><inertial><mass value="{m2}"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
</robot>"""

# The arm with unit counterweights: their parameter vectors phi_k are those of a unit mass.
unit = mechbal.Mechanism.from_urdf_string(ARM.format(m1=1.0, m2=1.0), name="unit")
names = unit.body_names
pi = unit.inertial_parameters().reshape(len(names), 10)
cw = [names.index("cw1"), names.index("cw2")]
arm = [i for i in range(len(names)) if i not in cw]

# Workspace sample and the regressor there: (N, dof, 10 B).
rng = np.random.default_rng(0)
q = rng.uniform(-np.pi, np.pi, (200, unit.dof))
Y = unit.gravity_regressor(q).reshape(len(q), unit.dof, len(names), 10)
G_arm = np.einsum("nibk,bk->ni", Y[:, :, arm], pi[arm]).reshape(-1)          # N m
A = np.stack([np.einsum("nik,k->ni", Y[:, :, b], pi[b]) for b in cw], -1).reshape(-1, 2)
masses, *_ = np.linalg.lstsq(A, -G_arm, rcond=None)
print(f"counterweights: {masses[0]:.4f} kg at 0.15 m behind the shoulder, "
      f"{masses[1]:.4f} kg at 0.10 m behind the elbow")

# Check on the balanced arm: no gravity torque anywhere (to rounding).
before = mechbal.Mechanism.from_urdf_string(ARM.format(m1=0.0, m2=0.0), name="unbalanced")
after = mechbal.Mechanism.from_urdf_string(ARM.format(m1=masses[0], m2=masses[1]), name="balanced")
q_test = rng.uniform(-np.pi, np.pi, (500, unit.dof))
g0 = np.abs(before.gravity_torque(q_test)).max()
g1 = np.abs(after.gravity_torque(q_test)).max()
print(f"peak gravity torque: {g0:.3f} N m unbalanced, {g1:.2e} N m balanced")
assert g1 < 1e-9 * g0
# the forearm's counterweight puts its centre of mass on the elbow: 1 kg x 0.15 m / 0.10 m
assert abs(masses[1] - 1.5) < 1e-9
