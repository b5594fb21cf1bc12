"""The general reactionless controller (mechbal.control.ReactionlessController, C++
control/reactionless.hpp) from Python: the ``[control]`` table and ``mechbal run`` on the
reaction-wheel arm and on PAMINSA, the momentum conserved in the *exported poses* (finite
differences of bodies_controlled.npz), the wheel arm against an independent sympy Lagrangian, a
random spatial tree with three balancing joints, bad input, and the computed-torque stage in
mechbal.simulate.closed_loop."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import control, simulate
from mechbal.cases import run_case
from mechbal.config import CASES_DIR, ConfigError, case_path
from mechbal.export import read_bodies, shaking_wrench_by_finite_differences
from mechbal.trajectory import RestToRest

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

sys.path.insert(0, str(Path(__file__).parent))
from random_trees import random_tree  # noqa: E402

WHEEL_CASE = CASES_DIR / "reaction-wheel-arm.toml"
S = control.Status
_HARD = int(S.non_finite_input) | int(S.out_of_range) | int(S.solver_error)


def _fd_moment(path: Path) -> tuple[np.ndarray, dict]:
    data = read_bodies(path)
    _, M = shaking_wrench_by_finite_differences(data)
    return M, data


@pytest.fixture(scope="module")
def wheel_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("wheel") / "out"
    summary = run_case("reaction-wheel-arm", out)
    return out, summary


# ---- the wheel arm through mechbal run ------------------------------------------------------------

def test_wheel_arm_run_writes_both_variants(wheel_run):
    out, summary = wheel_run
    for name in ("bodies_uncontrolled.npz", "bodies_controlled.npz", "shaking_wrench.png",
                 "balancing_joints.png", "summary.json"):
        assert (out / name).is_file(), name
    s = json.loads((out / "summary.json").read_text())
    assert s["variants"] == ["uncontrolled", "controlled"]
    un, co = s["peak_shaking_moment"]["uncontrolled"], s["peak_shaking_moment"]["controlled"]
    assert un[2] > 0.1  # the arm's motion shakes its base about z ...
    assert co[2] < 1e-6 * un[2]  # ... and the wheel cancels it
    assert s["control"]["singular_ticks"] == 0 and s["control"]["saturated_ticks"] == 0
    assert s["control"]["peak_balancing_rate"][0] > 1.0  # the wheel really spins


def test_wheel_arm_exported_poses_conserve_angular_momentum(wheel_run):
    """The shaking moment recomputed by finite differences from the exported poses alone (RK4 at
    1 kHz) is at most 1e-4 of the uncontrolled peak; the stored wrench is that of the poses."""
    out, _ = wheel_run
    Mu, du = _fd_moment(out / "bodies_uncontrolled.npz")
    Mc, dc = _fd_moment(out / "bodies_controlled.npz")
    peak = np.max(np.abs(du["shaking_moment"][:, 2]))
    assert np.max(np.abs(Mu[:, 2])) == pytest.approx(peak, rel=1e-3)  # FD sees the shaking
    assert np.max(np.abs(Mc[:, 2])) <= 1e-4 * peak
    # the stored (analytic) wrench of the controlled poses: zero about z to rounding
    assert np.max(np.abs(dc["shaking_moment"][:, 2])) <= 1e-9 * peak
    # and it is the FD wrench of the stored poses where the arm moves (x, y: not cancelled)
    assert np.max(np.abs(Mc[:, :2] - dc["shaking_moment"][:, :2])) <= 1e-3 * np.max(np.abs(dc["shaking_moment"]))


def test_wheel_arm_against_sympy_lagrangian(wheel_run):
    """An independent model of the same arm: the kinetic energy written with sympy from the case
    file's numbers; the angular momentum about the vertical is the momentum conjugate to the
    shoulder angle (a rigid rotation of the whole arm), H_z = dT/dq1'. Reactionless: H_z = 0
    gives the wheel rate in closed form; uncontrolled: dH_z/dt is the shaking moment."""
    sp = pytest.importorskip("sympy")
    out, _ = wheel_run
    case = tomllib.loads(WHEEL_CASE.read_text())
    j = {jt["name"]: jt for jt in case["mechanism"]["joints"]}
    m1, m2, m3 = (j[n]["link"]["mass"] for n in ("shoulder", "elbow", "wheel"))
    c1, c2 = j["shoulder"]["link"]["com"][0], j["elbow"]["link"]["com"][0]
    I1, I2, I3 = (j[n]["link"]["inertia"][2] for n in ("shoulder", "elbow", "wheel"))
    L1, L2 = j["elbow"]["origin"]["xyz"][0], j["wheel"]["origin"]["xyz"][0]
    # exact rationals: the shoulder angle then cancels symbolically (rotational invariance)
    m1, m2, m3, c1, c2, I1, I2, I3, L1, L2 = (sp.Rational(str(x)) for x in
                                              (m1, m2, m3, c1, c2, I1, I2, I3, L1, L2))

    t = sp.symbols("t")
    q1, q2, q3 = (sp.Function(f"q{i}")(t) for i in (1, 2, 3))
    e1 = sp.Matrix([sp.cos(q1), sp.sin(q1)])
    e12 = sp.Matrix([sp.cos(q1 + q2), sp.sin(q1 + q2)])
    p1, p2, p3 = c1 * e1, L1 * e1 + c2 * e12, L1 * e1 + L2 * e12
    w1, w2, w3 = q1.diff(t), (q1 + q2).diff(t), (q1 + q2 + q3).diff(t)
    T = sum(m * p.diff(t).dot(p.diff(t)) / 2 for m, p in ((m1, p1), (m2, p2), (m3, p3))) \
        + (I1 * w1 ** 2 + I2 * w2 ** 2 + I3 * w3 ** 2) / 2
    d1, d2, d3 = sp.symbols("d1 d2 d3")
    a1, a2 = sp.symbols("a1 a2")
    x1, x2 = sp.symbols("x1 x2")
    sub = {q1.diff(t): d1, q2.diff(t): d2, q3.diff(t): d3}
    Hz = sp.simplify(T.diff(q1.diff(t)).subs(sub).subs({q1: x1, q2: x2}))
    assert not Hz.has(x1)  # H_z does not depend on where the arm points
    wheel_rate = sp.solve(sp.Eq(Hz, 0), d3)[0]  # reactionless from rest: H_z = 0
    rate_fn = sp.lambdify((x2, d1, d2), wheel_rate, "numpy")
    # shaking moment with the wheel held: d/dt H_z along (q1, q2), q3' = q3'' = 0
    Hz_t = T.diff(q1.diff(t)).subs({q3.diff(t): 0})
    Mz = Hz_t.diff(t).subs({q1.diff(t, 2): a1, q2.diff(t, 2): a2}).subs(
        {q1.diff(t): d1, q2.diff(t): d2, q3.diff(t): 0}).subs({q1: x1, q2: x2})
    Mz = sp.simplify(Mz)
    assert not Mz.has(x1)
    moment_fn = sp.lambdify((x2, d1, d2, a1, a2), Mz, "numpy")

    du = read_bodies(out / "bodies_uncontrolled.npz")
    Mz_sym = moment_fn(du["q"][:, 1], du["qd"][:, 0], du["qd"][:, 1], du["qdd"][:, 0], du["qdd"][:, 1])
    peak = np.max(np.abs(Mz_sym))
    assert peak > 0.1
    assert np.max(np.abs(du["shaking_moment"][:, 2] - Mz_sym)) <= 1e-10 * peak

    dc = read_bodies(out / "bodies_controlled.npz")
    rate_sym = rate_fn(dc["q"][:, 1], dc["qd"][:, 0], dc["qd"][:, 1])
    assert np.max(np.abs(rate_sym)) > 1.0
    assert np.max(np.abs(dc["qd"][:, 2] - rate_sym)) <= 1e-10 * np.max(np.abs(rate_sym))
    # the wheel angle: the sympy rate integrated independently (trapezoid on the ticks, O(dt^2))
    tt = dc["t"]
    angle = np.concatenate([[0.0], np.cumsum(np.diff(tt) * (rate_sym[1:] + rate_sym[:-1]) / 2)])
    assert np.max(np.abs(dc["q"][:, 2] - angle)) <= 1e-5 * np.max(np.abs(angle))


# ---- PAMINSA through the general controller ------------------------------------------------------

def _with_control(src: Path, dst: Path, control_table: str) -> Path:
    dst.write_text(src.read_text() + "\n" + control_table)
    return dst


def test_paminsa_exported_poses_conserve_angular_momentum(tmp_path):
    """PAMINSA as data (38 bodies, 9 loops) with its wrist balancing the moment: the shaking
    moment recomputed by finite differences from bodies_controlled.npz (RK4, 1 kHz) is at most
    1e-4 of the uncontrolled peak."""
    case = _with_control(case_path("paminsa-linkage"), tmp_path / "paminsa-rl.toml",
                         '[control]\nkind = "reactionless"\nbalancing_joints = ["wrist_phi", '
                         '"wrist_theta", "wrist_psi"]\ncancel = ["moment"]\nintegrator = "rk4"\n'
                         'rate_hz = 1000.0\n')
    out = tmp_path / "out"
    summary = run_case(case, out)
    Mu, du = _fd_moment(out / "bodies_uncontrolled.npz")
    Mc, dc = _fd_moment(out / "bodies_controlled.npz")
    peak = np.max(np.abs(du["shaking_moment"]))
    assert peak > 1e-2
    assert np.max(np.abs(Mc)) <= 1e-4 * peak
    assert np.max(np.abs(dc["shaking_moment"])) <= 1e-8 * peak
    assert summary["closed"] is True


# ---- a random spatial tree with three balancing joints -------------------------------------------

def test_random_tree_three_balancing_joints_conserve_momentum():
    rng = np.random.default_rng(4)
    tree = random_tree(rng, 7, types="RRR", branching=True)
    # the three last links balance: heavier inertias (reaction-wheel like) so that they can
    # cancel the moment within their rate limit (cond of the balancing block below 10 here)
    for link in tree.links[-3:]:
        link.principal = link.principal * 30.0
    mech = tree.mechanism()
    names = mech.actuated_names
    balancing = [link.name + "_joint" for link in tree.links[-3:]]
    n = len(names)
    q0 = rng.uniform(-0.5, 0.5, n)
    ctrl = control.ReactionlessController(mech, balancing, "moment", "rk4", 1000.0, q0=q0)
    task = list(ctrl.task_indices)
    end = q0.copy()
    end[task] += rng.uniform(-0.6, 0.6, len(task))
    traj = RestToRest(q0, end, 1.0)
    r = ctrl.follow(traj, duration=1.2)
    assert np.all(r.status == 0)
    assert np.max(r.condition) < 10.0
    motion = mech.body_motion(r.q_full, r.v_full, r.a_full)
    bodies = mech.bodies
    data = dict(t=r.t, mass=np.array([b.mass for b in bodies]),
                inertia_body=np.array([b.inertia for b in bodies]).reshape(-1, 3, 3),
                com=motion.com, rotation=motion.rotation)
    _, Mc = shaking_wrench_by_finite_differences(data)
    # uncontrolled: the balancing joints held at their start
    qa = np.array([traj.evaluate(t)[0] for t in r.t])
    qa[:, [names.index(b) for b in balancing]] = q0[[names.index(b) for b in balancing]]
    va = np.array([traj.evaluate(t)[1] for t in r.t])
    va[:, [names.index(b) for b in balancing]] = 0.0
    aa = np.array([traj.evaluate(t)[2] for t in r.t])
    aa[:, [names.index(b) for b in balancing]] = 0.0
    Mu = mech.shaking_wrench(qa, va, aa).shaking_moment
    peak = np.max(np.abs(Mu))
    assert peak > 1e-2
    assert np.max(np.abs(Mc)) <= 1e-4 * peak
    # the commanded momentum stays on target
    assert np.max(np.abs(r.momentum[:, 3:] - r.momentum[0, 3:])) <= 1e-10 * (1 + np.max(np.abs(r.momentum)))


# ---- ticks: bad input, singular, fast tick ---------------------------------------------------------

def _wheel_mech():
    return mechbal.Mechanism.from_toml(WHEEL_CASE)


def test_bad_input_holds_and_recovers():
    ctrl = control.ReactionlessController(_wheel_mech(), ["wheel"], "moment_z", rate_hz=1000.0)
    q, v, a = np.array([0.1, 0.2]), np.array([0.5, -0.3]), np.zeros(2)
    c = ctrl.step(q, v, a)
    assert c.status == 0 and abs(c.v[2]) > 0
    held = ctrl.step([np.nan, 0.0], v, a)
    assert held.status == int(S.non_finite_input)
    assert np.all(np.isfinite(held.q)) and np.all(held.v == 0) and np.all(held.a == 0)
    assert ctrl.step(q, [1e300, 0.0], a).status == int(S.out_of_range)
    assert ctrl.step(q, v, a).status == 0
    with pytest.raises(ValueError, match="q_task"):
        ctrl.step(np.zeros(3), v, a)


def test_singular_and_fast_tick():
    ctrl = control.ReactionlessController(_wheel_mech(), ["wheel"], "moment_x", rate_hz=1000.0)
    c = ctrl.step([0.1, 0.2], [0.5, -0.3], [0.0, 0.0])
    assert c.status & int(S.singular) and np.all(np.isfinite(c.v))
    fast = control.ReactionlessController(_wheel_mech(), ["wheel"], ["moment_z"], "rk4", 1000.0)
    slow = control.ReactionlessController(_wheel_mech(), ["wheel"], ["moment_z"], "rk4", 1000.0)
    now = np.array([[0.1, 0.2], [0.5, -0.3], [0.0, 0.1]])
    half = np.array([[0.1005, 0.1999], [0.5, -0.3]])
    nxt = np.array([[0.101, 0.1997], [0.5, -0.3]])
    out = np.zeros((3, 3))
    assert fast.step_into(now, half, nxt, out) == 0
    ref = slow.step(now[0], now[1], now[2], half[0], half[1], nxt[0], nxt[1])
    np.testing.assert_array_equal(out[0], ref.q)
    np.testing.assert_array_equal(out[1], ref.v)


def test_constructor_errors_name_the_field():
    with pytest.raises(ValueError, match=r"balancing_joints\[0\]: 'whel'"):
        control.ReactionlessController(_wheel_mech(), ["whel"], "moment_z")
    with pytest.raises(ValueError, match="cancel"):
        control.ReactionlessController(_wheel_mech(), ["wheel"], "torque_z")
    with pytest.raises(ValueError, match="integrator"):
        control.ReactionlessController(_wheel_mech(), ["wheel"], "moment_z", "rk45")


# ---- the [control] table ------------------------------------------------------------------------

def test_control_table_is_strict(tmp_path):
    text = WHEEL_CASE.read_text().replace("balancing_joints =", "balancing_joint =")
    (tmp_path / "bad.toml").write_text(text)
    with pytest.raises(ConfigError, match="balancing_joints"):
        run_case(tmp_path / "bad.toml", tmp_path / "out")
    text = WHEEL_CASE.read_text().replace('cancel = ["moment_z"]', 'cancel = ["moment_w"]')
    (tmp_path / "bad2.toml").write_text(text)
    with pytest.raises(ConfigError, match="cancel"):
        run_case(tmp_path / "bad2.toml", tmp_path / "out")
    text = WHEEL_CASE.read_text().replace('balancing_joints = ["wheel"]', 'balancing_joints = ["wheal"]')
    (tmp_path / "bad3.toml").write_text(text)
    with pytest.raises(ConfigError, match="wheel"):
        run_case(tmp_path / "bad3.toml", tmp_path / "out")


def test_init_reactionless_template_runs(tmp_path, capsys):
    from mechbal.cli import main

    assert main(["init", "reactionless"]) == 0
    path = tmp_path / "rl.toml"
    path.write_text(capsys.readouterr().out)
    summary = run_case(path, tmp_path / "out")
    assert summary["variants"] == ["uncontrolled", "controlled"]


# ---- the computed-torque stage in the closed-loop simulator ----------------------------------------

def test_closed_loop_with_reactionless_computed_torque():
    mech = _wheel_mech()
    ctrl = control.ReactionlessController(mech, ["wheel"], "moment_z", "rk4", 1000.0,
                                          kp=[400.0] * 3, kd=[40.0] * 3)
    traj = RestToRest(np.zeros(3), np.array([1.0, -1.2, 0.0]), 1.0)
    res = simulate.closed_loop(mech, ctrl, traj, dt=1e-3, duration=1.2)
    assert res.steps_completed == 1200
    assert np.all((res.status & _HARD) == 0)
    # the plant's wheel follows the reactionless command: the angular momentum about z of the
    # simulated motion stays small against that of the arm alone
    H = mech.momentum(res.q, res.v).angular_momentum[:, 2]
    arm = res.v.copy()
    arm[:, 2] = 0.0
    H_arm = mech.momentum(res.q, arm).angular_momentum[:, 2]
    assert np.max(np.abs(H_arm)) > 0.1
    assert np.max(np.abs(H)) <= 1e-2 * np.max(np.abs(H_arm))
    with pytest.raises(TypeError, match="kp and kd"):
        simulate.closed_loop(mech, control.ReactionlessController(mech, ["wheel"], "moment_z"), traj)


def test_reactionless_joint_controller_ticks_are_typed_and_keep_the_dict_keys():
    """The computed-torque stage answers as every joint controller: step -> JointCommand, run ->
    ControlRun (the dict keys of earlier releases warn), the same torques both ways."""
    mech = _wheel_mech()
    jc = control.ReactionlessController(mech, ["wheel"], "moment_z", kp=[400.0] * 3,
                                        kd=[40.0] * 3).joint_controller
    assert isinstance(jc, control.ReactionlessJointController)
    twin = control.ReactionlessJointController(mech.model, ["wheel"], np.zeros(3), [400.0] * 3, [40.0] * 3,
                                               cancel=["moment_z"])
    q, v = np.array([0.1, 0.2, 0.0]), np.array([0.5, -0.3, 0.0])
    cmd = jc.step(q, v, q + 0.01, v, np.zeros(3))
    assert isinstance(cmd, control.JointCommand) and cmd.status == 0 and cmd.joint_torque.shape == (3,)
    N = 4
    run = twin.run(np.tile(q, (N, 1)), np.tile(v, (N, 1)), np.tile(q + 0.01, (N, 1)), np.tile(v, (N, 1)),
                   np.zeros((N, 3)))
    assert isinstance(run, control.ControlRun) and run.joint_torque.shape == (N, 3) and np.all(run.status == 0)
    np.testing.assert_array_equal(run.joint_torque[0], cmd.joint_torque)
    for key in ("joint_torque", "status"):
        with pytest.warns(DeprecationWarning, match=rf"result\['{key}'\] is deprecated"):
            np.testing.assert_array_equal(run[key], getattr(run, key))
    with pytest.warns(DeprecationWarning, match="ReactionlessJointController.step: 'qd' is deprecated"):
        jc.step(q, qd=v, q_des=q, v_des=v, a_des=np.zeros(3))


# ---- operational-space mode (the reaction null space) ----------------------------------------------

ARM4 = """
[case]
name = "arm4"
kind = "mechanism"
[mechanism]
[[mechanism.joints]]
name = "j1"
axis = [0.0, 0.0, 1.0]
link = { mass = 1.0, com = [0.2, 0.0, 0.0], inertia = [0.001, 0.015, 0.015] }
[[mechanism.joints]]
name = "j2"
origin = { xyz = [0.4, 0.0, 0.0] }
axis = [0.0, 0.0, 1.0]
link = { mass = 1.2, com = [0.2, 0.0, 0.0], inertia = [0.011, 0.015, 0.025] }
[[mechanism.joints]]
name = "j3"
origin = { xyz = [0.4, 0.0, 0.0] }
axis = [0.0, 0.0, 1.0]
link = { mass = 1.4, com = [0.2, 0.0, 0.0], inertia = [0.021, 0.015, 0.035] }
[[mechanism.joints]]
name = "j4"
origin = { xyz = [0.4, 0.0, 0.0] }
axis = [0.0, 0.0, 1.0]
link = { mass = 1.5, com = [0.0, 0.0, 0.0], inertia = [0.1, 0.1, 0.2] }
[[mechanism.frames]]
name = "tool"
link = "j3"
origin = { xyz = [0.4, 0.0, 0.0] }
[trajectory]
start = [0.3, 0.8, 0.6, 0.4]
end = [0.3, 0.8, 0.6, 0.4]
duration = 1.0
"""


def test_operational_space_task_rows_errors_are_the_factory_messages(tmp_path):
    """The Python ReactionlessTaskController reads task_rows through the C++ factory's table
    (mechbal::task_rows_mask): the factory's message, with the argument's name."""
    (tmp_path / "arm4.toml").write_text(ARM4)
    mech = mechbal.Mechanism.from_toml(tmp_path / "arm4.toml")
    with pytest.raises(ValueError) as e:
        control.ReactionlessTaskController(mech, "tool", ["v_x", "lineal"], "moment_z")
    assert str(e.value) == ("task_rows[1]: 'lineal' is not a twist component (all, linear, angular, v_x, "
                            "v_y, v_z, w_x, w_y, w_z)")
    with pytest.raises(ValueError, match=r"^task_rows: must name at least one twist component$"):
        control.ReactionlessTaskController(mech, "tool", [], "moment_z")


def test_operational_space_uses_redundancy_to_cancel_the_moment(tmp_path):
    """A planar 3R arm with a disc joint (4 joints; the tool on the third link) follows a circle:
    with v = J^+ x' alone the arm shakes its base about z; in the reaction null space
    (v = J^+ x' + N z) the tool path is the same and H_z stays zero.
    Tool positions and the shaking moment are recomputed from the commanded poses."""
    (tmp_path / "arm4.toml").write_text(ARM4)
    mech = mechbal.Mechanism.from_toml(tmp_path / "arm4.toml")
    q0 = np.array([0.3, 0.8, 0.6, 0.4])
    ctrl = control.ReactionlessTaskController(mech, "tool", ["v_x", "v_y"], "moment_z", "rk4", 1000.0,
                                              q0=q0)
    dt, steps = ctrl.dt, 1500
    th = np.arange(2 * steps + 1) * dt / 2
    twist = np.zeros((len(th), 6))
    twist[:, 0], twist[:, 1] = -0.2 * np.sin(2 * th), 0.2 * np.cos(2 * th)
    r = ctrl.run(twist)
    assert np.all(r.status == 0)
    # the tool follows the circle: positions of the commanded poses against the integrated path
    p = mech.frame_placement(r.q, "tool")[:, :3, 3]
    circle = p[0, :2] + np.stack([0.1 * (np.cos(2 * r.t) - 1), 0.1 * np.sin(2 * r.t)], axis=1)
    assert np.max(np.abs(p[:, :2] - circle)) < 1e-9
    # H_z of the commanded motion (recomputed by mechbal.Mechanism) stays at the start's (zero)
    H = mech.momentum(r.q, r.v).angular_momentum[:, 2]
    assert np.max(np.abs(H)) < 1e-10
    # the same path by the pseudo-inverse alone (RK4 in numpy): it shakes the base about z
    q = q0.copy()
    Hpinv = []
    for n in range(steps + 1):
        def rate(qq, k):
            J = mech.frame_jacobian(qq, "tool")[:2]
            return np.linalg.pinv(J) @ twist[k, :2]
        k1 = rate(q, 2 * n)
        Hpinv.append(mech.momentum(q, k1).angular_momentum[2])
        if n == steps:
            break
        k2 = rate(q + dt / 2 * k1, 2 * n + 1)
        k3 = rate(q + dt / 2 * k2, 2 * n + 1)
        k4 = rate(q + dt * k3, 2 * n + 2)
        q = q + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    Mz_pinv = np.gradient(np.array(Hpinv), r.t)
    Mz_rl = np.gradient(H, r.t)
    assert np.max(np.abs(Mz_pinv)) > 0.05
    assert np.max(np.abs(Mz_rl)) <= 1e-6 * np.max(np.abs(Mz_pinv))
