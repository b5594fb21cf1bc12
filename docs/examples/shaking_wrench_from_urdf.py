"""Load a robot from its URDF file and compute the shaking force and moment it exerts on its base.

Run: python docs/examples/shaking_wrench_from_urdf.py
"""
from pathlib import Path

import numpy as np

import mechbal

HERE = Path(__file__).resolve().parent

robot = mechbal.Mechanism.from_urdf(HERE / "two_link_arm.urdf")
print(robot)                         # <Mechanism 'two_link_arm': 2 dof, ...>
print("joints:", robot.joint_names)  # ['shoulder', 'elbow']

# One instant: 1-D arrays of robot.dof values (rad, rad/s, rad/s^2).
q, v, a = np.array([0.3, -0.5]), np.array([1.0, 0.5]), np.array([2.0, -1.0])
wrench = robot.shaking_wrench(q, v, a)
print("shaking force [N]:", wrench.shaking_force)
print("shaking moment about O [N m]:", wrench.shaking_moment)

# A whole trajectory in one C++ call: (N, dof) arrays, a per-instant status array.
motion = mechbal.trajectory.quintic(start=[0.0, 0.0], end=[1.2, -0.9], duration=1.0)
t = np.linspace(0.0, 1.0, 201)
q, v, a = motion.evaluate(t)  # each (201, 2)
wrench = robot.shaking_wrench(q, v, a)
assert wrench.shaking_force.shape == (201, 3) and not wrench.status.any()
peak = np.linalg.norm(wrench.shaking_force, axis=1).max()
print(f"peak shaking force along the motion: {peak:.3f} N")

# The wrench the base exerts on the robot, gravity included, and the joint torques.
reaction = robot.base_reaction(q, v, a)
tau = robot.inverse_dynamics(q, v, a)
print(f"peak base reaction force: {np.linalg.norm(reaction.base_reaction_force, axis=1).max():.3f} N, "
      f"peak shoulder torque: {np.abs(tau[:, 0]).max():.3f} N m")

# The same momentum rate checked by finite differences of the momentum (an invariant).
P = robot.momentum(q, v).linear_momentum
dP = np.gradient(P, t, axis=0)
assert np.allclose(dP[5:-5], wrench.shaking_force[5:-5], atol=1e-2 * peak)
print("shaking force = dP/dt: checked by finite differences")
