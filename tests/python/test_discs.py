"""Coutinho & Hess Coelho, counter-rotating discs: acceptance of the four balanced mechanisms,
an independent energy/Lagrange check (sympy), Pinocchio and KDL on the arm links, the paper's
two-stage coupling vs the C++ evaluator, the corrected closed forms (k_i written here from the
equations, not imported), the printed equations that fail, decoupled control, and the runner."""
import json
from functools import lru_cache

import numpy as np
import pytest

from mechbal import _core
from mechbal.papers.discs import coupling as cp
from mechbal.papers.discs.runner import parameters_from_config
from mechbal.config import ConfigError, read_case
from mechbal.papers import discs as dz

CASES = {"planar3r": "discs-3r", "spatial3r": "discs-spatial", "scara": "scara",
         "fivebar": "five-bar"}


@lru_cache(maxsize=None)
def params(kind):
    return parameters_from_config(kind, read_case(CASES[kind]))


def k_closed_form(kind, p):
    """eqs 16, 27 (corrected: l2 where l1 is printed), 37 (general l2) and the 5R, from the
    derivation, independently of mechbal.papers.discs."""
    if kind == "planar3r":
        l1, l2, m1, m2, m3 = (p[k] for k in ("l1", "l2", "m1", "m2", "m3"))
        J = [None] + [p[f"Jx{i}"] for i in range(1, 8)]
        X = J[2] + J[3] + J[4] + J[6] + J[7] + m3 * l2 ** 2 + m3 ** 2 * l2 ** 2 / m2
        return [sum(J[1:]) + m2 * l1 ** 2 + m3 * (l1 ** 2 + l2 ** 2)
                + l1 ** 2 * (m2 + m3) ** 2 / m1 + l2 ** 2 * m3 ** 2 / m2,
                X + X ** 2 / J[5], (J[3] + J[6]) * (J[3] + J[6] + J[7]) / J[7]]
    if kind == "spatial3r":
        l1, l2, m2, m3 = (p[k] for k in ("l1", "l2", "m2", "m3"))
        return [sum(p[f"Jz{i}"] for i in range(1, 6)) + m2 * l1 ** 2 + m3 * (l1 ** 2 + l2 ** 2)
                + l2 ** 2 * m3 ** 2 / m2,
                p["Jx2"] + p["Jx3"] + p["Jx4"] + p["Jx5"] + m3 * l2 ** 2 + l2 ** 2 * m3 ** 2 / m2,
                (p["Jx3"] + p["Jx4"]) * (p["Jx3"] + p["Jx4"] + p["Jx5"]) / p["Jx5"]]
    if kind == "scara":
        l1, l2, m1, m2, m3 = (p[k] for k in ("l1", "l2", "m1", "m2", "m3"))
        mu = m3 * l2 ** 2 * (1 + m3 / m2)
        Y = p["Jx2"] + p["Jx3"] + p["Jx4"] + mu
        return [sum(p[f"Jx{i}"] for i in range(1, 6)) + (m2 + m3) * l1 ** 2
                + l1 ** 2 * (m2 + m3) ** 2 / m1 + mu, Y * (Y + p["Jx5"]) / p["Jx5"], m3]
    b = dz.balance_fivebar(p)["lg"]
    return [p["Jp1"] + p["mp1"] * b["cp1"] ** 2 + (p["md1"] + p["mP"]) * p["a1"] ** 2
            + p["Jd2"] + p["md2"] * b["cd2"] ** 2,
            p["Jp2"] + p["mp2"] * b["cp2"] ** 2 + (p["md2"] + p["mP"]) * p["a2"] ** 2
            + p["Jd1"] + p["md1"] * b["cd1"] ** 2]


@lru_cache(maxsize=None)
def sampled(kind, balanced, n=1000):
    q, qd = dz.sample_states(kind, n, np.random.default_rng(11))
    return dz.evaluate(kind, dz.design(kind, params(kind), balanced), q, qd)


@pytest.mark.parametrize("kind", dz.MECHANISMS)
def test_balanced_mass_matrix_is_constant_diagonal_and_free_of_velocity_and_gravity(kind):
    M, v, g = sampled(kind, True)
    M0, v0, g0 = sampled(kind, False)
    assert M.shape[0] == 1000
    n = M.shape[1]
    diag = np.einsum("nii->ni", M)
    off = np.abs(M - diag[:, :, None] * np.eye(n))
    assert np.max(off.max(axis=(1, 2)) / diag.min(axis=1)) <= 1e-12
    assert np.max((diag.max(0) - diag.min(0)) / diag.mean(0)) <= 1e-12
    k = np.array(k_closed_form(kind, params(kind)))
    assert np.max(np.abs(diag - k) / k) <= 1e-12
    assert np.max(np.abs(v)) <= 1e-12 * np.max(np.abs(v0))
    assert np.max(np.abs(g)) <= 1e-12 * np.max(np.abs(g0))
    # the unbalanced baseline really is coupled and gravity-loaded (the test can fail)
    d0 = np.einsum("nii->ni", M0)
    assert np.max(np.abs(M0 - d0[:, :, None] * np.eye(n))) > 1e-2 * d0.min()
    assert np.max(np.abs(g0)) > 1.0
    # and the library's own k agree with the equations written above
    assert np.allclose(dz.BALANCE[kind](params(kind))["k"], k, rtol=1e-14)


