"""Issue 24: parsers that cannot crash or hang, cost linear in the mechanism's size, batch results
that cannot be mistaken, plausibility ranges, output folders that recover from a dead run.

Each test checks one line of the README's "Input guarantees". What could crash the interpreter
(a SIGSEGV in the XML reader) or hang it (a FIFO) runs in a subprocess with a timeout, so that a
regression fails the test instead of killing or blocking the whole run. Memory bounds are read
from ``resource.getrusage`` in a fresh subprocess (the growth of the peak resident size), never
from timings."""
from __future__ import annotations

import errno
import json
import math
import os
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.config import ConfigError
from mechbal.errors import PlausibilityWarning
from mechbal.mechanism import BatchArray

S = _core.Status
ROBOT = '<robot name="r">{}</robot>'
LINK = ('<link name="{n}"><inertial><origin xyz="0.1 0 0" rpy="0 0 0"/><mass value="{m}"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="{izz}"/></inertial></link>')
JOINT = ('<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/>'
         '<origin xyz="{xyz}" rpy="0 0 0"/><axis xyz="0 0 1"/>'
         '<limit lower="-3" upper="3" effort="10" velocity="5"/></joint>')


def urdf(links, joints):
    return ROBOT.format("".join(links) + "".join(joints))


def link(n, m="1.0", izz="0.01"):
    return LINK.format(n=n, m=m, izz=izz)


def joint(n, p, c, xyz="0.2 0 0"):
    return JOINT.format(n=n, p=p, c=c, xyz=xyz)


