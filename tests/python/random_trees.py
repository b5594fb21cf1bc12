"""Random kinematic trees for the tests: one random structure written both as a URDF string (for
Pinocchio, and for mechbal's URDF reader) and as mechbal description objects built directly."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

import mechbal
from mechbal import _core


def rpy_matrix(rpy) -> np.ndarray:
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def transform(xyz, rpy) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(rpy)
    T[:3, 3] = xyz
    return T


@dataclass
class RandomLink:
    name: str
    parent: str
    joint_type: str  # revolute | prismatic | fixed
    xyz: np.ndarray
    rpy: np.ndarray
    axis: np.ndarray
    mass: float
    com: np.ndarray
    inertia_rpy: np.ndarray
    principal: np.ndarray
    mimic: tuple | None = None  # (master, ratio, offset)

    @property
    def inertia_link(self) -> np.ndarray:
        R = rpy_matrix(self.inertia_rpy)
        return R @ np.diag(self.principal) @ R.T


@dataclass
class RandomTree:
    links: list[RandomLink] = field(default_factory=list)
    root: str = "base"

    def urdf(self) -> str:
        out = [f'<robot name="random">', f'  <link name="{self.root}"/>']
        for ln in self.links:
            Ir = ln.inertia_link
            # URDF inertia is given in the inertial frame (origin rpy): give it already rotated,
            # with rpy 0, so that both readers see the same tensor.
            out.append(f'  <link name="{ln.name}"><inertial><origin xyz="{_f(ln.com)}" rpy="0 0 0"/>'
                       f'<mass value="{float(ln.mass)!r}"/><inertia ixx="{float(Ir[0, 0])!r}" ixy="{float(Ir[0, 1])!r}" '
                       f'ixz="{float(Ir[0, 2])!r}" iyy="{float(Ir[1, 1])!r}" iyz="{float(Ir[1, 2])!r}" '
                       f'izz="{float(Ir[2, 2])!r}"/>'
                       f'</inertial></link>')
            jt = ln.joint_type
            extra = ""
            if jt != "fixed":
                extra = f'<axis xyz="{_f(ln.axis)}"/><limit lower="-3" upper="3" effort="100" velocity="10"/>'
            if ln.mimic:
                extra += f'<mimic joint="{ln.mimic[0]}_joint" multiplier="{float(ln.mimic[1])!r}" offset="{float(ln.mimic[2])!r}"/>'
            out.append(f'  <joint name="{ln.name}_joint" type="{jt}"><parent link="{ln.parent}"/>'
                       f'<child link="{ln.name}"/><origin xyz="{_f(ln.xyz)}" rpy="{_f(ln.rpy)}"/>{extra}</joint>')
        out.append("</robot>")
        return "\n".join(out)

    def mechanism(self, merge_fixed: bool = False) -> mechbal.Mechanism:
        """The same tree built directly as mechbal description objects (joint 'x_joint' moving
        link 'x' becomes joint 'x_joint' whose link is named 'x_joint'). With `merge_fixed`, every
        link on a fixed joint becomes extra bodies on its nearest moving (or base) ancestor: several
        bodies per link, the same physics."""
        if merge_fixed:
            return self._merged()
        jt = {"revolute": _core.JointType.revolute, "prismatic": _core.JointType.prismatic,
              "fixed": _core.JointType.fixed}
        name = {ln.name: ln.name + "_joint" for ln in self.links}
        name[self.root] = self.root
        joints, bodies = [], []
        for ln in self.links:
            kw = {}
            if ln.mimic:
                kw = dict(mimic_joint=name[ln.mimic[0]], mimic_ratio=ln.mimic[1], mimic_offset=ln.mimic[2])
            joints.append(_core.Joint(name[ln.name], jt[ln.joint_type], name[ln.parent],
                                      transform(ln.xyz, ln.rpy), ln.axis,
                                      **({"lower": -3.0, "upper": 3.0} if ln.joint_type != "fixed" else {}),
                                      **kw))
            bodies.append(_core.Body(ln.name, name[ln.name], ln.mass, ln.com, ln.inertia_link))
        return mechbal.Mechanism.from_description(joints, bodies, root_name=self.root)


    def _merged(self) -> mechbal.Mechanism:
        jt = {"revolute": _core.JointType.revolute, "prismatic": _core.JointType.prismatic}
        by_name = {ln.name: ln for ln in self.links}
        # carrier link and placement in it of every link (fixed chains collapsed)
        carrier = {self.root: (self.root, np.eye(4))}
        for ln in self.links:  # parents come first
            pc, pT = carrier[ln.parent]
            T = pT @ transform(ln.xyz, ln.rpy)
            carrier[ln.name] = (pc, T) if ln.joint_type == "fixed" else (ln.name + "_joint", np.eye(4))
        joints, bodies = [], []
        for ln in self.links:
            pc, pT = carrier[ln.parent]
            if ln.joint_type != "fixed":
                kw = {}
                if ln.mimic:
                    kw = dict(mimic_joint=ln.mimic[0] + "_joint", mimic_ratio=ln.mimic[1],
                              mimic_offset=ln.mimic[2])
                joints.append(_core.Joint(ln.name + "_joint", jt[ln.joint_type], pc,
                                          pT @ transform(ln.xyz, ln.rpy), ln.axis, **kw))
            c, T = carrier[ln.name]
            R = T[:3, :3]
            bodies.append(_core.Body(ln.name, c, ln.mass, R @ ln.com + T[:3, 3], R @ ln.inertia_link @ R.T))
        del by_name
        return mechbal.Mechanism.from_description(joints, bodies, root_name=self.root)


def _f(v) -> str:
    return " ".join(repr(float(x)) for x in v)


def random_tree(rng: np.random.Generator, n: int, *, types="RRRPF", branching=True,
                mimic: bool = False) -> RandomTree:
    tree = RandomTree()
    names = [tree.root]
    for i in range(n):
        parent = names[rng.integers(0, len(names))] if branching else names[-1]
        t = {"R": "revolute", "P": "prismatic", "F": "fixed"}[types[rng.integers(0, len(types))]]
        axis = rng.normal(size=3)
        if rng.random() < 0.4:  # often an aligned axis, as in real robots
            axis = np.eye(3)[rng.integers(0, 3)] * rng.choice([-1.0, 1.0])
        axis /= np.linalg.norm(axis)
        principal = rng.uniform(0.01, 0.2, 3)
        principal[2] = rng.uniform(abs(principal[0] - principal[1]) + 1e-3, principal[0] + principal[1])
        link = RandomLink(name=f"l{i + 1}", parent=parent, joint_type=t, xyz=rng.uniform(-0.4, 0.4, 3),
                          rpy=rng.uniform(-np.pi, np.pi, 3), axis=axis, mass=float(rng.uniform(0.2, 3.0)),
                          com=rng.uniform(-0.2, 0.2, 3), inertia_rpy=rng.uniform(-np.pi, np.pi, 3),
                          principal=principal)
        tree.links.append(link)
        names.append(link.name)
    if mimic:
        movable = [ln for ln in tree.links if ln.joint_type != "fixed"]
        if len(movable) >= 2:
            follower, master = movable[-1], movable[0]
            if tree.links[0].joint_type != "fixed" and follower is not master:
                follower.mimic = (master.name, float(rng.uniform(-2, 2)), float(rng.uniform(-0.5, 0.5)))
                # Pinocchio requires the follower to have the master's type
                follower.joint_type = master.joint_type
    return tree