# ---- independent check: energies of all bodies -> Lagrange (sympy, built once per mechanism) ----
def _bodies_symbolic(kind):
    sp = pytest.importorskip("sympy")
    n = 2 if kind == "fivebar" else 3
    q, qd = sp.symbols(f"q1:{n + 1}"), sp.symbols(f"qd1:{n + 1}")
    P = {}

    def s(name):
        return P.setdefault(name, sp.Symbol(name))

    def Rx(a):
        return sp.Matrix([[1, 0, 0], [0, sp.cos(a), -sp.sin(a)], [0, sp.sin(a), sp.cos(a)]])

    def Rz(a):
        return sp.Matrix([[sp.cos(a), -sp.sin(a), 0], [sp.sin(a), sp.cos(a), 0], [0, 0, 1]])

    y = lambda L: sp.Matrix([0, L, 0])  # noqa: E731
    J = lambda i: (s(f"Jx{i}"), s(f"Jy{i}"), s(f"Jz{i}"))  # noqa: E731
    if kind == "planar3r":
        # rotations about parallel axes add: R2 = Rx(q1 + q2) (keeps the expressions small)
        R1, R2, R3 = Rx(q[0]), Rx(q[0] + q[1]), Rx(q[0] + q[1] + q[2])
        o2 = R1 * y(s("l1")); o3 = o2 + R2 * y(s("l2"))  # noqa: E702
        bodies = [(s("m1"), R1 * y(s("lg1")), R1, J(1)), (s("m2"), o2 + R2 * y(s("lg2")), R2, J(2)),
                  (s("m3"), o3 + R3 * y(s("lg3")), R3, J(3))]
        for i, a in ((4, q[0] + q[1]), (5, q[0] + s("beta") * q[1]), (6, q[0] + q[1] + q[2]),
                     (7, q[0] + q[1] + s("gamma") * q[2])):
            bodies.append((0, None, Rx(a), J(i)))
    elif kind == "spatial3r":
        R1, R2, R3 = Rz(q[0]), Rz(q[0]) * Rx(q[1]), Rz(q[0]) * Rx(q[1] + q[2])
        o2 = R1 * y(s("l1")); o3 = o2 + R2 * y(s("l2"))  # noqa: E702
        bodies = [(s("m1"), sp.zeros(3, 1), R1, J(1)), (s("m2"), o2 + R2 * y(s("lg2")), R2, J(2)),
                  (s("m3"), o3 + R3 * y(s("lg3")), R3, J(3))]
        for i, r in ((4, 1), (5, s("beta"))):
            bodies.append((0, None, R1 * Rx(q[1] + r * q[2]), J(i)))
    elif kind == "scara":
        R1, R2 = Rx(q[0]), Rx(q[0] + q[1])
        o2 = R1 * y(s("l1")); o3 = o2 + R2 * y(s("l2")) + R2 * sp.Matrix([q[2], 0, 0])  # noqa: E702
        bodies = [(s("m1"), R1 * y(s("lg1")), R1, J(1)), (s("m2"), o2 + R2 * y(s("lg2")), R2, J(2)),
                  (s("m3"), o3, R2, J(3))]
        for i, r in ((4, 1), (5, s("beta"))):
            bodies.append((0, None, Rx(q[0] + r * q[1]), J(i)))
    else:  # parallelogram 5R: distal links parallel to the opposite proximal links
        e = lambda t: sp.Matrix([0, sp.cos(t), sp.sin(t)])  # noqa: E731
        B1, B2 = s("a1") * e(q[0]), s("a2") * e(q[1])
        Pp = B1 + B2
        bodies = [(s("mp1"), s("cp1") * e(q[0]), Rx(q[0]), J("p1")),
                  (s("mp2"), s("cp2") * e(q[1]), Rx(q[1]), J("p2")),
                  (s("md1"), B1 + s("cd1") * e(q[1]), Rx(q[1]), J("d1")),
                  (s("md2"), B2 + s("cd2") * e(q[0]), Rx(q[0]), J("d2")),
                  (s("mP"), Pp, sp.eye(3), (0, 0, 0))]
    return sp, q, qd, bodies, P


