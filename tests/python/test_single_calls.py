"""Single-sample calls of Mechanism and the joint controllers' step() (issue 26): a 1-D float64
array goes straight to the C++ algorithm, anything else takes the general path. The two paths
must give the same results, to the last bit, and the same errors; the fast path must be the one
taken for float64 arrays. (Their cost is measured in bench/bench_python.py, never here.)"""
from __future__ import annotations

import copy

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.control import JointCommand
from mechbal.mechanism import ShakingWrench
from random_trees import random_tree


@pytest.fixture(scope="module")
def mech():
    """A random tree with revolute, prismatic and fixed joints and a gear coupling, read from URDF
    so that every link is a named frame."""
    tree = random_tree(np.random.default_rng(2626), 7, types="RRPRF", mimic=True)
    m = mechbal.Mechanism.from_urdf_string(tree.urdf(), name="tree")
    assert m.dof >= 4 and len(m.frame_names) >= 5
    return m


def _states(mech, count=6, seed=5):
    rng = np.random.default_rng(seed)
    return [tuple(rng.uniform(-2, 2, mech.dof) for _ in range(3)) for _ in range(count)]


def _general(x):
    """The same values in a form the fast path does not take (a list)."""
    return list(x)


def test_single_calls_equal_the_general_path_to_the_last_bit(mech):
    frame = mech.frame_names[-1]
    for q, v, a in _states(mech):
        gq, gv, ga = _general(q), _general(v), _general(a)
        pairs = {
            "inverse_dynamics": (mech.inverse_dynamics(q, v, a), mech.inverse_dynamics(gq, gv, ga)),
            "mass_matrix": (mech.mass_matrix(q), mech.mass_matrix(gq)),
            "gravity_torque": (mech.gravity_torque(q), mech.gravity_torque(gq)),
            "center_of_mass": (mech.center_of_mass(q), mech.center_of_mass(gq)),
            "frame_placement": (mech.frame_placement(q, frame), mech.frame_placement(gq, frame)),
            "frame_jacobian": (mech.frame_jacobian(q, frame), mech.frame_jacobian(gq, frame)),
        }
        for name, (fast, general) in pairs.items():
            assert type(fast) is np.ndarray and fast.dtype == np.float64, name
            assert fast.shape == general.shape and np.array_equal(fast, general), name
            # and the row of a batch of one
        assert np.array_equal(pairs["inverse_dynamics"][0], mech.inverse_dynamics(q[None], v[None], a[None])[0])
        fast, general = mech.shaking_wrench(q, v, a), mech.shaking_wrench(gq, gv, ga)
        assert isinstance(fast, ShakingWrench)
        for field in ("shaking_force", "shaking_moment", "linear_momentum", "angular_momentum"):
            assert np.array_equal(getattr(fast, field), getattr(general, field)), field
        assert fast.status == general.status == 0 and type(fast.status) is type(general.status)
        assert fast == ShakingWrench(**vars(fast)) and repr(fast) == repr(ShakingWrench(**vars(fast)))
        with pytest.raises(AttributeError):  # still frozen
            fast.status = 1


def test_the_fast_path_is_taken_for_float64_arrays_only(mech):
    """The binding's contract: a result for 1-D C-contiguous float64 numpy arrays of dof values,
    None (the general path) for anything else and for a rejected instant."""
    single = mech._single
    q = np.linspace(-1, 1, mech.dof)
    frame = mech.frame_names[0]
    assert single.inverse_dynamics(q, q, q) is not None
    assert single.shaking_wrench(q, q, q) is not None
    assert single.frame_placement(q, frame) is not None and single.frame_jacobian(q, frame) is not None
    nan = q.copy()
    nan[0] = np.nan
    others = [list(q), q.astype(np.float32), q.astype(int), np.zeros(mech.dof + 1), q[None],
              np.repeat(q, 2)[::2], q.astype(">f8"), q.astype(complex), nan, q.view(mechbal.BatchArray)]
    for x in others:
        assert single.inverse_dynamics(x, q, q) is None
        assert single.inverse_dynamics(q, q, x) is None
        assert single.mass_matrix(x) is None and single.gravity_torque(x) is None
        assert single.center_of_mass(x) is None and single.shaking_wrench(q, x, q) is None
        assert single.frame_placement(x, frame) is None and single.frame_jacobian(x, frame) is None
    assert single.frame_placement(q, "no such frame") is None and single.frame_jacobian(q, 3) is None
    # an overflowing instant is refused by the fast path and reported by the general one
    assert single.inverse_dynamics(q, np.full(mech.dof, 1e300), q) is None
    with pytest.raises(ValueError, match="out_of_range"):
        mech.inverse_dynamics(q, np.full(mech.dof, 1e300), q)


