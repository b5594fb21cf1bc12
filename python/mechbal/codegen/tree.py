"""The model's algorithms written once more over the expression graph (`expr.Graph`), with the
model's constants known: each function returns the outputs as graph values (floats or nodes).

The recursions are the library's (cpp/include/mechbal/detail/tree.hpp, algorithm/*.hpp): link
frames F_i = F_parent * placement_i * J_i(q_i); Newton-Euler on 3-vectors in link frames for the
inverse dynamics (Luh, Walker & Paul 1980); composite rigid bodies for the mass matrix
(Featherstone 2008, alg. 6.2, on 3-vectors); the shaking wrench as the momentum rate about O, the
force the moving links push on the root; gear couplings q_j = ratio q_i + offset projected with
tau = G^T tau_joint. Bodies on one link are merged into one set of inertial constants (mass,
first moment and inertia about the link's origin) at generation time.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .expr import (Graph, Value, cross, directional_derivative, dot, ldlt_apply, ldlt_factor, matmul, mattvec,
                   matvec, substitute, transpose, vadd, vscale, vsub)

_RIGHT_ANGLE_ULP = 4.0


def _snap_rotation(R: np.ndarray) -> np.ndarray:
    """A rotation within 4 ulp of a signed permutation is that permutation (the model does the
    same at construction: a URDF's rpy of +-pi/2 leaves 6e-17 where the zeros belong)."""
    eps = _RIGHT_ANGLE_ULP * np.finfo(float).eps
    snapped = np.round(R)
    if np.all(np.abs(R - snapped) <= eps) and np.allclose(np.abs(snapped).sum(axis=0), 1.0) \
            and np.allclose(np.abs(snapped).sum(axis=1), 1.0):
        return snapped + 0.0
    return R


def _axis_rotation(g: Graph, axis, c: Value, s: Value):
    """Rodrigues' rotation about the unit `axis` (constants) by the angle of cosine c, sine s."""
    x, y, z = (float(u) for u in axis)
    one_c = g.sub(1.0, c)
    if sorted(abs(u) for u in (x, y, z)) == [0.0, 0.0, 1.0]:
        # about +-e_k: the k-th row and column are exactly e_k (c + (1 - c) would round)
        k = [abs(u) for u in (x, y, z)].index(1.0)
        sign = (x, y, z)[k]
        R: list[list[Value]] = [[c if r == col else 0.0 for col in range(3)] for r in range(3)]
        R[k][k] = 1.0
        i, j = (k + 1) % 3, (k + 2) % 3
        R[j][i] = g.mul(sign, s)
        R[i][j] = g.neg(R[j][i])
        return R
    return [[g.add(c, g.mul(one_c, x * x)), g.sub(g.mul(one_c, x * y), g.mul(s, z)),
             g.add(g.mul(one_c, x * z), g.mul(s, y))],
            [g.add(g.mul(one_c, x * y), g.mul(s, z)), g.add(c, g.mul(one_c, y * y)),
             g.sub(g.mul(one_c, y * z), g.mul(s, x))],
            [g.sub(g.mul(one_c, x * z), g.mul(s, y)), g.add(g.mul(one_c, y * z), g.mul(s, x)),
             g.add(c, g.mul(one_c, z * z))]]


@dataclass
class Link:
    """One moving link of the tree, with the constants of its joint and its merged bodies."""

    name: str
    parent: int             # index into the link list, -1 for the root's children... root = 0
    kind: str               # "revolute", "prismatic", "fixed"
    R0: np.ndarray          # placement rotation (parent -> joint frame)
    p0: np.ndarray          # placement translation
    axis: np.ndarray        # unit, in the joint (= link) frame
    coordinate: int = -1    # index into q of the joint's master coordinate (-1: fixed)
    ratio: float = 1.0      # q_joint = ratio q[coordinate] + offset
    offset: float = 0.0
    mass: float = 0.0
    first_moment: np.ndarray = field(default_factory=lambda: np.zeros(3))   # sum m c
    inertia_origin: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # about origin
    moves: bool = True      # False for the root and links fixed to it


@dataclass
class TreeConstants:
    """What the generator knows of a model: links in depth-first order (0 is the root)."""

    name: str
    dof: int
    coordinate_names: list[str]
    links: list[Link]
    gravity: np.ndarray
    frames: dict[str, tuple[int, np.ndarray]]  # name -> (link, 4x4 placement in the link frame)
    springs: list  # (link_a, anchor_a, link_b, anchor_b, K_eq, T0 = count preload / k - K_eq L0)
    loops: list = field(default_factory=list)      # (type name, frame_a, frame_b)
    actuated: list = field(default_factory=list)   # coordinates of q# (every one without loops)
    passive: list = field(default_factory=list)    # the others, solved by the closures


def tree_constants(mechanism) -> TreeConstants:
    """Read the constants of a `mechbal.Mechanism` (an open tree; loops are refused upstream)."""
    model = mechanism.model
    description = model.description
    joints = {j.name: j for j in description.joints}
    names = list(model.link_names)
    parents = list(model.link_parents)
    coordinates = list(model.coordinate_names)
    index = {n: i for i, n in enumerate(names)}

    def master(name: str, ratio: float = 1.0, offset: float = 0.0):
        j = joints[name]
        if j.mimic_joint:
            return master(j.mimic_joint, ratio * j.mimic_ratio, ratio * j.mimic_offset + offset)
        return coordinates.index(name), ratio, offset

    links: list[Link] = [Link(names[0], -1, "fixed", np.eye(3), np.zeros(3), np.array([0.0, 0, 1]),
                              moves=False)]
    for i in range(1, len(names)):
        j = joints[names[i]]
        P = np.asarray(j.placement, dtype=float)
        kind = j.type.name
        axis = np.asarray(j.axis, dtype=float)
        axis = axis / np.linalg.norm(axis)
        link = Link(names[i], parents[i], kind, _snap_rotation(P[:3, :3]), P[:3, 3].copy(), axis)
        if kind != "fixed":
            link.coordinate, link.ratio, link.offset = master(names[i])
        link.moves = kind != "fixed" or links[parents[i]].moves
        links.append(link)
    for b in description.bodies:
        link = links[index[b.link]]
        c = np.asarray(b.com, dtype=float)
        cx = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])
        link.mass += b.mass
        link.first_moment = link.first_moment + b.mass * c
        link.inertia_origin = link.inertia_origin + np.asarray(b.inertia, dtype=float) - b.mass * cx @ cx
    frames = {}
    for f in description.frames:
        frames[f.name] = (index[f.link], np.asarray(f.placement, dtype=float))
    springs = []
    for s in description.springs:
        k = s.pulley_ratio
        K_eq = s.count * s.rate / k**2
        T0 = s.count * s.preload / k - K_eq * s.free_length
        springs.append((index[s.link_a], np.asarray(s.anchor_a, float), index[s.link_b],
                        np.asarray(s.anchor_b, float), K_eq, T0))
    loops = [(lc.type.name, lc.frame_a, lc.frame_b) for lc in description.loops]
    return TreeConstants(mechanism.name if hasattr(mechanism, "name") else "mechanism", model.dof,
                         coordinates, links, np.asarray(model.gravity, dtype=float), frames, springs,
                         loops, list(model.actuated_coordinates), list(model.passive_coordinates))