def _pythagoras(sp, e):
    """Exact normal form of a polynomial in sin/cos: expand, then replace sin(a)^k (k >= 2) by
    (1 - cos(a)^2) sin(a)^(k-2) until no such power is left (sin^2 + cos^2 = 1 is the only
    relation; identical to trigsimp on these expressions, and ~100x faster)."""
    e = sp.expand(e)
    while True:
        pows = [p for p in e.atoms(sp.Pow)
                if isinstance(p.base, sp.sin) and p.exp.is_Integer and p.exp >= 2]
        if not pows:
            return e
        e = sp.expand(e.xreplace({p: (1 - sp.cos(p.base.args[0]) ** 2)
                                  * sp.sin(p.base.args[0]) ** (p.exp - 2) for p in pows}))


@lru_cache(maxsize=None)
def lagrange_torque(kind):
    """tau = d/dt dL/dqd - dL/dq from T = sum 1/2 m |r_G'|^2 + 1/2 w^T J w, with the body-frame
    angular velocity w from [w]x = R^T dR/dt (reduced per body with sin^2 = 1 - cos^2), and
    V = sum m g z_G."""
    sp, q, qd, bodies, P = _bodies_symbolic(kind)
    qdd = sp.symbols(f"qdd1:{len(q) + 1}")
    T = V = 0
    for m, rG, R, (Jx, Jy, Jz) in bodies:
        if m != 0:
            rd = rG.jacobian(q) * sp.Matrix(qd)
            T += m * (rd.T * rd)[0] / 2
            V += m * dz.G * rG[2]
        W = R.T * sum((R.diff(a) * b for a, b in zip(q, qd)), sp.zeros(3, 3))
        w = [_pythagoras(sp, x) for x in (W[2, 1], W[0, 2], W[1, 0])]
        T += (Jx * w[0] ** 2 + Jy * w[1] ** 2 + Jz * w[2] ** 2) / 2
    tau = []
    for i in range(len(q)):
        p_i = sp.diff(T, qd[i])
        tau.append(sum(sp.diff(p_i, qd[j]) * qdd[j] + sp.diff(p_i, q[j]) * qd[j]
                       for j in range(len(q))) - sp.diff(T, q[i]) + sp.diff(V, q[i]))
    names = sorted(P)
    return names, sp.lambdify([q, qd, qdd] + [P[k] for k in names], tau, "numpy", cse=True)


def _symbol_values(kind, d):
    vals = dict(d)
    if kind == "fivebar":
        for key in ("p1", "p2", "d1", "d2"):
            vals[f"Jx{key}"], vals[f"Jy{key}"], vals[f"Jz{key}"] = d[f"inertia_{key}"]
    elif not d.get("discs", True):
        for i in (4, 5, 6, 7):
            vals[f"Jx{i}"] = vals[f"Jy{i}"] = vals[f"Jz{i}"] = 0.0
    return vals


def _perturbed(kind, rng):
    """Balanced design, then every physical parameter off by up to 20 % (non-axisymmetric
    discs too, so the disc gyroscopic term matters)."""
    d = dz.design(kind, params(kind), True)
    for k in list(d):
        if k[:1] in ("m", "l", "c") and isinstance(d[k], float) and k != "mP1_share":
            d[k] *= 1 + rng.uniform(-0.2, 0.2)
    for i in range(1, 8):  # scale each body's inertia as a whole (stays physical)
        f = 1 + rng.uniform(-0.2, 0.2)
        for a in "xyz":
            if f"J{a}{i}" in d:
                d[f"J{a}{i}"] *= f
    if kind in ("spatial3r", "planar3r"):
        d["Jy5"] = d["Jz5"] * 0.7  # non-axisymmetric disc: the gyroscopic term matters
        d["Jx5"] = 0.95 * (d["Jy5"] + d["Jz5"])  # still a physical body
    return d


@pytest.mark.parametrize("kind", dz.MECHANISMS)
def test_torques_agree_with_the_lagrangian_of_all_bodies(kind):
    names, f = lagrange_torque(kind)
    rng = np.random.default_rng(3)
    designs = {"balanced": dz.design(kind, params(kind), True),
               "unbalanced": dz.design(kind, params(kind), False),
               "perturbed": _perturbed(kind, rng)}
    if kind == "fivebar":  # the symbolic model is the parallelogram: keep its geometry exact
        designs["perturbed"].update({k: params(kind)[k] for k in ("a1", "a2", "b1", "b2")})
    for label, d in designs.items():
        q, qd = dz.sample_states(kind, 30, rng)
        qdd = rng.uniform(-3, 3, q.shape)
        M, v, g = dz.evaluate(kind, d, q, qd)
        tau = np.einsum("nij,nj->ni", M, qdd) + v + g
        vals = _symbol_values(kind, d)
        ref = np.array([np.array(f(a, b, c, *[vals[k] for k in names]), float).ravel()
                        for a, b, c in zip(q, qd, qdd)])
        err = np.max(np.abs(ref - tau), axis=1) / np.max(np.abs(ref), axis=1)
        assert np.max(err) < 1e-8, (label, np.max(err))


