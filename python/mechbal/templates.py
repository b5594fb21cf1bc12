"""Commented case templates printed by ``mechbal init KIND`` (a starting point to edit, accepted
as is by ``mechbal run``; the tests run them)."""

SERIAL = '''\
# A mechbal case: a serial chain (here a two-link arm in the vertical x-z plane) moving along a
# rest-to-rest trajectory. Run it with
#     mechbal run my.toml --out out/my
# to get out/my/summary.json (peak shaking force and moment, joint and base-reaction torques),
# PNG plots and out/my/bodies_nominal.npz (every body's pose along the motion).
# Units are SI throughout: m, kg, kg m^2, rad, s. The base frame has z up.

[case]
name = "my_robot"             # a name for the reports
kind = "serial_chain"         # the runner: a serial chain of revolute/prismatic joints
title = "My two-link arm, quintic rest-to-rest motion in 1 s"

[mechanism]
gravity = [0.0, 0.0, -9.81]   # m/s^2 in the base frame
# base = { xyz = [0.0, 0.0, 0.0], rpy = [0.0, 0.0, 0.0] }   # optional pose of the first joint's
                                                            # parent frame in the base frame

# One [[mechanism.joints]] table per joint, from the base outwards. Each joint:
#   name   a label used in plots and files
#   type   "revolute" (angle, torque in N m) or "prismatic" (displacement, force in N)
#   origin = { xyz = [...], rpy = [...] }   the joint frame in the previous link's frame
#            (roll-pitch-yaw about fixed x, y, z), with axis = [x, y, z] the joint axis in it;
#          or mdh = { a, alpha, d, theta }   modified (Craig) Denavit-Hartenberg parameters;
#          or dh  = { a, alpha, d, theta }   standard Denavit-Hartenberg parameters
#            (DH joints move about/along their z axis: no axis key)
#   link = { mass, com, inertia }   the link after the joint: mass [kg], centre of mass [m] in the
#          joint frame, inertia about the centre of mass [kg m^2] as [Ixx, Iyy, Izz],
#          [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 matrix

[[mechanism.joints]]
name = "shoulder"
type = "revolute"
origin = { xyz = [0.0, 0.0, 0.0], rpy = [0.0, 0.0, 0.0] }
axis = [0.0, -1.0, 0.0]       # a positive angle lifts the arm from +x towards +z
link = { mass = 4.0, com = [0.25, 0.0, 0.0], inertia = [0.004, 0.09, 0.09] }

[[mechanism.joints]]
name = "elbow"
type = "revolute"
origin = { xyz = [0.5, 0.0, 0.0] }   # 0.5 m along the first link
axis = [0.0, -1.0, 0.0]
link = { mass = 2.0, com = [0.2, 0.0, 0.0], inertia = [0.002, 0.03, 0.03] }

[trajectory]
law = "quintic"               # quintic | cubic (minimum energy)
start = [0.0, 0.0]            # one value per joint [rad or m]
end = [1.2, -0.9]
duration = 1.0                # s
samples = 501                 # instants evaluated (at least 3)
'''

LINKAGE_NOT_YET = (
    "'mechbal init linkage' is not available yet: closed-loop mechanisms (a four-bar with a "
    "counterweight) need the general mechanism model's file format (loop closures), which is "
    "being added; start from 'mechbal init serial' or the built-in five-bar case "
    "('mechbal cases')")