# ---- kinematics ---------------------------------------------------------------------------------
class Kinematics:
    """Link-to-parent rotations and translations and world poses, as graph values."""

    def __init__(self, g: Graph, tree: TreeConstants, q):
        self.g = g
        self.tree = tree
        self.R_local: list = []
        self.p_local: list = []
        self._world: dict[int, tuple] = {}
        for link in tree.links:
            if link.parent < 0:
                self.R_local.append([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])
                self.p_local.append([0.0, 0.0, 0.0])
                continue
            R0 = [[float(x) for x in row] for row in link.R0]
            p0 = [float(x) for x in link.p0]
            if link.kind == "revolute":
                angle = g.add(g.mul(link.ratio, q[link.coordinate]), link.offset)
                J = _axis_rotation(g, link.axis, g.cos(angle), g.sin(angle))
                self.R_local.append(matmul(g, R0, J))
                self.p_local.append(p0)
            elif link.kind == "prismatic":
                d = g.add(g.mul(link.ratio, q[link.coordinate]), link.offset)
                self.R_local.append(R0)
                self.p_local.append(vadd(g, p0, vscale(g, d, matvec(g, R0, list(link.axis)))))
            else:
                self.R_local.append(R0)
                self.p_local.append(p0)

    def world(self, i: int):
        """(R, p) of link i in O."""
        if i in self._world:
            return self._world[i]
        link = self.tree.links[i]
        if link.parent < 0:
            out = ([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]], [0.0, 0.0, 0.0])
        else:
            Rp, pp = self.world(link.parent)
            out = (matmul(self.g, Rp, self.R_local[i]), vadd(self.g, pp, matvec(self.g, Rp, self.p_local[i])))
        self._world[i] = out
        return out