# ---- independent engines on the unbalanced arm links ----
@pytest.mark.parametrize("kind", ["planar3r", "scara", "spatial3r"])
def test_unbalanced_arm_links_match_pinocchio_and_kdl(kind):
    pin = pytest.importorskip("pinocchio")
    d = dz.design(kind, params(kind), False)
    joints, links, discs = dz.serial_structure(kind, d)
    assert discs == []
    chain = dz.arm_mechanism(joints, links).model
    pm = pin.Model()
    parent = 0
    for j, b in zip(joints, links):
        jm = (pin.JointModelRevoluteUnaligned(j.axis) if j.type == "R"
              else pin.JointModelPrismaticUnaligned(j.axis))
        parent = pm.addJoint(parent, jm, pin.SE3(np.eye(3), j.offset), f"j{parent}")
        pm.appendBodyToJoint(parent, pin.Inertia(b.mass, b.com, b.inertia), pin.SE3.Identity())
    pm.gravity.linear = np.array([0.0, 0.0, -9.81])
    pd = pm.createData()
    rng = np.random.default_rng(5)
    q, qd = dz.sample_states(kind, 40, rng)
    qdd = rng.uniform(-3, 3, q.shape)
    ours = dz.disc_design_mechanism(kind, d).inverse_dynamics(q, qd, qdd)
    ref = np.array([pin.rnea(pm, pd, a, b, c) for a, b, c in zip(q, qd, qdd)])
    kdl = _core.KdlChainDynamics(chain).inverse_dynamics(q, qd, qdd)["tau"]
    scale = np.max(np.abs(ref), axis=1, keepdims=True)
    assert np.max(np.abs(ours - ref) / scale) < 1e-10
    assert np.max(np.abs(kdl - ref) / scale) < 1e-10


@pytest.mark.parametrize("kind", ["planar3r", "spatial3r", "scara"])
def test_paper_two_stage_coupling_equals_the_general_single_stage_model(kind):
    """Arm model (M#, v#, g#) first, then discs (the paper's procedure, Python) == the general
    model (dz.evaluate: discs as gear couplings), on a perturbed design with non-axisymmetric
    discs."""
    rng = np.random.default_rng(8)
    d = _perturbed(kind, rng)
    q, qd = dz.sample_states(kind, 20, rng)
    M, v, g = dz.evaluate(kind, d, q, qd)
    joints, links, discs = dz.serial_structure(kind, d)
    for k in range(len(q)):
        ref = cp.arm_with_discs(joints, links, discs, q[k], qd[k])
        s = np.max(np.abs(ref.mass))
        assert np.allclose(M[k], ref.mass, atol=1e-12 * s)
        assert np.allclose(v[k], ref.velocity, atol=1e-12 * max(1.0, np.max(np.abs(ref.velocity))))
        assert np.allclose(g[k], ref.gravity, atol=1e-12 * max(1.0, np.max(np.abs(ref.gravity))))


# ---- the printed equations that fail, and the corrected ones that hold ----
def test_printed_spatial_equations_fail_and_corrections_hold():
    p = params("spatial3r")
    l1, l2, m2, m3 = p["l1"], p["l2"], p["m2"], p["m3"]
    M, _, _ = sampled("spatial3r", True)
    k = np.einsum("nii->ni", M).mean(0)
    # C7, C8: eq 27 as printed (l1^2 m3^2/m2) vs the model's constant diagonal
    k1_printed = (sum(p[f"Jz{i}"] for i in range(1, 6)) + m2 * l1 ** 2 + m3 * (l1 ** 2 + l2 ** 2)
                  + l1 ** 2 * m3 ** 2 / m2)
    k2_printed = p["Jx2"] + p["Jx3"] + p["Jx4"] + p["Jx5"] + m3 * l2 ** 2 + l1 ** 2 * m3 ** 2 / m2
    assert abs(k1_printed - k[0]) > 1e-2 * k[0] and abs(k2_printed - k[1]) > 1e-2 * k[1]
    # C2: eq 25 as printed (Jy2 = Jz2, Jy3 = Jz3 + mu) leaves D'11 varying
    d = dz.design("spatial3r", p, True)
    mu = m3 * l2 ** 2 * (1 + m3 / m2)
    d.update(Jy2=p["Jz2"], Jy3=p["Jz3"] + mu)
    # (with Jx2 = 0.47 the printed condition is not even a physical body: the C++ model refuses
    # it, so evaluate with the Python coupling, which does not validate)
    joints, links, discs = dz.serial_structure("spatial3r", d)
    with pytest.raises(ValueError, match="triangle"):
        dz.disc_design_mechanism("spatial3r", d)
    q, qd = dz.sample_states("spatial3r", 40, np.random.default_rng(1))
    out = [cp.arm_with_discs(joints, links, discs, a, b) for a, b in zip(q, qd)]
    D11 = np.array([o.mass[0, 0] for o in out])
    assert np.ptp(D11) > 0.1 * np.mean(D11)
    assert max(np.max(np.abs(o.velocity)) for o in out) > 0.1


