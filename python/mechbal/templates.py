"""Commented case templates printed by ``mechbal init KIND`` (a starting point to edit, accepted
as is by ``mechbal run``; the tests run them).

Layer: Python core (docs/architecture.md)."""

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
#          joint frame, inertia about the centre of mass [kg m^2] as
#          { ixx, iyy, izz, ixy, ixz, iyz } (products absent: 0), [Ixx, Iyy, Izz],
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
link = { mass = 2.0, com = [0.2, 0.0, 0.0], inertia = { ixx = 0.002, iyy = 0.03, izz = 0.03 } }

[trajectory]
law = "quintic"               # quintic | cubic (minimum energy) | constant_speed
start = [0.0, 0.0]            # one value per joint [rad or m]
end = [1.2, -0.9]             # rest-to-rest laws
duration = 1.0                # s
samples = 501                 # instants evaluated (at least 3)
# law = "constant_speed" instead: start, then speed = [1.0, -2.0] (rad/s, or one number for
# every joint) or rpm = ..., and duration or revolutions = 2 (turns of the fastest joint); no end
'''

LINKAGE = r'''# A mechbal case: a closed linkage (here a four-bar in the vertical x-z plane with a
# counterweight on its crank) driven by its crank at constant speed. Run it with
#     mechbal run my.toml --out out/my
# to get out/my/summary.json (peak shaking force and moment, actuator and base-reaction torques),
# PNG plots and out/my/bodies_nominal.npz (every body's pose along the motion).
# Units are SI throughout: m, kg, kg m^2, rad, s. The base frame has z up.
#
# A closed linkage is described as a tree of joints (each with a parent) plus loop closures that
# join two frames on different branches. Here: crank -> coupler is one branch, rocker another,
# and the loop pins the coupler's tip to the rocker's tip.
#
#      coupler_tip = rocker_tip   (loop "coupler_rocker")
#            /         \
#     coupler           rocker
#        /                 \
#   crank (motor)          |
#   base O ---- 0.45 m ---- rocker pivot

[case]
name = "my_linkage"           # a name for the reports
kind = "mechanism"            # the runner of the general model (trees and closed loops)
title = "My four-bar with a crank counterweight, quintic crank motion in 1 s"

[mechanism]
gravity = [0.0, 0.0, -9.81]   # m/s^2 in the base frame
actuated = ["crank"]          # the motor-driven joints (one per degree of freedom of the linkage);
                              # the other joints are passive and follow from the loop closures

# One [[mechanism.joints]] table per joint. Each joint:
#   name    a label used in plots and files (also the name of the link it moves)
#   parent  the joint whose link carries it, or "base" (default: the previous joint)
#   type    "revolute" (angle) or "prismatic" (displacement); default revolute
#   origin = { xyz = [...], rpy = [...] }  the joint frame in the parent link's frame
#   axis    the joint axis in that frame
#   link = { mass, com, inertia }  the link after the joint: mass [kg], centre of mass [m] in the
#           joint frame, inertia about the centre of mass [kg m^2] as
#           { ixx, iyy, izz, ixy, ixz, iyz } (products absent: 0), [Ixx, Iyy, Izz],
#           [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 matrix; or, the linkage being planar,
#           izz = ... alone: the moment about the joints' common axis (here y), the link taken
#           as a thin lamina in the plane of motion

[[mechanism.joints]]
name = "crank"
parent = "base"
origin = { xyz = [0.0, 0.0, 0.0] }
axis = [0.0, -1.0, 0.0]       # a positive angle lifts +x towards +z
link = { mass = 0.8, com = [0.1, 0.0, 0.0], inertia = [0.0002, 0.003, 0.003] }

[[mechanism.joints]]
name = "coupler"
parent = "crank"
origin = { xyz = [0.2, 0.0, 0.0] }   # at the crank's end: crank length 0.2 m
axis = [0.0, -1.0, 0.0]
link = { mass = 1.5, com = [0.25, 0.0, 0.0], izz = 0.032 }   # planar: the moment about y alone

[[mechanism.joints]]
name = "rocker"
parent = "base"               # a second branch from the base
origin = { xyz = [0.45, 0.0, 0.0] }  # ground link 0.45 m
axis = [0.0, -1.0, 0.0]
link = { mass = 1.1, com = [0.2, 0.0, 0.0], inertia = [0.0003, 0.015, 0.015] }

# Extra bodies on any link: counterweights, motors, discs, payloads (kind is a label).
[[mechanism.bodies]]
name = "crank_counterweight"
kind = "counterweight"
link = "crank"
mass = 0.6                    # kg
com = [-0.08, 0.0, 0.0]       # m, in the crank's frame (opposite the coupler)
inertia = [0.0001, 0.0001, 0.0001]