def _joint_rates(g: Graph, link: Link, v):
    return g.mul(link.ratio, v[link.coordinate]) if link.coordinate >= 0 else 0.0


# ---- Newton-Euler --------------------------------------------------------------------------------
def newton_euler(g: Graph, tree: TreeConstants, q, v, a, *, gravity: bool, springs: bool,
                 kin: Kinematics | None = None):
    """Joint-space forces (dof values) and the wrench the moving links exert on the root about
    O in O (force, moment), by the recursive Newton-Euler algorithm in link frames."""
    kin = kin or Kinematics(g, tree, q)
    n = len(tree.links)
    w = [None] * n      # angular velocity in link frame
    dw = [None] * n     # angular acceleration
    acc = [None] * n    # linear acceleration of the link origin
    grav = [-float(x) for x in tree.gravity] if gravity else [0.0, 0.0, 0.0]
    w[0], dw[0], acc[0] = [0.0] * 3, [0.0] * 3, grav
    f = [None] * n
    m = [None] * n
    for i in range(1, n):
        link = tree.links[i]
        R, p = kin.R_local[i], kin.p_local[i]
        par = link.parent
        # the parent's motion carried to this link's origin, in the parent frame, then rotated
        a_par = vadd(g, acc[par], vadd(g, cross(g, dw[par], p), cross(g, w[par], cross(g, w[par], p))))
        wi = mattvec(g, R, w[par])
        dwi = mattvec(g, R, dw[par])
        ai = mattvec(g, R, a_par)
        axis = [float(x) for x in link.axis]
        if link.kind == "revolute":
            qd = _joint_rates(g, link, v)
            qdd = _joint_rates(g, link, a)
            wj = vscale(g, qd, axis)
            dwi = vadd(g, vadd(g, dwi, vscale(g, qdd, axis)), cross(g, wi, wj))
            wi = vadd(g, wi, wj)
        elif link.kind == "prismatic":
            qd = _joint_rates(g, link, v)
            qdd = _joint_rates(g, link, a)
            ai = vadd(g, ai, vadd(g, vscale(g, qdd, axis), vscale(g, 2.0, cross(g, wi, vscale(g, qd, axis)))))
        w[i], dw[i], acc[i] = wi, dwi, ai
        mass = link.mass
        h = [float(x) for x in link.first_moment]
        I = [[float(x) for x in row] for row in link.inertia_origin]
        # force and moment about the link origin that the link's motion needs
        f[i] = vadd(g, vscale(g, mass, ai), vadd(g, cross(g, dwi, h), cross(g, wi, cross(g, wi, h))))
        m[i] = vadd(g, vadd(g, matvec(g, I, dwi), cross(g, wi, matvec(g, I, wi))), cross(g, h, ai))
    f[0], m[0] = [0.0] * 3, [0.0] * 3
    if springs and tree.springs:
        _spring_wrenches(g, tree, kin, f, m)
    tau_joint = [0.0] * n
    for i in range(n - 1, 0, -1):
        link = tree.links[i]
        axis = [float(x) for x in link.axis]
        if link.kind == "revolute":
            tau_joint[i] = dot(g, axis, m[i])
        elif link.kind == "prismatic":
            tau_joint[i] = dot(g, axis, f[i])
        R, p = kin.R_local[i], kin.p_local[i]
        fp = matvec(g, R, f[i])
        mp = vadd(g, matvec(g, R, m[i]), cross(g, p, fp))
        par = link.parent
        f[par] = vadd(g, f[par], fp)
        m[par] = vadd(g, m[par], mp)
    tau: list[Value] = [0.0] * tree.dof
    for i in range(1, n):
        link = tree.links[i]
        if link.coordinate >= 0:
            tau[link.coordinate] = g.add(tau[link.coordinate], g.mul(link.ratio, tau_joint[i]))
    return tau, (f[0], m[0])