def test_disc_gyroscopic_term_is_needed_c5():
    """Eq 20 writes v = 0 for the spatial discs: dropping omega x J omega disagrees with the
    Lagrangian (non-axisymmetric discs), keeping it agrees."""
    names, f = lagrange_torque("spatial3r")
    d = dz.design("spatial3r", params("spatial3r"), True)
    d.update(Jy4=0.003, Jy5=0.03, Jz5=0.01, Jx5=0.035)
    q, qd = np.array([0.2, 0.4, -0.9]), np.array([1.0, 0.5, -1.5])
    joints, links, discs = dz.serial_structure("spatial3r", d)
    vals = _symbol_values("spatial3r", d)
    ref = np.array(f(q, qd, np.zeros(3), *[vals[k] for k in names]), float).ravel()
    full = cp.arm_with_discs(joints, links, discs, q, qd)
    assert np.allclose(full.velocity + full.gravity, ref, rtol=1e-10, atol=1e-12)
    # the paper's disc model: v_d = 0
    arm, kin = cp.arm_model(joints, links, q, qd)
    subs, rows, bias = [cp.Subsystem(arm.mass, arm.velocity, arm.gravity)], [], []
    for ds in discs:
        sub, Jd, b = cp.disc_subsystem(ds, kin, q, qd)
        subs.append(cp.Subsystem(sub.mass, np.zeros(3), sub.gravity))
        rows.append(Jd)
        bias.append(b)
    A = np.zeros((6, 9))
    A[0:3, :3], A[0:3, 3:6], A[3:6, :3], A[3:6, 6:9] = -rows[0], np.eye(3), -rows[1], np.eye(3)
    paper = cp.couple(subs, A, [0, 1, 2], -np.concatenate(bias), qd)
    assert np.max(np.abs(paper.velocity + paper.gravity - ref)) > 1e-3


def test_symbolic_coupling_derives_the_planar_gear_ratios_eq14():
    """Offline derivation with couple_symbolic: statically balanced planar 3R (eq 8) + four discs
    (constant C, eq 12); solving D'12 = D'13 = 0 gives eq 14."""
    sp = pytest.importorskip("sympy")
    q = sp.symbols("q1:4")
    l1, l2, m1, m2, m3 = sp.symbols("l1 l2 m1 m2 m3", positive=True)
    Jx = sp.symbols("Jx1:8", positive=True)
    beta, gamma = sp.symbols("beta gamma")
    lg = [-l1 * (m2 + m3) / m1, -l2 * m3 / m2, 0]
    a = [q[0], q[0] + q[1], q[0] + q[1] + q[2]]
    e = lambda t: sp.Matrix([sp.cos(t), sp.sin(t)])  # noqa: E731
    r = [lg[0] * e(a[0]), l1 * e(a[0]) + lg[1] * e(a[1]), l1 * e(a[0]) + l2 * e(a[1]) + lg[2] * e(a[2])]
    Ma = sp.zeros(3, 3)
    for i, m in enumerate((m1, m2, m3)):
        Jv = r[i].jacobian(q)
        Jw = sp.Matrix([[1 if j <= i else 0 for j in range(3)]])
        Ma += m * Jv.T * Jv + Jx[i] * Jw.T * Jw
    Ma = Ma.applyfunc(lambda x: sp.factor(_pythagoras(sp, sp.expand_trig(x))))  # exact normal form
    assert all(sp.diff(Ma, qq) == sp.zeros(3, 3) for qq in q)  # eq 9: constant after eq 8
    # discs 4..7: omega = theta1' + theta2' (4), + beta theta2' (5), ... (eq 11)
    Ad = -sp.Matrix([[1, 1, 0], [1, beta, 0], [1, 1, 1], [1, 1, gamma]])
    A = Ad.row_join(sp.eye(4))
    Mc, _, _, C = cp.couple_symbolic([Ma] + [sp.Matrix([[j]]) for j in Jx[3:]],
                                     [sp.zeros(3, 1)] + [sp.zeros(1, 1)] * 4,
                                     [sp.zeros(3, 1)] + [sp.zeros(1, 1)] * 4, A, [0, 1, 2])
    sol = sp.solve([sp.expand(Mc[0, 1]), sp.expand(Mc[0, 2])], [beta, gamma], dict=True)[0]
    X = Jx[1] + Jx[2] + Jx[3] + Jx[5] + Jx[6] + m3 * l2 ** 2 + m3 ** 2 * l2 ** 2 / m2
    # (rational functions, no trig left: cancel() == 0 is an exact identity test)
    assert sp.cancel(sol[beta] + X / Jx[4]) == 0
    assert sp.cancel(sol[gamma] + (Jx[2] + Jx[5]) / Jx[6]) == 0
    assert sp.cancel(Mc[1, 2].subs(sol)) == 0
    k2 = Mc[1, 1].subs(sol)
    assert sp.cancel(k2 - X * (X + Jx[4]) / Jx[4]) == 0