def test_inputs_the_fast_path_leaves_give_the_same_results_and_errors(mech):
    n = mech.dof
    q = np.linspace(-1, 1, n)
    expected = mech.gravity_torque(q)
    for x in (list(q), tuple(q), np.asfortranarray(q), np.repeat(q, 2)[::2], q.astype(">f8"),
              q.view(mechbal.BatchArray)):
        assert np.array_equal(mech.gravity_torque(x), expected)
    assert np.array_equal(mech.gravity_torque(np.arange(n)), mech.gravity_torque(np.arange(n, dtype=float)))
    nan = q.copy()
    nan[1] = np.nan
    with pytest.raises(ValueError, match="tree: input rejected \\(non_finite_input\\)"):
        mech.inverse_dynamics(nan, q, q)
    with pytest.raises(ValueError, match="non_finite_input"):
        mech.frame_placement(nan, mech.frame_names[0])
    with pytest.raises(ValueError, match=rf"q must have shape \({n},\) or \(N, {n}\), got \({n + 1},\)"):
        mech.mass_matrix(np.zeros(n + 1))
    with pytest.raises(TypeError, match="real numeric"):
        mech.center_of_mass(q.astype(complex))
    with pytest.raises(TypeError, match="real numeric"):
        mech.shaking_wrench(q, q, np.array(["1"] * n))
    with pytest.raises(ValueError, match="which does not match"):
        mech.inverse_dynamics(q, q[None], q)
    with pytest.raises(ValueError, match="did you mean"):
        mech.frame_jacobian(q, mech.frame_names[0] + "x")
    # a batch still gives a BatchArray
    assert isinstance(mech.inverse_dynamics(q[None], q[None], q[None]), mechbal.BatchArray)


def test_a_mechanism_keeps_its_fast_path_through_copies_and_a_new_model(mech):
    q = np.linspace(-0.5, 0.5, mech.dof)
    other = copy.copy(mech)  # (a Mechanism does not pickle: its model's description does not)
    assert other._single is not mech._single
    assert np.array_equal(other.mass_matrix(q), mech.mass_matrix(q))
    assert other.name == mech.name and other.model is mech.model
    heavier = mech.with_bodies([_core.Body("extra", mech.link_names[-1], 2.0)])
    swapped = copy.copy(mech)
    swapped.model = heavier.model  # the per-sample data follows the model
    assert np.array_equal(swapped.gravity_torque(q), heavier.gravity_torque(q))
    assert not np.array_equal(swapped.gravity_torque(q), mech.gravity_torque(q))


def _controllers():
    rng = np.random.default_rng(26)
    tree = random_tree(rng, 5, types="RRP")
    m = tree.mechanism()
    n = m.dof
    yield mechbal.ComputedTorque(m, np.full(n, 100.0), np.full(n, 20.0)), n
    yield mechbal.DecoupledJointController(rng.uniform(0.1, 1.0, 3), np.full(3, 100.0), np.full(3, 20.0)), 3
    yield mechbal.ComputedTorque(_core.Arm2DofDynamics(_core.Arm2DofParameters()), [100, 100], [20, 20]), 2