def _spring_wrenches(g: Graph, tree: TreeConstants, kin: Kinematics, f, m):
    """Subtract each spring's pull on its two links from the forces their motion needs (a spring
    pulling B toward A helps the motors there): f_i -= R_i^T F, m_i -= r x (R_i^T F)."""
    for la, anchor_a, lb, anchor_b, K_eq, T0 in tree.springs:
        Ra, pa = kin.world(la)
        Rb, pb = kin.world(lb)
        A = vadd(g, pa, matvec(g, Ra, [float(x) for x in anchor_a]))
        B = vadd(g, pb, matvec(g, Rb, [float(x) for x in anchor_b]))
        d_vec = vsub(g, A, B)  # from B to A
        d = g.sqrt(dot(g, d_vec, d_vec))
        tension = g.add(T0, g.mul(K_eq, d))
        pull_on_b = vscale(g, g.div(tension, d), d_vec)  # toward A
        for link, anchor, force in ((lb, anchor_b, pull_on_b), (la, anchor_a, vscale(g, -1.0, pull_on_b))):
            if link == 0:
                continue
            R, _ = kin.world(link)
            local = mattvec(g, R, force)
            r = [float(x) for x in anchor]
            f[link] = vsub(g, f[link], local)
            m[link] = vsub(g, m[link], cross(g, r, local))


def shaking_wrench(g: Graph, tree: TreeConstants, q, v, a):
    """(F, M_O): the momentum rates about O in O (no gravity, no springs)."""
    _, (f0, m0) = newton_euler(g, tree, q, v, a, gravity=False, springs=False)
    return f0, m0


# ---- composite rigid bodies ------------------------------------------------------------------------
def _skew_mul_sym(g: Graph, p, h):
    """-[p]x[h]x - [h]x[p]x as a 3x3 of values (the first-moment shift of an inertia)."""
    # [a]x[b]x = b a^T - (a.b) I
    ab = dot(g, p, h)
    out = [[None] * 3 for _ in range(3)]
    for r in range(3):
        for c in range(3):
            val = g.neg(g.add(g.mul(h[r], p[c]), g.mul(p[r], h[c])))
            if r == c:
                val = g.add(val, g.mul(2.0, ab))
            out[r][c] = val
    return out


def _composite_bodies(g: Graph, tree: TreeConstants, kin: Kinematics):
    """Each link's composite body (its subtree) in its own frame: (mass, first moment, inertia
    about the link's origin), accumulated leaf to root."""
    n = len(tree.links)
    mass: list[Value] = [link.mass for link in tree.links]
    h: list = [[float(x) for x in link.first_moment] for link in tree.links]
    I: list = [[[float(x) for x in row] for row in link.inertia_origin] for link in tree.links]
    for i in range(n - 1, 0, -1):
        par = tree.links[i].parent
        R, p = kin.R_local[i], kin.p_local[i]
        hR = matvec(g, R, h[i])
        IR = matmul(g, matmul(g, R, I[i]), transpose(R))
        # inertia about the parent's origin: I' - m [p]x[p]x - [p]x[h']x - [h']x[p]x
        pp = dot(g, p, p)
        shift_m = [[g.mul(mass[i], g.sub(pp if r == c else 0.0, g.mul(p[r], p[c]))) for c in range(3)] for r in range(3)]
        shift_h = _skew_mul_sym(g, p, hR)
        I[par] = [[g.add(I[par][r][c], g.add(IR[r][c], g.add(shift_m[r][c], shift_h[r][c])))
                   for c in range(3)] for r in range(3)]
        h[par] = vadd(g, h[par], vadd(g, hR, vscale(g, mass[i], p)))
        mass[par] = g.add(mass[par], mass[i])
    return mass, h, I