def test_general_five_bar_is_not_decoupled_but_is_statically_balanced():
    """C11: leg-wise static balancing of a non-parallelogram 5R removes gravity but leaves a
    varying, coupled mass matrix."""
    p = dict(params("fivebar"))
    p.update(d=0.12, b1=0.32, b2=0.34)
    d = dz.design("fivebar", p, True)
    rng = np.random.default_rng(2)
    q = np.stack([rng.uniform(0.2, 1.2, 100), rng.uniform(1.8, 2.8, 100)], 1)
    M, v, g = dz.evaluate("fivebar", d, q, rng.uniform(-2, 2, q.shape))
    m = dz.metrics(M, v, g)
    assert m["peak_gravity_torque"] < 1e-12
    assert m["offdiag_ratio"] > 0.1 and m["diag_variation"] > 0.1


def test_cpp_five_bar_equals_the_python_coupling_model():
    """mechbal._core.FiveBarDynamics (fixed-size CoupledProjection, 4x4 A° per tick) == the
    Python coupling (mechbal.papers.discs.fivebar_model), to 1e-12, on balanced, unbalanced,
    perturbed parallelogram and general (d > 0, b_i free) five-bars."""
    rng = np.random.default_rng(21)
    p = params("fivebar")
    general = dict(p, d=0.12, b1=0.32, b2=0.34)
    designs = {"balanced": dz.design("fivebar", p, True),
               "unbalanced": dz.design("fivebar", p, False),
               "perturbed": _perturbed("fivebar", rng),
               "general": dz.design("fivebar", general, True),
               "general_unbalanced": dz.design("fivebar", general, False)}
    worst = 0.0
    for label, d in designs.items():
        if label.startswith("general"):
            q = np.stack([rng.uniform(0.2, 1.2, 40), rng.uniform(1.8, 2.8, 40)], 1)
            qd = rng.uniform(-2, 2, q.shape)
        else:
            q, qd = dz.sample_states("fivebar", 40, rng)
        r = dz.fivebar_dynamics(d).evaluate(q, qd)
        assert np.all(r.status == 0) and np.all(r.ok), label
        for k in range(len(q)):
            ref = dz.fivebar_model(d, q[k], qd[k])
            s = np.max(np.abs(ref.mass))
            for ours, theirs in ((r.mass_matrix[k], ref.mass), (r.coriolis_torque[k], ref.velocity),
                                 (r.gravity_torque[k], ref.gravity)):
                err = np.max(np.abs(ours - theirs)) / max(s, np.max(np.abs(theirs)))
                worst = max(worst, err)
                assert err < 1e-12, (label, k, err)


def test_cpp_five_bar_singular_pose_gives_a_status_and_no_nan():
    d = dz.design("fivebar", params("fivebar"), True)
    dyn = dz.fivebar_dynamics(d)
    q = np.array([[0.4, 0.4], [0.4, 0.4 + np.pi], [0.4, 1.4]])
    r = dyn.evaluate(q, np.ones_like(q))
    assert list(r.ok) == [False, False, True]
    assert list(r.status) == [int(_core.Status.singular)] * 2 + [0]
    assert np.all(np.isfinite(r.mass_matrix)) and np.all(np.isfinite(r.coriolis_torque))
    assert np.all(r.reciprocal_condition[:2] < 1e-6) and r.reciprocal_condition[2] > 1e-3
    with pytest.raises(ValueError, match="singularity"):   # one sample: a ValueError
        dyn.evaluate(q[0], np.ones(2))
    with pytest.raises(ValueError, match="singular"):
        dz.evaluate("fivebar", d, q, np.ones_like(q))
    with pytest.raises(ValueError, match="five_bar.a1"):
        dz.fivebar_dynamics(dict(d, a1=-0.3))