@pytest.mark.parametrize("index", range(3))
def test_controller_step_fast_and_general_inputs_agree(index):
    ctrl, n = list(_controllers())[index]
    twin, _ = list(_controllers())[index]
    rng = np.random.default_rng(index)
    for k in range(5):
        x = [rng.uniform(-1, 1, n) for _ in range(5)]
        if k == 3:
            x[0][0] = np.nan  # held command, non-ok status, on both
        fast = ctrl.step(*x)
        general = twin.step(*[list(a) for a in x])
        assert isinstance(fast, JointCommand) and type(fast.status) is int
        assert type(fast.joint_torque) is np.ndarray and fast.joint_torque.shape == (n,)
        assert np.array_equal(fast.joint_torque, general.joint_torque) and fast.status == general.status
        assert (fast.status == 0) == (k != 3)
        tau, status = fast  # still a tuple
        # the C++ class's step: the same numbers, the status as a Status
        raw_tau, raw_status = _core.ComputedTorque.step(ctrl, *x) if isinstance(ctrl, _core.ComputedTorque) \
            else _core.DecoupledJointController.step(ctrl, *x)
        assert isinstance(raw_status, _core.Status) and raw_status == status
    with pytest.raises(ValueError, match=rf"v must have shape \({n},\) \(the controller has {n} joints\)"):
        ctrl.step(np.zeros(n), np.zeros(n + 1), np.zeros(n), np.zeros(n), np.zeros(n))
    with pytest.raises(TypeError, match="q_des must be an array of real numbers"):
        ctrl.step(np.zeros(n), np.zeros(n), np.zeros(n, complex), np.zeros(n), np.zeros(n))


def _outcome(fn, *args):
    try:
        r = fn(*args)
    except ValueError as exc:
        return ("raised", str(exc))
    if isinstance(r, ShakingWrench):
        r = np.concatenate([r.shaking_force, r.shaking_moment, r.linear_momentum, r.angular_momentum])
    return ("value", np.asarray(r).tobytes())


def test_huge_inputs_get_the_same_verdict_on_both_paths(mech):
    """Coordinates and rates near overflow (prismatic joints far out): the fast path accepts
    exactly the instants the general path accepts, and gives the same values."""
    frame = mech.frame_names[-1]
    n = mech.dof
    verdicts = set()
    for i in range(n):
        for x in (1e307, -1e307, 1e300, 1e200, np.finfo(float).max):
            q = np.full(n, 0.3)
            q[i] = x
            v = np.zeros(n)
            for v_scale in (0.0, 1e150):
                v[:] = v_scale
                for name, args in (("shaking_wrench", (q, v, v)), ("inverse_dynamics", (q, v, v)),
                                   ("center_of_mass", (q,)), ("gravity_torque", (q,)),
                                   ("mass_matrix", (q,)), ("frame_placement", (q, frame)),
                                   ("frame_jacobian", (q, frame))):
                    fn = getattr(mech, name)
                    general = tuple(list(a) if isinstance(a, np.ndarray) else a for a in args)
                    fast, slow = _outcome(fn, *args), _outcome(fn, *general)
                    assert fast == slow, (name, i, x, v_scale)
                    verdicts.add(fast[0])
    assert verdicts == {"raised", "value"}


def test_batch_shaking_wrench_without_reactions_keeps_the_verdicts(mech):
    """The batch shaking wrench not asked for the reactions computes them only when their bounds
    cannot tell they are finite (reaction_bounds.hpp): instant by instant it gives the statuses
    and values of the path that computes them, huge inputs included, and no reaction arrays."""
    n = mech.dof
    Q, V = [], []
    for i in range(n):
        for x in (0.3, 1e307, -1e307, 1e300, 1e200, np.finfo(float).max):
            for v_scale in (0.0, 1e150):
                q = np.full(n, 0.3)
                q[i] = x
                Q.append(q)
                V.append(np.full(n, v_scale))
    Q, V = np.array(Q), np.array(V)
    lazy = _core.mechanism_shaking_wrench(mech.model, Q, V, V, False)
    full = _core.mechanism_shaking_wrench(mech.model, Q, V, V, True)
    np.testing.assert_array_equal(lazy["status"], full["status"])
    assert (lazy["status"] == 0).any() and (lazy["status"] != 0).any()
    for key in ("shaking_force", "shaking_moment", "linear_momentum", "angular_momentum"):
        np.testing.assert_array_equal(lazy[key], full[key])
    assert "base_reaction_force" not in lazy and "support_reaction_moment" not in lazy