def run_python(code: str, timeout: float = 120.0) -> subprocess.CompletedProcess:
    """``code`` in a fresh interpreter (a crash or a hang fails the test, not the run)."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=timeout)


# ---- parsers: no crash, no hang, one-line errors ------------------------------------------------

def test_urdf_nested_100000_deep_is_a_one_line_error_not_a_crash(tmp_path):
    deep = tmp_path / "deep.urdf"
    deep.write_text('<robot name="r">' + "<a>" * 100_000 + "</a>" * 100_000 + "</robot>")
    r = run_python(f"""
        import mechbal
        try:
            mechbal.Mechanism.from_urdf({str(deep)!r})
        except mechbal.ConfigError as e:
            print("ERR", e)
        """)
    assert r.returncode == 0, (r.returncode, r.stderr[-400:])  # not -11 (SIGSEGV)
    out = r.stdout.strip()
    assert out.startswith("ERR") and len(out.splitlines()) == 1, out
    assert "nest more than 64 deep" in out and "line 1" in out
    r = run_python(f"""
        from mechbal.cli import main
        raise SystemExit(main(["run", {str(deep)!r}, "--out", {str(tmp_path / 'o')!r}]))
        """)
    assert r.returncode == 2, (r.returncode, r.stderr[-400:])
    assert len(r.stderr.strip().splitlines()) == 1 and "deep" in r.stderr


@pytest.mark.parametrize("links, joints, needles", [
    # l0 -> l1 -> l0 beside a root: each link of the cycle has a parent
    (["base", "l0", "l1"], [("j0", "base", "l0"), ("j1", "l0", "l1"), ("j2", "l1", "l0")],
     ["two joints", "'j0'", "'j2'"]),
    # a pure cycle, no root
    (["l0", "l1"], [("j1", "l0", "l1"), ("j2", "l1", "l0")], ["cycle", "'j1'", "'j2'"]),
    # a joint whose parent is its child
    (["base", "l1"], [("j0", "base", "l1"), ("jself", "l1", "l1")], ["jself", "same link"]),
    # a three-joint cycle hanging off nothing
    (["base", "a", "b", "c"], [("ja", "c", "a"), ("jb", "a", "b"), ("jc", "b", "c")],
     ["cycle", "'ja'", "'jb'", "'jc'"]),
])
def test_urdf_joint_cycles_are_refused_naming_the_joints(links, joints, needles):
    xml = urdf([link(n) for n in links], [joint(*j) for j in joints])
    with pytest.raises(ConfigError) as e:
        mechbal.Mechanism.from_urdf_string(xml)
    msg = str(e.value)
    assert len(msg.splitlines()) == 1
    for n in needles:
        assert n in msg, (n, msg)


@pytest.mark.parametrize("where, value", [
    ("mass", "nan"), ("mass", "inf"), ("mass", "-inf"), ("mass", "abc"), ("mass", "1e999"),
    ("mass", ""), ("izz", "abc"), ("izz", "nan"), ("izz", "0.01x"), ("xyz", "0.2 nan 0"),
    ("xyz", "0.2 0 zero"),
])
def test_urdf_numbers_are_parsed_strictly_naming_the_element(where, value):
    if where == "mass":
        xml = urdf([link("base"), link("arm", m=value)], [joint("j1", "base", "arm")])
        needles = ["link 'arm'", "<mass value="]
    elif where == "izz":
        xml = urdf([link("base"), link("arm", izz=value)], [joint("j1", "base", "arm")])
        needles = ["link 'arm'", "<inertia izz="]
    else:
        xml = urdf([link("base"), link("arm")], [joint("j1", "base", "arm", xyz=value)])
        needles = ["joint 'j1'", "<origin xyz="]
    with pytest.raises(ConfigError) as e:
        mechbal.Mechanism.from_urdf_string(xml)
    msg = str(e.value)
    assert len(msg.splitlines()) == 1
    for n in needles + ["line 1"]:
        assert n in msg, (n, msg)


def test_strict_numbers_still_read_every_valid_spelling():
    xml = urdf([link("base"), link("arm", m="2.5E0", izz="1e-2")], [joint("j1", "base", "arm", xyz="0.2 -0 .0")])
    m = mechbal.Mechanism.from_urdf_string(xml)
    assert m.total_mass == pytest.approx(3.5)
    assert m.model.bodies[1].inertia[2, 2] == pytest.approx(0.01)


def test_urdf_size_limit(tmp_path):
    big = tmp_path / "big.urdf"
    with open(big, "wb") as f:  # sparse: no disk used
        f.truncate(_core.MAX_URDF_BYTES + 1)
    with pytest.raises(ConfigError, match="more than"):
        mechbal.Mechanism.from_urdf(big)
    with pytest.raises(ValueError, match="more than a URDF may be"):
        _core.mechanism_from_urdf(str(big))
    with pytest.raises(ValueError, match="more than a URDF may be"):
        _core.mechanism_from_urdf_string(" " * (_core.MAX_URDF_BYTES + 1))


@pytest.mark.parametrize("reader", ["from_toml", "from_urdf"])
def test_file_readers_accept_regular_files_only_quickly(tmp_path, reader):
    fifo = tmp_path / ("pipe.toml" if reader == "from_toml" else "pipe.urdf")
    os.mkfifo(fifo)
    folder = tmp_path / ("folder.toml" if reader == "from_toml" else "folder.urdf")
    folder.mkdir()
    # in a subprocess with a timeout: a reader that blocks on the FIFO or reads /dev/zero forever
    # fails the test instead of hanging the run
    r = run_python(f"""
        import mechbal
        for p in ("/dev/zero", {str(fifo)!r}, {str(folder)!r}, "/dev/null"):
            try:
                mechbal.Mechanism.{reader}(p)
                print("ACCEPTED", p)
            except mechbal.ConfigError as e:
                print("ERR", e)
        """, timeout=60)
    assert r.returncode == 0, r.stderr[-400:]
    lines = r.stdout.strip().splitlines()
    assert len(lines) == 4 and all(x.startswith("ERR") for x in lines), lines
    assert "not a regular file" in lines[0] and "not a regular file" in lines[1]
    assert "is a folder" in lines[2]
    # the C++ reader refuses them too (it is reachable without Python's checks)
    for p in ("/dev/zero", str(fifo), str(folder)):
        with pytest.raises(ValueError, match="folder|not a regular file"):
            _core.mechanism_from_urdf(p)


def test_toml_size_and_depth_limits(tmp_path):
    from mechbal.config import MAX_CASE_BYTES, MAX_CASE_DEPTH, read_toml

    big = tmp_path / "big.toml"
    with open(big, "wb") as f:
        f.truncate(MAX_CASE_BYTES + 1)
    with pytest.raises(ConfigError, match="more than"):
        read_toml(big)
    deep = tmp_path / "deep.toml"
    deep.write_text("x = " + "[" * 100_000 + "]" * 100_000 + "\n")
    with pytest.raises(ConfigError, match="too deeply"):
        mechbal.Mechanism.from_toml(deep)
    # deep through table headers (no recursion in the TOML reader, but every walk after it)
    headers = tmp_path / "headers.toml"
    headers.write_text("[" + ".".join(f"k{i}" for i in range(MAX_CASE_DEPTH + 5)) + "]\nx = 1\n")
    with pytest.raises(ConfigError, match="too deeply"):
        read_toml(headers)


# ---- cost linear in the mechanism's size --------------------------------------------------------

CHAIN = """
    import json, resource, time
    import numpy as np
    from mechbal import _core
    import mechbal

    def rss():
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # MB

    n = {n}
    joints, bodies = [], []
    T = np.eye(4); T[0, 3] = 0.05
    axes = (np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0]))
    for i in range(n):
        joints.append(_core.Joint(f"j{{i}}", _core.JointType.revolute, "base" if i == 0 else f"j{{i-1}}",
                                  T, axes[i % 2]))
        bodies.append(_core.Body(f"b{{i}}", f"j{{i}}", 0.1, np.array([0.025, 0.0, 0.0]),
                                 np.diag([1e-4, 1e-4, 1e-4])))
    m = mechbal.Mechanism.from_description(joints, bodies, frames=[_core.Frame("tip", f"j{{n-1}}")])
    rng = np.random.default_rng(0)
    q, v, a = (rng.uniform(-0.01, 0.01, n) for _ in range(3))
    before = rss()
    out = {{}}
    t0 = time.process_time()
    for name in {algorithms}:
        fn = getattr(m, name)
        args = {{"center_of_mass": (q,), "gravity_torque": (q,), "static_torque": (q,),
                "spring_torque": (q,), "potential_energy": (q,), "momentum_matrix": (q,),
                "inverse_dynamics": (q, v, a), "bias_torque": (q, v), "momentum": (q, v),
                "shaking_wrench": (q, v, a), "base_reaction": (q, v, a), "body_motion": (q, v, a),
                "momentum_regressor": (q, v), "frame_jacobian": (q, "tip"),
                "frame_placement": (q, "tip"), "mass_matrix": (q,), "torque_regressor": (q, v, a),
                "gravity_regressor": (q,)}}[name]
        r = fn(*args)
        arrays = [np.asarray(x) for x in (r.__dict__.values() if hasattr(r, "__dict__") else [r])
                  if isinstance(x, np.ndarray)]
        out[name] = bool(all(np.all(np.isfinite(x)) for x in arrays))
    out["cpu_seconds"] = time.process_time() - t0
    # invariants: centre of mass = the mass-weighted body centres; at rest, tau = G(q)
    com = m.center_of_mass(q)
    bm = m.body_motion(q)
    out["com_error"] = float(np.abs(com - bm.com.mean(axis=0)).max())
    out["id_error"] = float(np.abs(m.inverse_dynamics(q, 0 * q, 0 * q) - m.gravity_torque(q)).max())
    out["growth_mb"] = rss() - before
    print(json.dumps(out))