def _unit_momentum(g: Graph, link: Link, mass: Value, h, I):
    """(H about the link's origin, L) of a composite body moving at unit rate of its joint."""
    axis = [float(x) for x in link.axis]
    if link.kind == "revolute":
        return matvec(g, I, axis), cross(g, axis, h)
    return cross(g, h, axis), vscale(g, mass, axis)


def mass_matrix(g: Graph, tree: TreeConstants, q):
    """M(q) (dof x dof values, symmetric) by composite rigid bodies in link frames."""
    kin = Kinematics(g, tree, q)
    n = len(tree.links)
    mass, h, I = _composite_bodies(g, tree, kin)
    M_joint: dict[tuple[int, int], Value] = {}
    for i in range(1, n):
        link = tree.links[i]
        if link.coordinate < 0:
            continue
        H, L = _unit_momentum(g, link, mass[i], h[i], I[i])
        j = i
        while j > 0:
            lj = tree.links[j]
            if lj.coordinate >= 0:
                aj = [float(x) for x in lj.axis]
                M_joint[(i, j)] = dot(g, aj, H) if lj.kind == "revolute" else dot(g, aj, L)
            R, p = kin.R_local[j], kin.p_local[j]
            L = matvec(g, R, L)
            H = vadd(g, matvec(g, R, H), cross(g, p, L))
            j = lj.parent
    M: list[list[Value]] = [[0.0] * tree.dof for _ in range(tree.dof)]
    for (i, j), val in M_joint.items():
        ci, cj = tree.links[i].coordinate, tree.links[j].coordinate
        term = g.mul(tree.links[i].ratio * tree.links[j].ratio, val)
        M[ci][cj] = g.add(M[ci][cj], term)
        if i != j:
            M[cj][ci] = g.add(M[cj][ci], term)
    return M


def center_of_mass(g: Graph, tree: TreeConstants, q):
    kin = Kinematics(g, tree, q)
    total = sum(link.mass for link in tree.links)
    moment = [0.0, 0.0, 0.0]
    for i, link in enumerate(tree.links):
        if link.mass == 0.0:
            continue
        R, p = kin.world(i)
        moment = vadd(g, moment, vadd(g, vscale(g, link.mass, p), matvec(g, R, [float(x) for x in link.first_moment])))
    return vscale(g, 1.0 / total, moment) if total > 0 else [0.0, 0.0, 0.0]


def frame_placement(g: Graph, tree: TreeConstants, q, frame: str):
    """(R, p) of a named frame in O."""
    kin = Kinematics(g, tree, q)
    link, P = tree.frames[frame]
    Rl, pl = kin.world(link)
    R = matmul(g, Rl, [[float(x) for x in row] for row in P[:3, :3]])
    p = vadd(g, pl, matvec(g, Rl, [float(x) for x in P[:3, 3]]))
    return R, p


def momentum_matrix(g: Graph, tree: TreeConstants, q):
    """A(q) (6 x dof values, linear rows first) with [P; H_O] = A(q) v: the momentum of each
    coordinate's subtree moving alone at unit rate, from the composite bodies."""
    kin = Kinematics(g, tree, q)
    n = len(tree.links)
    mass, h, I = _composite_bodies(g, tree, kin)
    A: list[list[Value]] = [[0.0] * tree.dof for _ in range(6)]
    for i in range(1, n):
        link = tree.links[i]
        if link.coordinate < 0:
            continue
        H, L = _unit_momentum(g, link, mass[i], h[i], I[i])
        Rw, pw = kin.world(i)
        Lw = matvec(g, Rw, L)
        Hw = vadd(g, matvec(g, Rw, H), cross(g, pw, Lw))
        k = link.coordinate
        for r in range(3):
            A[r][k] = g.add(A[r][k], g.mul(link.ratio, Lw[r]))
            A[3 + r][k] = g.add(A[3 + r][k], g.mul(link.ratio, Hw[r]))
    return A