@pytest.mark.parametrize("kind", ["planar3r", "spatial3r", "scara"])
def test_decoupled_controller_equals_computed_torque_on_the_balanced_model(kind):
    p = params(kind)
    k = dz.BALANCE[kind](p)["k"]
    kp, kd = np.array([100.0, 80.0, 60.0]), np.array([20.0, 18.0, 15.0])
    dc = _core.DecoupledJointController(np.asarray(k), kp, kd)
    ct = _core.ComputedTorque(_core.MechanismDynamics(dz.disc_design_mechanism(kind, dz.design(kind, p, True)).model),
                              kp, kd)
    rng = np.random.default_rng(4)
    for _ in range(50):
        x = [rng.uniform(-2, 2, 3) for _ in range(5)]
        t1, s1 = dc.step(*x)
        t2, s2 = ct.step(*x)
        assert s1 == s2 == _core.Status.ok
        assert np.allclose(t1, t2, rtol=1e-12, atol=1e-12 * np.max(np.abs(t2)))
    # the unbalanced model does not reduce to the decoupled law
    ct0 = _core.ComputedTorque(_core.MechanismDynamics(dz.disc_design_mechanism(kind, dz.design(kind, p, False)).model),
                               kp, kd)
    x = [rng.uniform(-2, 2, 3) for _ in range(5)]
    assert np.max(np.abs(ct0.step(*x)[0] - dc.step(*x)[0])) > 1e-2
    bad = x[:]
    bad[0] = np.array([np.nan, 0.0, 0.0])
    held = dc.last_command
    tau, s = dc.step(*bad)
    assert s == _core.Status.non_finite_input and np.array_equal(tau, held)


# ---- runner ----
@pytest.mark.parametrize("kind", dz.MECHANISMS)
def test_discs_case_runs_and_writes_the_summary(kind, tmp_path):
    from mechbal.cases import _load_runners, _RUNNERS

    _load_runners()
    cfg = read_case(CASES[kind])
    cfg["sampling"]["configurations"] = 40
    cfg["sensitivity"]["errors_pct"] = [5.0]
    cfg["trajectory"]["samples"] = 201
    s = _RUNNERS["discs"](cfg, tmp_path)
    saved = json.loads((tmp_path / "summary.json").read_text())
    assert (tmp_path / "joint_torques.png").stat().st_size > 1000
    for key in ("l_g", "k", "offdiag_ratio_before", "offdiag_ratio_after", "diag_variation_after",
                "peak_gravity_torque", "corrections", "sensitivity"):
        assert key in saved, key
    assert saved["offdiag_ratio_after"] < 1e-12 < saved["offdiag_ratio_before"]
    assert saved["peak_gravity_torque"]["after"] < 1e-12 * saved["peak_gravity_torque"]["before"]
    assert saved["decoupled_control"]["max_rel_difference"] < 1e-12
    assert len(saved["sensitivity"]) == len(cfg["sensitivity"]["parameters"])
    if kind != "fivebar":
        assert "beta" in saved
    if kind == "spatial3r":
        assert abs(saved["inertia_conditions"]["Jy2"] - s["inertia_conditions"]["Jy2"]) == 0
        assert {c["id"] for c in saved["corrections"]} >= {"C2", "C3", "C6", "C8"}
    # sized by mechbal.balance.moment on the [balance] table, the closed forms beside it
    d = saved["discs"]
    assert d["max_rel_difference"] < 1e-12 < d["tolerance_rel"]
    assert set(d["general_method"]) == set(d["closed_form"])
    sized = {"planar3r": ["beta", "gamma"], "spatial3r": ["Jy2", "Jy3", "beta"], "scara": ["beta"], "fivebar": []}
    assert d["sized_by_the_general_method"] == sized[kind]
    for key in sized[kind]:
        value = saved["inertia_conditions"][key] if key.startswith("Jy") else saved[key]
        assert value == d["general_method"][key] == pytest.approx(d["closed_form"][key], rel=1e-12)
    if kind != "fivebar":
        assert saved["k"] == d["general_method"]["k"]
    else:   # impossible with leg discs, and why: what remains is k1 + k2 + the discs' inertias
        assert not d["method"]["exact"] and d["method"]["limited_by"][0].startswith("impossible:")
    if kind == "fivebar":
        assert "FiveBarDynamics" in saved["decoupled_control"]["computed_torque_backend"]
    # bodies files: every link and disc, and the shaking wrench recomputed from the poses alone
    from mechbal.export import read_bodies, shaking_wrench_by_finite_differences

    sw = saved["shaking_wrench_on_trajectory"]
    n_links = {"fivebar": 5}.get(kind, 3)
    n_discs = {"planar3r": 4, "spatial3r": 2, "scara": 2}.get(kind, 0)
    for variant, nb in (("unbalanced", n_links), ("balanced", n_links + n_discs)):
        b = read_bodies(tmp_path / f"bodies_{variant}.npz")
        assert b["mass"].shape == (nb,) and b["com"].shape == (201, nb, 3)
        assert list(b["names"]) == sw[variant]["bodies"]
        F, M = shaking_wrench_by_finite_differences(b)
        sl = slice(3, -3)
        Fs = max(np.max(np.abs(b["shaking_force"])), 1e-3 * np.max(np.abs(b["shaking_moment"])))
        Ms = np.max(np.abs(b["shaking_moment"]))
        assert np.max(np.abs(F[sl] - b["shaking_force"][sl])) < 2e-3 * Fs, variant
        assert np.max(np.abs(M[sl] - b["shaking_moment"][sl])) < 2e-3 * Ms, variant
        assert sw[variant]["peak_shaking_force"] == pytest.approx(
            np.max(np.linalg.norm(b["shaking_force"], axis=1)), rel=1e-12)
        assert sw[variant]["peak_shaking_moment"] == pytest.approx(
            np.max(np.linalg.norm(b["shaking_moment"], axis=1)), rel=1e-12)
    if n_discs:  # the discs are there, massless (lumped into their carriers), spinning
        b = read_bodies(tmp_path / "bodies_balanced.npz")
        assert [str(x) for x in b["names"][n_links:]] == [f"disc{i + 4}" for i in range(n_discs)]
        assert np.all(b["mass"][n_links:] == 0.0)
        assert np.all(np.einsum("bii->bi", b["inertia_body"][n_links:]) > 0.0)
        R = b["rotation"][:, n_links:]
        assert np.allclose(np.einsum("nbji,nbjk->nbik", R, R), np.eye(3), atol=1e-12)
    if kind in ("planar3r", "fivebar"):
        # static balancing fixes the total centre of mass: no shaking force after, some before
        assert sw["balanced"]["peak_shaking_force"] < 1e-9 * sw["unbalanced"]["peak_shaking_force"]


