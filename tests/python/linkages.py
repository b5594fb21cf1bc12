"""Closed linkages for the tests, each as one tree (written as URDF for Pinocchio and as mechbal
description objects) plus loop closures between named frames."""
from __future__ import annotations

import numpy as np

import mechbal
from mechbal import _core
from random_trees import RandomLink, RandomTree


def _link(name, parent, xyz, axis, mass, com, principal=(0.01, 0.02, 0.025), rpy=(0.0, 0.0, 0.0)):
    return RandomLink(name=name, parent=parent, joint_type="revolute", xyz=np.array(xyz, float),
                      rpy=np.array(rpy, float), axis=np.array(axis, float) / np.linalg.norm(axis),
                      mass=float(mass), com=np.array(com, float), inertia_rpy=np.zeros(3),
                      principal=np.array(principal, float))


class Linkage:
    """A tree + loop closures: `tree` (RandomTree: URDF for Pinocchio), `closures` [(name, type,
    (link_a, xyz_a), (link_b, xyz_b))], `actuated` link names, `guess` (dict link -> angle)."""

    def __init__(self, tree, closures, actuated, guess, gravity=(0.0, 0.0, -9.81)):
        self.tree, self.closures, self.actuated, self.guess = tree, closures, actuated, guess
        self.gravity = np.array(gravity, float)

    def mechanism(self, loop_type=None) -> mechbal.Mechanism:
        base = self.tree.mechanism()
        d = base.model.description
        frames, loops = [], []
        for name, typ, (la, pa), (lb, pb) in self.closures:
            Ta, Tb = np.eye(4), np.eye(4)
            Ta[:3, 3], Tb[:3, 3] = pa, pb
            frames += [_core.Frame(f"{name}_a", la + "_joint", Ta), _core.Frame(f"{name}_b", lb + "_joint", Tb)]
            loops.append(_core.LoopConstraint(name, getattr(_core.LoopType, loop_type or typ),
                                              f"{name}_a", f"{name}_b"))
        return mechbal.Mechanism.from_description(d.joints, d.bodies, frames, self.gravity, loops=loops,
                                                  actuated=[a + "_joint" for a in self.actuated])

    def q_guess(self, mech) -> np.ndarray:
        return np.array([self.guess.get(n[:-len("_joint")], 0.0) for n in mech.joint_names])


def four_bar(a=0.2, b=0.5, c=0.4, d=0.45, gravity=(0.0, -9.81, 0.0)) -> Linkage:
    """Crank (a) at O, coupler (b), rocker (c) at (d, 0, 0); all joints about z; gravity along -y."""
    tree = RandomTree(links=[
        _link("crank", "base", [0, 0, 0], [0, 0, 1], 0.8, [a / 2, 0.01, 0]),
        _link("coupler", "crank", [a, 0, 0], [0, 0, 1], 1.5, [b / 2, -0.02, 0.01]),
        _link("rocker", "base", [d, 0, 0], [0, 0, 1], 1.1, [c / 2, 0.0, 0]),
    ])
    # crank at 60 deg, rocker near 100 deg: an assembly of this geometry
    return Linkage(tree, [("tip", "point", ("coupler", [b, 0, 0]), ("rocker", [c, 0, 0]))], ["crank"],
                   {"crank": np.pi / 3, "coupler": -0.6, "rocker": 1.75}, gravity)


def parallelogram(a=0.3, d=0.5) -> Linkage:
    """A four-bar with opposite sides equal (crank = rocker = a, coupler = ground = d)."""
    return four_bar(a=a, b=d, c=a, d=d)


def five_bar(l1=0.3, l2=0.45, d=0.25) -> Linkage:
    """Planar 5R: two actuated proximal links at (0,0) and (d,0), distal links closing at a point."""
    tree = RandomTree(links=[
        _link("p1", "base", [0, 0, 0], [0, 0, 1], 1.0, [l1 / 2, 0, 0]),
        _link("d1", "p1", [l1, 0, 0], [0, 0, 1], 0.7, [l2 / 2, 0.01, 0]),
        _link("p2", "base", [d, 0, 0], [0, 0, 1], 1.0, [l1 / 2, 0, 0]),
        _link("d2", "p2", [l1, 0, 0], [0, 0, 1], 0.7, [l2 / 2, -0.01, 0]),
    ])
    return Linkage(tree, [("tip", "point", ("d1", [l2, 0, 0]), ("d2", [l2, 0, 0]))], ["p1", "p2"],
                   {"p1": 2.0, "d1": -1.2, "p2": 1.1, "d2": 1.2}, (0.0, -9.81, 0.0))


def rusr() -> Linkage:
    """A spatial R-U-S-R linkage (the RSSR with the coupler's idle spin removed by a universal
    joint): crank about z at O, universal (two revolutes) at the crank tip, coupler, spherical
    closure (a point constraint) at the tip of a rocker turning about x at (0.1, 0.4, 0.2)."""
    tree = RandomTree(links=[
        _link("crank", "base", [0, 0, 0], [0, 0, 1], 0.9, [0.1, 0, 0]),
        _link("u1", "crank", [0.2, 0, 0], [0, 0, 1], 0.05, [0, 0, 0], principal=(1e-4, 1e-4, 1e-4)),
        _link("coupler", "u1", [0, 0, 0], [0, 1, 0], 1.2, [0.25, 0, 0]),
        _link("rocker", "base", [0.1, 0.4, 0.2], [1, 0, 0], 1.0, [0, 0.15, 0]),
    ])
    return Linkage(tree, [("s", "point", ("coupler", [0.5, 0, 0]), ("rocker", [0, 0.3, 0]))], ["crank"],
                   {"crank": 0.3, "u1": 1.2, "coupler": -0.5, "rocker": -1.0})