def base_reaction(g: Graph, tree: TreeConstants, q, v, a):
    """(force, moment about O): dP/dt - m g and dH_O/dt - (m c) x g over the moving bodies."""
    F, M = shaking_wrench(g, tree, q, v, a)
    kin = Kinematics(g, tree, q)
    grav = [float(x) for x in tree.gravity]
    mass = 0.0
    moment = [0.0, 0.0, 0.0]
    for i, link in enumerate(tree.links):
        if not link.moves or link.mass == 0.0:
            continue
        R, p = kin.world(i)
        mass += link.mass
        moment = vadd(g, moment, vadd(g, vscale(g, link.mass, p), matvec(g, R, [float(x) for x in link.first_moment])))
    force = vsub(g, F, [mass * x for x in grav])
    torque = vsub(g, M, cross(g, moment, grav))
    return force, torque


# ---- closed loops --------------------------------------------------------------------------------
def loop_residual(g: Graph, tree: TreeConstants, q) -> list:
    """Phi(q), the closure equations of every loop (algorithm/loops.hpp), with d = p_B - p_A:
    point d (3); planar_point [x_A . d, y_A . d] (2); axis d and [z_A . x_B, z_A . y_B] (5);
    weld d and the skew part of R_B R_A^T (6: the same manifold as the library's rotation
    vector near the closure, hence the same solution, velocities and accelerations)."""
    kin = Kinematics(g, tree, q)
    phi: list = []
    for kind, frame_a, frame_b in tree.loops:
        Ra, pa = _frame(g, kin, tree, frame_a)
        Rb, pb = _frame(g, kin, tree, frame_b)
        d = vsub(g, pb, pa)
        col = lambda R, k: [R[0][k], R[1][k], R[2][k]]  # noqa: E731
        if kind == "point":
            phi += d
        elif kind == "planar_point":
            phi += [dot(g, col(Ra, 0), d), dot(g, col(Ra, 1), d)]
        elif kind == "axis":
            phi += d + [dot(g, col(Ra, 2), col(Rb, 0)), dot(g, col(Ra, 2), col(Rb, 1))]
        elif kind == "weld":
            R = matmul(g, Rb, transpose(Ra))
            phi += d + [g.mul(0.5, g.sub(R[2][1], R[1][2])), g.mul(0.5, g.sub(R[0][2], R[2][0])),
                        g.mul(0.5, g.sub(R[1][0], R[0][1]))]
        else:  # pragma: no cover - the model knows no other type
            raise ValueError(f"loop type {kind!r}")
    return phi


def _frame(g: Graph, kin: Kinematics, tree: TreeConstants, frame: str):
    link, P = tree.frames[frame]
    Rl, pl = kin.world(link)
    R = matmul(g, Rl, [[float(x) for x in row] for row in P[:3, :3]])
    p = vadd(g, pl, matvec(g, Rl, [float(x) for x in P[:3, 3]]))
    return R, p


def _passive_columns(g: Graph, tree: TreeConstants, q, phi):
    """A° = dPhi/dq° column by column, its normal matrix A°^T A° and that matrix's LDL^T."""
    columns = [directional_derivative(g, phi, {q[p].id: 1.0}) for p in tree.passive]
    n = len(columns)
    N: list[list[Value]] = [[0.0] * n for _ in range(n)]
    for i in range(n):
        for j in range(i, n):
            N[i][j] = N[j][i] = dot(g, columns[i], columns[j])
    return columns, ldlt_factor(g, N)


def newton_step(g: Graph, tree: TreeConstants, q):
    """One Gauss-Newton step of the passive coordinates on Phi(q) = 0 (the normal equations of
    A°, as the library): the new passive values and Phi(q), the residual before the step."""
    phi = loop_residual(g, tree, q)
    columns, factor = _passive_columns(g, tree, q, phi)
    delta = ldlt_apply(g, factor, [g.neg(dot(g, c, phi)) for c in columns])
    return [g.add(q[p], delta[i]) for i, p in enumerate(tree.passive)], phi