"""

LINEAR = ["center_of_mass", "gravity_torque", "static_torque", "spring_torque", "potential_energy",
          "inverse_dynamics", "bias_torque", "momentum", "shaking_wrench", "base_reaction",
          "body_motion", "momentum_matrix", "momentum_regressor", "frame_jacobian", "frame_placement"]


def test_10000_link_chain_every_linear_algorithm_in_bounded_memory():
    """Before: one centre of mass of a 5000-link chain took 5.0 GB (the data held the mass matrix,
    a per-link mass matrix and two dof x 10 bodies regressors). Now the data is O(n): every
    algorithm whose result is O(n) runs on 10,000 links in a bounded peak memory growth."""
    r = run_python(CHAIN.format(n=10_000, algorithms=LINEAR), timeout=600)
    assert r.returncode == 0, r.stderr[-800:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert all(out[name] for name in LINEAR), out
    assert out["com_error"] < 1e-9 and out["id_error"] < 1e-6, out
    # the O(n) buffers of 10,000 links are a few MB; the old quadratic data would be > 16 GB
    assert out["growth_mb"] < 400, out


def test_quadratic_results_cost_their_own_size_only():
    """The mass matrix (dof^2) and the torque / gravity regressors (dof x 10 bodies) are sized by
    their first call, not with the data: 600 links, peak growth within a few result sizes."""
    algorithms = ["mass_matrix", "torque_regressor", "gravity_regressor"]
    r = run_python(CHAIN.format(n=600, algorithms=algorithms), timeout=600)
    assert r.returncode == 0, r.stderr[-800:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert all(out[name] for name in algorithms), out
    regressor_mb = 600 * 6000 * 8 / 2**20  # 27 MB
    assert out["growth_mb"] < 8 * regressor_mb, out


def test_1000_body_tree_invariants():
    """A random 1000-body tree (branching, revolute, prismatic and fixed joints, read from URDF):
    the recursive inverse dynamics equals M(q) a + b(q, v) from the composite-body mass matrix,
    and the centre of mass is the mass-weighted body centres (two algorithms each)."""
    from random_trees import random_tree

    tree = random_tree(np.random.default_rng(24), 1000, types="RRRPF")
    mech = mechbal.Mechanism.from_urdf_string(tree.urdf())
    assert len(mech.body_names) == 1000
    rng = np.random.default_rng(1)
    q, v, a = (rng.uniform(-0.5, 0.5, mech.dof) for _ in range(3))
    tau = mech.inverse_dynamics(q, v, a)
    tau_crba = mech.mass_matrix(q) @ a + mech.bias_torque(q, v)
    assert np.abs(tau - tau_crba).max() <= 1e-9 * max(1.0, np.abs(tau).max())
    masses = np.array([b.mass for b in mech.bodies])
    com = masses @ mech.body_motion(q).com / masses.sum()
    assert np.allclose(mech.center_of_mass(q), com, atol=1e-12 * max(1.0, np.abs(com).max()))


def test_300_body_tree_against_pinocchio():
    """Pinocchio (an independent engine) on a 300-body random tree: inverse dynamics. (Its Data is
    quadratic in the joints: 1000 bodies would need GBs there, not here.)"""
    pin = pytest.importorskip("pinocchio")
    from random_trees import random_tree

    tree = random_tree(np.random.default_rng(25), 300, types="RRRPF")
    mech = mechbal.Mechanism.from_urdf_string(tree.urdf())
    model = pin.buildModelFromXML(tree.urdf())
    data = model.createData()
    rng = np.random.default_rng(1)
    q, v, a = (rng.uniform(-0.5, 0.5, mech.dof) for _ in range(3))
    # mechbal's coordinates by joint name in Pinocchio's q
    idx = [model.joints[model.getJointId(name)].idx_q for name in mech.joint_names]
    qp, vp, ap = (np.zeros(model.nq) for _ in range(3))
    qp[idx], vp[idx], ap[idx] = q, v, a
    tau_pin = pin.rnea(model, data, qp, vp, ap)[idx]
    tau = mech.inverse_dynamics(q, v, a)
    assert np.abs(tau - tau_pin).max() <= 1e-9 * max(1.0, np.abs(tau_pin).max())


# ---- batch results that cannot be mistaken ------------------------------------------------------

@pytest.fixture(scope="module")
def arm():
    xml = urdf([link("base"), link("a"), link("b")], [joint("j1", "base", "a"), joint("j2", "a", "b")])
    return mechbal.Mechanism.from_urdf_string(xml)


BATCH_METHODS = {
    "inverse_dynamics": 3, "mass_matrix": 1, "gravity_torque": 1, "static_torque": 1,
    "spring_torque": 1, "spring_lengths": 1, "bias_torque": 2, "center_of_mass": 1,
    "momentum_matrix": 1, "torque_regressor": 3, "gravity_regressor": 1, "momentum_regressor": 2,
}


@pytest.mark.parametrize("name, nargs", sorted(BATCH_METHODS.items()))
def test_every_batch_method_flags_a_failed_row(arm, name, nargs):
    q = np.array([[np.nan, 0.0], [0.3, -0.2], [0.1, 0.4]])
    args = [q] + [np.full_like(q, 0.5)] * (nargs - 1)
    out = getattr(arm, name)(*args)
    assert isinstance(out, BatchArray)
    assert out.status.shape == (3,)
    assert out.status[0] & int(S.non_finite_input) and list(out.status[1:]) == [0, 0]
    assert list(out.ok) == [False, True, True]
    assert out[0].size == 0 or np.all(np.isnan(out[0]))  # never zeros that pass for a result
    for k in (1, 2):  # the good rows are the single-sample results
        single = getattr(arm, name)(*[x[k] for x in args])
        assert np.array_equal(np.asarray(out[k]), np.asarray(single))


@pytest.mark.parametrize("name, nargs", [("momentum", 2), ("shaking_wrench", 3), ("base_reaction", 3),
                                         ("body_motion", 3), ("spring_energy", 1), ("potential_energy", 1),
                                         ("spring_tension", 1), ("frame_jacobian", 1), ("frame_placement", 1),
                                         ("body_poses", 1)])
def test_every_other_batch_method_flags_a_failed_row(arm, name, nargs):
    """Every public Mechanism method over a batch: the failed instant is flagged and holds no
    finite number that could pass for a result (rotations and placements aside: identity)."""
    q = np.array([[0.3, -0.2], [np.inf, 0.0]])
    args = [q] + [np.full_like(q, 0.5)] * (nargs - 1)
    if name in ("frame_jacobian", "frame_placement"):
        args.append("b")
    out = getattr(arm, name)(*args)
    results = out if isinstance(out, tuple) else (out,)
    for r in results:
        status = r.status
        assert list(np.asarray(status) != 0) == [False, True], (name, status)
        arrays = [r] if isinstance(r, np.ndarray) else [np.asarray(v) for k, v in vars(r).items()
                                                         if k != "status" and isinstance(v, np.ndarray)]
        for a in arrays:
            bad = np.asarray(a)[1]
            if bad.shape[-2:] in ((3, 3), (4, 4)) and not np.isnan(bad).all():
                assert np.array_equal(bad, np.broadcast_to(np.eye(bad.shape[-1]), bad.shape)), name
            else:
                assert np.all(np.isnan(bad)), (name, bad)


def test_pose_batches_expose_the_status(arm):
    q = [[np.nan, 0.0], [0.2, 0.1]]
    T = arm.frame_placement(q, "a")
    assert isinstance(T, BatchArray) and list(T.ok) == [False, True]
    assert np.array_equal(T[0], np.eye(4))
    com, R = arm.body_poses(q)
    assert list(com.ok) == [False, True] and list(R.ok) == [False, True]


def test_gravity_torque_of_the_issue(arm):
    g = arm.gravity_torque([[np.nan, 0], [0, 0]])
    assert np.all(np.isnan(g[0])) and np.all(np.isfinite(g[1]))
    assert list(g.status != 0) == [True, False]


def test_failed_row_of_body_motion_has_identity_rotations(arm):
    m = arm.body_motion([[np.inf, 0], [0.2, 0.1]])
    assert m.status[0] != 0 and m.status[1] == 0
    assert np.array_equal(m.rotation[0], np.broadcast_to(np.eye(3), m.rotation[0].shape))
    assert np.array_equal(m.link_rotation[0], np.broadcast_to(np.eye(3), m.link_rotation[0].shape))
    assert np.array_equal(m.frame_placement[0], np.broadcast_to(np.eye(4), m.frame_placement[0].shape))
    assert np.all(np.isnan(m.com[0])) and np.all(np.isfinite(m.com[1]))
    # an overflowing motion (finite input) is flagged the same way
    w = arm.shaking_wrench([[0, 0], [0, 0]], [[1e300, 1e300], [0, 0]], [[0, 0], [0, 0]])
    assert w.status[0] & int(S.out_of_range) and w.status[1] == 0
    assert np.all(np.isnan(w.shaking_force[0]))


def test_status_of_is_not_promised_any_more():
    assert "status_of" not in (mechbal.Mechanism.inverse_dynamics.__doc__ or "")
    assert not hasattr(mechbal.Mechanism, "status_of")


@pytest.fixture(scope="module")
def four_bar():
    from linkages import four_bar

    lk = four_bar()
    mech = lk.mechanism()
    return mech, lk.q_guess(mech)


def test_closed_motion_rows_are_independent(four_bar):
    mech, g = four_bar
    qa = np.array([[1.0], [1.02], [1.04], [1.06]])
    va = np.full_like(qa, 0.5)
    good = mech.closed_motion(qa, va, np.zeros_like(qa), q_guess=g)
    assert list(good.status) == [0, 0, 0, 0]
    bad_v = va.copy()
    bad_v[1] = 1e300  # the issue's poisoning row
    bad = mech.closed_motion(qa, bad_v, np.zeros_like(qa), q_guess=g)
    assert bad.status[1] & int(S.out_of_range)
    assert list(bad.status[[0, 2, 3]]) == [0, 0, 0]
    assert np.all(np.isnan(bad.v[1]))
    for k in (0, 2, 3):
        assert np.allclose(bad.q[k], good.q[k], atol=1e-12)
        assert np.allclose(bad.v[k], good.v[k], atol=1e-9)
        assert bad.residual[k] < 1e-10
    # a row that cannot be assembled (the crank beyond reach) does not poison the next either
    qa2 = np.array([[1.0], [np.nan], [1.04]])
    m2 = mech.closed_motion(qa2, np.zeros_like(qa2), np.zeros_like(qa2), q_guess=g)
    assert m2.status[1] != 0 and m2.status[2] == 0
    assert np.allclose(m2.q[2], good.q[2], atol=1e-10)
    Mr, G = mech.reduced_mass_matrix(qa2, q_guess=g)
    assert Mr.status[1] != 0 and np.all(np.isnan(Mr[1])) and Mr.status[2] == 0
    F = mech.actuated_forces(qa, bad_v, np.zeros_like(qa), q_guess=g)
    assert F.status[1] != 0 and np.all(np.isnan(F[1])) and np.all(np.isfinite(F[[0, 2, 3]]))


def test_closed_forward_dynamics_overflow_is_not_ok(four_bar):
    mech, g = four_bar
    d = _core.MechanismDynamics(mech.model, g)
    for tau in (1.8e308, 1e308, -1e308, 1.7e308):  # 1.8e308 is inf in Python
        r = _core.mechanism_closed_forward_dynamics(mech.model, [1.0], [0.0], [tau], g)
        assert r["status"] != 0 or np.all(np.isfinite(r["a_actuated"])), (tau, r)
        try:
            assert np.all(np.isfinite(d.forward_dynamics([1.0], [0.0], [tau])))
        except ValueError:
            pass
    r = _core.mechanism_closed_forward_dynamics(mech.model, [1.0], [1e200], [0.0], g)
    assert r["status"] != 0 or np.all(np.isfinite(r["a_actuated"])), r


def test_per_sample_functions_raise_on_non_finite_results(arm):
    d = _core.MechanismDynamics(arm.model)
    with pytest.raises(ValueError, match="overflow|out_of_range"):
        d.coriolis([0.1, 0.2], [1e300, 1e300])
    kdl = _core.KdlChainDynamics(_core.MechanismModel(_core.arm2dof_description(_core.Arm2DofParameters())))
    with pytest.raises(ValueError, match="overflow|out_of_range"):
        kdl.coriolis([0.1, 0.2], [1e300, 1e300])
    pm = _core.PaminsaModel(_core.PaminsaParameters())
    P, s = pm.forward_kinematics(0.1, 2.0, 1.8e308)
    assert s != S.ok
    for bad in (np.nan, np.inf):
        with pytest.raises(ValueError):
            _core.pd_error_analytic(bad, 0.0, 100.0, 20.0, [0.0, 0.1])
        with pytest.raises(ValueError):
            _core.pd_error_analytic(0.1, 0.0, 100.0, 20.0, [0.0, bad])
    from mechbal.trajectory import Sampled, ViaPoints

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no RuntimeWarning: an error
        with pytest.raises(ValueError, match="overflow"):
            ViaPoints([0.0, 1e-300], [[0.0], [1e300]]).evaluate([0.5e-300])
        with pytest.raises(ValueError, match="overflow"):
            ViaPoints([0.0, 1e-300, 1.0], [[0.0], [1e300], [-1e300]]).evaluate([0.5e-300, 0.5])
        with pytest.raises(ValueError, match="overflow"):
            Sampled([0.0, 1e-300, 1.0], [[0.0], [1e300], [0.0]]).evaluate([0.5e-300, 0.5])


BAD_ARRAYS = {
    "complex": np.array([1 + 1j, 0, 0]),
    "string": np.array(["1", "0", "0"]),
    "bool": np.array([True, False, False]),
    "object": np.array([1.0, None, 0.0], dtype=object),
}


@pytest.mark.parametrize("kind", sorted(BAD_ARRAYS))
def test_wrong_array_types_are_type_errors_at_every_binding(kind, four_bar, arm):
    bad3 = BAD_ARRAYS[kind]
    bad4 = np.array([list(bad3) + [0]] * 4, dtype=bad3.dtype)
    mech, g = four_bar
    calls = [
        lambda: _core.Joint("j", _core.JointType.revolute, "base", np.eye(4), bad3),
        lambda: _core.Joint("j", _core.JointType.revolute, "base", bad4, [0, 0, 1]),
        lambda: _core.Body("b", "j", 1.0, bad3),
        lambda: _core.Body("b", "j", 1.0, [0, 0, 0], np.array([bad3] * 3, dtype=bad3.dtype)),
        lambda: _core.Frame("f", "j", bad4),
        lambda: _core.Spring("s", "a", bad3, "b", [0, 0, 0], 1.0),
        lambda: _core.Spring("s", "a", [0, 0, 0], "b", bad3, 1.0),
        lambda: mechbal.Mechanism.from_description([_core.Joint("j")], gravity=bad3),
        lambda: _core.mechanism_closed_forward_dynamics(mech.model, bad3[:1], [0.0], [0.0], g),
        lambda: _core.mechanism_closed_forward_dynamics(mech.model, [1.0], [0.0], [0.0], np.resize(bad3, 3)),
        lambda: _core.MechanismDynamics(mech.model, np.resize(bad3, 3)),
        lambda: mech.closed_motion(bad3[:1], q_guess=g),
        lambda: mech.closed_motion([1.0], bad3[:1], q_guess=g),
        lambda: mech.closed_motion([1.0], q_guess=np.resize(bad3, 3)),
        lambda: mech.actuated_forces(bad3[:1], [0.0], [0.0], q_guess=g),
        lambda: mech.reduced_mass_matrix(bad3[:1], q_guess=g),
        lambda: mechbal.trajectory.quintic(bad3[:2], [0, 0], 1.0),
        lambda: mechbal.trajectory.ViaPoints([0.0, 1.0], np.array([bad3[:2]] * 2, dtype=bad3.dtype)),
        lambda: mechbal.trajectory.quintic([0, 0], [1, 1], 1.0).evaluate(bad3),
    ]
    for name, nargs in BATCH_METHODS.items():
        calls.append(lambda name=name, nargs=nargs: getattr(arm, name)(*([bad3[:2]] * nargs)))
    for extra in ("momentum", "shaking_wrench", "base_reaction", "body_motion", "spring_energy",
                  "potential_energy", "spring_tension"):
        n = {"momentum": 2, "shaking_wrench": 3, "base_reaction": 3}.get(extra, 1)
        calls.append(lambda extra=extra, n=n: getattr(arm, extra)(*([bad3[:2]] * n)))
    calls.append(lambda: arm.frame_jacobian(bad3[:2], "a"))
    calls.append(lambda: arm.frame_placement(bad3[:2], "a"))
    failures = []
    for i, call in enumerate(calls):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a ComplexWarning would be a silent truncation
            try:
                call()
                failures.append((i, "accepted"))
            except TypeError:
                pass
            except Exception as e:  # noqa: BLE001 - report which call gave what
                failures.append((i, f"{type(e).__name__}: {e}"))
    assert not failures, failures


# ---- plausibility ranges ------------------------------------------------------------------------

def test_implausible_values_warn_in_the_api():
    from mechbal.plausibility import MAX_GRAVITY, MAX_MASS

    j = [_core.Joint("j", _core.JointType.revolute, "base")]
    with pytest.warns(PlausibilityWarning, match="gravity"):
        mechbal.Mechanism.from_description(j, [_core.Body("b", "j", 1.0)], gravity=[0, 0, -1.01 * MAX_GRAVITY])
    with pytest.warns(PlausibilityWarning, match="mass"):
        mechbal.Mechanism.from_description(j, [_core.Body("b", "j", 2 * MAX_MASS)])
    with pytest.warns(PlausibilityWarning, match="travel"):
        mechbal.Mechanism.from_description([_core.Joint("j", _core.JointType.revolute, "base", lower=-1e9, upper=1.0)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mechbal.Mechanism.from_description(j, [_core.Body("b", "j", 0.99 * MAX_MASS)],
                                           gravity=[0, 0, -0.99 * MAX_GRAVITY])


CASE = """
[case]
name = "plausible"
kind = "serial_chain"