def test_bad_configurations_are_refused_naming_the_field():
    cfg = read_case("discs-3r")
    cfg["parameters"]["m2"] = -3.0
    with pytest.raises(ConfigError, match=r"parameters\.m2"):
        parameters_from_config("planar3r", cfg)
    cfg = read_case("discs-3r")
    cfg["inertia"]["link1"] = [0.25, 1e-3, 1e-3]  # the reference's non-physical planar inertia
    with pytest.raises(ConfigError, match=r"inertia\.link1"):
        parameters_from_config("planar3r", cfg)
    cfg = read_case("discs-spatial")
    cfg["inertia"]["link2"] = [0.9, 0.41, 0.08]  # Jx2 > Jy2 + Jz2 after the eq 25 condition
    with pytest.raises(ConfigError, match=r"inertia\.link2"):
        parameters_from_config("spatial3r", cfg)
    from mechbal.cases import _load_runners, _RUNNERS

    _load_runners()
    cfg = read_case("five-bar")
    cfg["parameters"]["d"] = 0.1
    with pytest.raises(ConfigError, match="parallelogram"):
        _RUNNERS["discs"](cfg, None)


def test_the_general_computed_torque_runs_over_the_five_bar_closed_form():
    """FiveBarDynamics is an InverseDynamics back end (its binding adds no constructor to the
    general ComputedTorque): with zero tracking error the command is the closed form's inverse
    dynamics of the desired motion."""
    from mechbal import control

    fb = dz.FiveBarDynamics(dz.FiveBarParameters(
        a1=0.3, a2=0.25, b1=0.25, b2=0.3, mp1=1.0, mp2=1.0, md1=0.8, md2=0.8, mP=0.5, cp1=0.1,
        cp2=0.1, cd1=0.1, cd2=0.1, Jp1=0.01, Jp2=0.01, Jd1=0.01, Jd2=0.01))
    assert isinstance(fb, _core.InverseDynamics)
    ct = control.ComputedTorque(fb, kp=[100.0, 100.0], kd=[20.0, 20.0])
    q, v, a = np.array([0.6, 1.9]), np.array([0.3, -0.2]), np.array([1.0, 0.5])
    cmd = ct.step(q, v, q, v, a)
    assert cmd.status == 0
    np.testing.assert_allclose(cmd.joint_torque, fb.inverse_dynamics(q, v, a), rtol=1e-12, atol=1e-12)
    assert np.abs(cmd.joint_torque).max() > 0.1