def closed_projection(g: Graph, tree: TreeConstants, q, v_actuated, a_actuated, w=None):
    """At a closed q: v = C v#, a = C a# + c (full dof), from A°, A#, gamma = dA/dt v.

    gamma is the closures' second time derivative at zero acceleration, from the links' angular
    velocities and velocity-product accelerations (`loop_velocity_product`). Given `w`, spare
    inputs (one per coordinate), it is derived instead by forward mode twice with v held constant
    (about three times the operations; kept as the independent reference of the tests)."""
    phi = loop_residual(g, tree, q)
    columns, factor = _passive_columns(g, tree, q, phi)
    act = tree.actuated

    def solve(b):
        return ldlt_apply(g, factor, [g.neg(dot(g, c, b)) for c in columns])

    Aa_v = directional_derivative(g, phi, {q[k].id: v_actuated[i] for i, k in enumerate(act)})
    v_passive = solve(Aa_v)
    v: list[Value] = [0.0] * tree.dof
    for i, k in enumerate(act):
        v[k] = v_actuated[i]
    for i, k in enumerate(tree.passive):
        v[k] = v_passive[i]
    if w is None:
        gamma = loop_velocity_product(g, tree, Kinematics(g, tree, q), v)
    else:  # the same by forward mode twice along spare inputs w, then w = v (the reference)
        seeds = {q[k].id: w[k] for k in range(tree.dof)}
        gamma_w = directional_derivative(g, directional_derivative(g, phi, seeds), seeds)
        gamma = substitute(g, gamma_w, {w[k].id: v[k] for k in range(tree.dof)})
    Aa_a = directional_derivative(g, phi, {q[k].id: a_actuated[i] for i, k in enumerate(act)})
    a_passive = solve([g.add(x, y) for x, y in zip(Aa_a, gamma)])
    a: list[Value] = [0.0] * tree.dof
    for i, k in enumerate(act):
        a[k] = a_actuated[i]
    for i, k in enumerate(tree.passive):
        a[k] = a_passive[i]
    return v, a



def closed_actuated_forces(g: Graph, tree: TreeConstants, q, v, a):
    """tau# = C^T tau(q, v, a) at a closed q: the tree's inverse dynamics (gravity and springs)
    projected on the actuated coordinates, C^T tau = tau_act - A#^T A° N^-1 tau° (N = A°^T A°,
    as v° = -N^-1 A°^T A# v#)."""
    tau, _ = newton_euler(g, tree, q, v, a, gravity=True, springs=True)
    phi = loop_residual(g, tree, q)
    columns, factor = _passive_columns(g, tree, q, phi)
    y = ldlt_apply(g, factor, [tau[k] for k in tree.passive])
    z = [0.0] * len(phi)
    for c, yi in zip(columns, y):
        z = [g.add(zr, g.mul(cr, yi)) for zr, cr in zip(z, c)]
    out = []
    for k in tree.actuated:
        column = directional_derivative(g, phi, {q[k].id: 1.0})
        out.append(g.sub(tau[k], dot(g, column, z)))
    return out

# ---- velocity products of the closures -----------------------------------------------------------
def _link_rates(g: Graph, tree: TreeConstants, kin: Kinematics, v):
    """Per link, in O: angular velocity w, origin velocity pv, and at zero joint accelerations the
    angular acceleration dw and origin acceleration pa (the velocity-product terms)."""
    n = len(tree.links)
    zero = [0.0, 0.0, 0.0]
    w, pv, dw, pa = [zero] * n, [zero] * n, [zero] * n, [zero] * n
    for i in range(1, n):
        link = tree.links[i]
        par = link.parent
        R, p = kin.world(i)
        _, p_par = kin.world(par)
        r = vsub(g, p, p_par)
        wp, dwp = w[par], dw[par]
        pv_i = vadd(g, pv[par], cross(g, wp, r))
        pa_i = vadd(g, pa[par], vadd(g, cross(g, dwp, r), cross(g, wp, cross(g, wp, r))))
        rate = _joint_rates(g, link, v)
        w_i, dw_i = wp, dwp
        if link.kind in ("revolute", "prismatic"):
            u = vscale(g, rate, matvec(g, R, [float(x) for x in link.axis]))  # joint rate x axis in O
            if link.kind == "revolute":
                w_i = vadd(g, wp, u)
                dw_i = vadd(g, dwp, cross(g, wp, u))
            else:
                pv_i = vadd(g, pv_i, u)
                pa_i = vadd(g, pa_i, vscale(g, 2.0, cross(g, wp, u)))
        w[i], dw[i], pv[i], pa[i] = w_i, dw_i, pv_i, pa_i
    return w, pv, dw, pa


