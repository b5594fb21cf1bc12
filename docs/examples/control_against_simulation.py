"""Step a controller against a simulation: computed-torque control of an arm read from URDF.

1. The whole closed loop in one C++ call (mechbal.simulate.closed_loop): RK4 plant, 1 kHz
   controller, along a quintic and along a user's sampled motion (spline-interpolated).
2. The same controller ticked from Python, as a test harness would: step_into writes the torque
   into a preallocated array (about a microsecond per tick), and the plant is integrated here.

Run: python docs/examples/control_against_simulation.py
"""
from pathlib import Path

import numpy as np

import mechbal
from mechbal import control, simulate, trajectory

HERE = Path(__file__).resolve().parent
robot = mechbal.Mechanism.from_urdf(HERE / "two_link_arm.urdf")

# Computed torque over the robot's own model (kp [1/s^2], kd [1/s]: critically damped at 10 rad/s).
kp, kd = np.full(robot.dof, 100.0), np.full(robot.dof, 20.0)
controller = control.ComputedTorque(robot, kp, kd)

# --- 1. closed loop in C++ ---------------------------------------------------------------------
motion = trajectory.quintic(start=[0.0, 0.0], end=[1.0, -0.8], duration=1.0)
run = simulate.closed_loop(robot, controller, motion, q0=[0.05, -0.05], dt=1e-3)
err = np.abs(run.tracking_error)
print(f"quintic: {len(run.t)} ticks, initial error 0.05 rad, final error {err[-1].max():.2e} rad, "
      f"all ticks ok: {run.ok}")
assert run.ok and err[-1].max() < 1e-3

# A user's motion, sampled at 20 Hz and interpolated by cubic splines.
t_samples = np.linspace(0.0, 2.0, 41)
q_samples = np.stack([0.3 * (1 - np.cos(np.pi * t_samples)), 0.4 * np.sin(np.pi * t_samples) ** 2], 1)
measured = trajectory.Sampled(t_samples, q_samples)
controller.reset()
run = simulate.closed_loop(robot, controller, measured, dt=1e-3)
print(f"sampled motion: max tracking error {np.abs(run.tracking_error).max():.2e} rad")
assert run.ok and np.abs(run.tracking_error).max() < 1e-3

# --- 2. tick by tick from Python -------------------------------------------------------------
plant = control.MechanismDynamics(robot.model)
controller.reset()
dt, steps = 1e-3, 1000
q, v = np.array([0.05, -0.05]), np.zeros(2)
tau = np.zeros(robot.dof)  # preallocated output of step_into
q_des, v_des, a_des = motion.evaluate(np.arange(steps) * dt)
statuses = np.zeros(steps, dtype=np.uint32)
for k in range(steps):
    statuses[k] = controller.step_into(q, v, q_des[k], v_des[k], a_des[k], tau)
    a = plant.forward_dynamics(q, v, tau)       # the plant: M(q) a = tau - C v - G
    v = v + dt * a                              # semi-implicit Euler
    q = q + dt * v
print(f"ticked from Python: final error {np.abs(q - motion.evaluate(steps * dt)[0]).max():.2e} rad, "
      f"non-ok ticks: {np.count_nonzero(statuses)}")
assert not statuses.any() and np.abs(q - motion.evaluate(1.0)[0]).max() < 1e-2

# Batch: the controller over a whole recorded (N, n) log in one call.
batch = controller.run(run.q, run.v, run.q_des, run.v_des, np.zeros_like(run.q))
print("batch of", batch.joint_torque.shape[0], "ticks: statuses", set(batch.status.tolist()))