# Named frames on links: the loop closures join two of them.
[[mechanism.frames]]
name = "coupler_tip"
link = "coupler"
origin = { xyz = [0.5, 0.0, 0.0] }   # coupler length 0.5 m

[[mechanism.frames]]
name = "rocker_tip"
link = "rocker"
origin = { xyz = [0.4, 0.0, 0.0] }   # rocker length 0.4 m

# One [[mechanism.loops]] table per closure. type:
#   "point"         the two frame origins coincide (a spherical or, in a plane, a revolute pin;
#                   3 equations)
#   "planar_point"  the origins coincide in the plane normal to frame_a's z (2 equations: a pin
#                   of a planar linkage without redundant constraints)
#   "axis"          origins coincide and z axes are parallel (5 equations: a revolute pin)
#   "weld"          the frames coincide (6 equations)
[[mechanism.loops]]
name = "coupler_rocker"
type = "point"
frame_a = "coupler_tip"
frame_b = "rocker_tip"

[trajectory]
law = "constant_speed"        # the crank turning steadily; or quintic | cubic (rest to rest:
                              # start, end, duration)
start = [1.0]                 # one value per actuated joint [rad or m]
rpm = 60                      # or speed = 6.283 (rad/s); one number, or one per actuated joint
revolutions = 1               # turns of the crank; or duration = 1.0 (s)
samples = 1001                # instants evaluated (at least 3)
branch = "open"               # the four-bar's assembly: "open" (the default) or "crossed";
                              # summary.json says which was used
# initial_guess = [1.0]       # or: the actuated joints only (the passive ones are solved on
                              # branch), or every joint (crank, coupler, rocker) near the wanted
                              # assembly at start [rad]
'''

REACTIONLESS = '''\
# A mechbal case with a reactionless controller: a planar two-link arm (shoulder and elbow about
# the vertical z) carries a reaction wheel that the controller spins so that the angular momentum
# about z stays at its initial value: the arm's motion exerts no shaking moment about z on its
# base. Run it with
#     mechbal run my.toml --out out/my
# to get out/my/summary.json (peak shaking wrench with the wheel held still, "uncontrolled", and
# under the controller, "controlled"), the plots and out/my/bodies_uncontrolled.npz,
# out/my/bodies_controlled.npz (every body's pose at every controller tick).
# Units are SI throughout: m, kg, kg m^2, rad, s. The base frame has z up.

[case]
name = "my_reactionless_arm"
kind = "mechanism"            # any mechanism of the general model (trees, gears, closed loops)
title = "Two-link arm with a reaction wheel"

[mechanism]
gravity = [0.0, 0.0, -9.81]

[[mechanism.joints]]
name = "shoulder"
axis = [0.0, 0.0, 1.0]
link = { mass = 2.0, com = [0.25, 0.0, 0.0], inertia = [0.002, 0.04, 0.04] }  # kg, m, kg m^2

[[mechanism.joints]]
name = "elbow"
origin = { xyz = [0.5, 0.0, 0.0] }
axis = [0.0, 0.0, 1.0]
link = { mass = 1.5, com = [0.2, 0.0, 0.0], inertia = [0.001, 0.02, 0.02] }

[[mechanism.joints]]
name = "wheel"                # the balancing joint: an actuated disc on the forearm
origin = { xyz = [0.3, 0.0, 0.0] }
axis = [0.0, 0.0, 1.0]
link = { mass = 2.0, com = [0.0, 0.0, 0.0], inertia = [0.05, 0.05, 0.1] }

# Every actuated joint is listed; a balancing joint's start is its initial position, its end is
# ignored (the controller computes its motion).
[trajectory]
law = "quintic"               # quintic | cubic
start = [0.0, 0.0, 0.0]       # rad
end = [1.0, -1.2, 0.0]
duration = 2.0                # s
samples = 2001

[control]
kind = "reactionless"
balancing_joints = ["wheel"]  # actuated joints whose motion the controller computes
cancel = ["moment_z"]         # any of "moment", "force", "both", "moment_x|y|z", "force_x|y|z"
integrator = "rk4"            # or "euler"
rate_hz = 1000                # controller rate [Hz]
damping = 1e-3                # damped least squares near singularities (relative)
# max_rate = 20.0             # balancing joints' rate limit [rad/s] (default: none beyond the
#                             #   joints' declared limits = { velocity = ... })
# home_gain = 0.0             # with more balancing joints than cancelled components: pull
# limit_gain = 0.0            #   towards the start pose / away from the joint limits [1/s]
# task_frame = "tool"         # operational-space mode (a redundant arm, every joint listed in
# task_rows = ["linear"]      #   balancing_joints): [trajectory] is then the frame's path from its
#                             #   pose at start to its pose at end (see panda-reactionless.toml)
'''