def loop_velocity_product(g: Graph, tree: TreeConstants, kin: Kinematics, v) -> list:
    """gamma = d/dt(A(q)) v: the second time derivative of `loop_residual` along the motion of
    rates v (every coordinate) with zero accelerations, from the frames' velocities and
    velocity-product accelerations (one pass over the links, 3-vectors: no second derivatives of
    rotation matrices)."""
    w, pv, dw, pa = _link_rates(g, tree, kin, v)

    def frame_motion(name: str):
        """(axes e_k, de_k, dde_k as columns; point x, dx, ddx) of a named frame, in O."""
        link, _ = tree.frames[name]
        R, x = _frame(g, kin, tree, name)
        _, p = kin.world(link)
        rho = vsub(g, x, p)
        dx = vadd(g, pv[link], cross(g, w[link], rho))
        ddx = vadd(g, pa[link], vadd(g, cross(g, dw[link], rho), cross(g, w[link], cross(g, w[link], rho))))
        axes = [[R[0][k], R[1][k], R[2][k]] for k in range(3)]
        d_axes = [cross(g, w[link], e) for e in axes]
        dd_axes = [vadd(g, cross(g, dw[link], e), cross(g, w[link], de)) for e, de in zip(axes, d_axes)]
        return (axes, d_axes, dd_axes), (x, dx, ddx)

    def second(a, b):
        """d2/dt2 (a . b) for a = (a, da, dda), b = (b, db, ddb)."""
        return g.add(g.add(dot(g, a[2], b[0]), g.mul(2.0, dot(g, a[1], b[1]))), dot(g, a[0], b[2]))

    gamma: list = []
    for kind, frame_a, frame_b in tree.loops:
        (ea, dea, ddea), xa = frame_motion(frame_a)
        (eb, deb, ddeb), xb = frame_motion(frame_b)
        d = [vsub(g, xb[k], xa[k]) for k in range(3)]  # d, its rate and acceleration
        col = lambda e, de, dde, k: (e[k], de[k], dde[k])  # noqa: E731
        if kind == "point":
            gamma += d[2]
        elif kind == "planar_point":
            gamma += [second(col(ea, dea, ddea, 0), d), second(col(ea, dea, ddea, 1), d)]
        elif kind == "axis":
            za = col(ea, dea, ddea, 2)
            gamma += d[2] + [second(za, col(eb, deb, ddeb, 0)), second(za, col(eb, deb, ddeb, 1))]
        elif kind == "weld":
            # R = R_B R_A^T = sum_k b_k a_k^T: R'' = sum_k b''_k a_k^T + 2 b'_k a'_k^T + b_k a''_k^T
            def entry(r, c):
                out = 0.0
                for k in range(3):
                    out = g.add(out, g.add(g.add(g.mul(ddeb[k][r], ea[k][c]), g.mul(2.0, g.mul(deb[k][r], dea[k][c]))),
                                           g.mul(eb[k][r], ddea[k][c])))
                return out
            gamma += d[2] + [g.mul(0.5, g.sub(entry(2, 1), entry(1, 2))), g.mul(0.5, g.sub(entry(0, 2), entry(2, 0))),
                             g.mul(0.5, g.sub(entry(1, 0), entry(0, 1)))]
        else:  # pragma: no cover - the model knows no other type
            raise ValueError(f"loop type {kind!r}")
    return gamma