[mechanism]
gravity = [0.0, 0.0, {g}]

[[mechanism.joints]]
name = "j1"
type = "revolute"
origin = {{ xyz = [0.0, 0.0, 0.0] }}
link = {{ mass = {mass}, com = [0.1, 0.0, 0.0], inertia = [0.01, 0.01, 0.01] }}

[trajectory]
law = "quintic"
start = [0.0]
end = [{end}]
duration = 1.0
samples = 21
"""


@pytest.mark.parametrize("field, values", [
    ("trajectory.end", dict(g=-9.81, mass=1.0, end=1e9)),
    ("gravity", dict(g=-1e12, mass=1.0, end=1.0)),
    ("mass", dict(g=-9.81, mass=1e7, end=1.0)),
])
def test_implausible_values_are_refused_by_the_cli_unless_forced(tmp_path, capsys, field, values):
    from cli_checks import one_line_error
    from mechbal.cli import main

    case = tmp_path / "case.toml"
    case.write_text(CASE.format(**values))
    assert main(["run", str(case), "--out", str(tmp_path / "o"), "-q"]) == 2
    one_line_error(capsys, field, "plausible", "--force")
    assert not (tmp_path / "o").exists()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["run", str(case), "--out", str(tmp_path / "o"), "-q", "--force"]) == 0
    assert (tmp_path / "o" / "summary.json").exists()


@pytest.mark.parametrize("kw, error, needle", [
    (dict(dt=5e-324), ValueError, "steps"),
    (dict(dt=1e-300), ValueError, "steps"),
    (dict(duration=1.8e308), ValueError, "duration must be a finite"),
    (dict(duration=1e300), ValueError, "steps"),
    (dict(dt=None), TypeError, "dt must be a number"),
    (dict(duration="2"), TypeError, "duration must be a number"),
    (dict(dt=float("nan")), ValueError, "dt must be a finite"),
    (dict(dt=-1e-3), ValueError, "dt must be a finite"),
    (dict(dt=0.1, duration=0.01), ValueError, "duration must be >= dt"),
])
def test_closed_loop_timing_is_validated_with_clear_messages(arm, kw, error, needle):
    from mechbal import control, simulate, trajectory

    ctl = control.ComputedTorque(_core.MechanismDynamics(arm.model), [100.0, 100.0], [20.0, 20.0])
    for traj in (trajectory.quintic([0, 0], [0.1, 0.1], 0.5),
                 trajectory.ViaPoints([0.0, 0.5], [[0, 0], [0.1, 0.1]])):
        with pytest.raises(error, match=needle):
            simulate.closed_loop(arm, ctl, traj, **kw)


def test_axis_of_two_values_names_the_size():
    from mechbal.spec import mechanism_spec

    table = {"joints": [{"name": "j", "type": "revolute", "axis": [0.0, 1.0],
                         "origin": {"xyz": [0, 0, 0]}, "link": {"mass": 1.0}}]}
    with pytest.raises(ConfigError) as e:
        mechanism_spec(table)
    assert "None" not in str(e.value) and "axis" in str(e.value)
    with pytest.raises(ValueError, match=r"axis must have shape \(3,\)"):
        _core.Joint("j", _core.JointType.revolute, "base", np.eye(4), [0.0, 1.0])


# ---- output folders -----------------------------------------------------------------------------

def dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_stale_siblings_of_dead_runs_are_removed_and_only_those(tmp_path):
    from mechbal.output import staged_output

    out = tmp_path / "D"
    dead = dead_pid()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        stale = [tmp_path / f".D.partial-{dead}-abc", tmp_path / f".D.old-{dead}-def"]
        kept = [tmp_path / f".D.partial-{live.pid}-ghi", tmp_path / ".D.partial-legacy",
                tmp_path / f".E.partial-{dead}-jkl"]
        for p in stale + kept:
            p.mkdir()
            (p / "summary.json").write_text("{}")
        out.mkdir()
        (out / "summary.json").write_text('{"run": "old"}')
        with staged_output(out) as tmp:
            (tmp / "summary.json").write_text('{"run": "new"}')
        assert json.loads((out / "summary.json").read_text()) == {"run": "new"}
        for p in stale:
            assert not p.exists(), p
        for p in kept:
            assert p.exists(), p
        names = sorted(p.name for p in tmp_path.iterdir())
        assert names == sorted(["D"] + [p.name for p in kept])
    finally:
        live.kill()
        live.wait()


def test_a_kill_between_the_renames_is_recovered(tmp_path):
    """A run killed after moving the old run aside and before moving its own into place leaves
    no D: the next run (even a failing one) puts the old run back first."""
    from mechbal.output import recover_stale, staged_output

    out = tmp_path / "D"
    dead = dead_pid()
    old = tmp_path / f".D.old-{dead}-xyz"
    old.mkdir()
    (old / "summary.json").write_text('{"run": "old"}')
    partial = tmp_path / f".D.partial-{dead}-uvw"
    partial.mkdir()
    with pytest.raises(RuntimeError):
        with staged_output(out):
            raise RuntimeError("the runner fails")
    assert json.loads((out / "summary.json").read_text()) == {"run": "old"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["D"]
    assert recover_stale(out) == []


def test_a_lost_race_has_its_own_exit_code(tmp_path, capsys, monkeypatch):
    from cli_checks import one_line_error
    from mechbal import output
    from mechbal.cli import main

    def lose(tmp, out):
        raise OSError(errno.ENOTEMPTY, "Directory not empty")

    monkeypatch.setattr(output, "_replace", lose)
    assert main(["run", "arm2link", "--out", str(tmp_path / "o"), "-q"]) == 4
    one_line_error(capsys, "another run", "discarded")
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # its own partial folder is gone
