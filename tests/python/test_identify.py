"""Identification from logs (issue 42): synthetic round trips on a UR5 and a random 6-joint tree
whose true inertias differ from the CAD file's, the identified URDF against Pinocchio, bad logs
refused with one line, the base parameters' regrouping, the log-Cholesky map, excitation.

The logs are simulated from a known "true" model (the CAD parameters perturbed: masses, centres
of mass and inertias changed) plus friction and Gaussian noise; the identification sees the CAD
file and the logs only."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal.cli import main
from mechbal.identify import Friction, Log, LogError, fit, fourier_motion, read_log, simulate_log
from mechbal.identify.base import base_structure, random_states
from mechbal.identify.consistent import consistency, consistent_fit, pseudo_inertia
from mechbal.identify.fitting import IdentifyError, _identified_mechanism
from mechbal.identify.model import body_parameters, structure_of
from mechbal.identify.signal import prepare

sys.path.insert(0, str(Path(__file__).parent))
from random_trees import random_tree  # noqa: E402

NOISE_TAU = 1e-4      # N m: "low noise"
RATE = 500.0          # Hz


def _ur5() -> Path:
    from test_urdf import ROBOTS, _robot_file

    path = _robot_file(*ROBOTS["ur5"])
    if path is None or not Path(path).is_file():
        pytest.skip("example-robot-data is not installed")
    return Path(path)


def _true_model(mech, seed: int):
    """The CAD model with every moving body changed (what the real robot is)."""
    S = structure_of(mech)
    rng = np.random.default_rng(seed)
    pi = S.cad.copy()
    for i in range(len(S.segment_links)):
        p = pi[10 * i:10 * i + 10]
        from mechbal.identify.model import parameters_to_body
        m, c, Ic = parameters_to_body(p)
        m2 = max(m, 0.2) * rng.uniform(0.8, 1.25)
        R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        p1, p2 = rng.uniform(0.004, 0.02, 2)
        p3 = rng.uniform(abs(p1 - p2) + 1e-3, p1 + p2 - 1e-3)    # the triangle inequality holds
        Ic2 = R @ np.diag([p1, p2, p3]) @ R.T + 0.5 * Ic
        pi[10 * i:10 * i + 10] = body_parameters(m2, c + rng.uniform(-0.03, 0.03, 3), Ic2)
    return _identified_mechanism(S, pi), pi


def _motion(dof: int, seed: int, duration: float = 12.0, amplitude: float = 0.25, K: int = 5):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(dof, K)) * amplitude
    b = rng.normal(size=(dof, K)) * amplitude
    t = np.arange(0.0, duration, 1.0 / RATE)
    return (t, *fourier_motion(a, b, np.zeros(dof), duration, t))


def _friction(names):
    return {j: Friction(0.3 + 0.1 * i, 0.5 + 0.2 * i, 0.2 - 0.1 * i) for i, j in enumerate(names)}


def _round_trip(cad, true, logs_seed: int):
    fr = _friction(cad.joint_names)
    log = simulate_log(true, _motion(cad.dof, logs_seed), friction=fr, noise_tau=NOISE_TAU, noise_q=1e-7,
                       noise_v=1e-6, seed=1, source="identification")
    val = simulate_log(true, _motion(cad.dof, logs_seed + 1), friction=fr, noise_tau=NOISE_TAU, noise_q=1e-7,
                       noise_v=1e-6, seed=2, source="validation")
    return fit(cad, [log], validate=[val]), fr


def _check_round_trip(result, pi_true, fr):
    S = result.structure
    x_true = np.concatenate([pi_true, np.ravel([[f.viscous, f.coulomb, f.offset] for f in fr.values()])])
    beta_true = result.base.project(x_true)
    # every base parameter to 1e-3 of its own size (those near zero: of the largest one's 1 %)
    floor = 1e-2 * np.max(np.abs(beta_true))
    rel = np.abs(result.base_values - beta_true) / np.maximum(np.abs(beta_true), floor)
    worst = int(np.argmax(rel))
    assert rel.max() < 1e-3, (result.base.names[worst], beta_true[worst], result.base_values[worst])
    # the consistent model's base parameters: where the consistency constraints are active (bodies on
    # the boundary of the cone, along directions the data barely see) they move a little more
    rel_c = np.abs(result.base.project(result.parameters) - beta_true) / np.maximum(np.abs(beta_true), floor)
    assert rel_c.max() < 1e-2
    # the conic solver converged, and every body is physically consistent: the invariant checked
    # here on the parameters themselves (pseudo-inertia positive semi-definite, positive mass,
    # principal moments non-negative and within the triangle inequality)
    assert result.solver["converged"] and result.solver["status"] in ("Solved", "AlmostSolved")
    assert max(result.solver["primal_residual"], result.solver["dual_residual"], result.solver["gap"]) <= 1e-7
    assert all(c.consistent for c in result.consistency)
    for i in range(len(S.segment_links)):
        pi = result.parameters[10 * i:10 * i + 10]
        J = pseudo_inertia(pi)
        assert np.linalg.eigvalsh(J).min() >= -1e-12 * np.abs(J).max()
        lam = consistency("b", pi).principal_moments
        assert pi[0] > 0 and lam[0] >= 0 and lam[2] <= lam[0] + lam[1] * (1 + 1e-12)
    # the price of consistency on the identification logs: the consistent model's residual is at
    # least least squares' (it minimises the same sum under constraints) and, the true model being
    # consistent, hardly more
    for j in S.joint_names:
        ls, c = result.residual_rms_least_squares[j], result.residual_rms[j]
        assert c <= 1.05 * ls, (j, c, ls)
    assert result.ok and not result.limited_by
    # validation: the identified model approaches the noise level, the CAD model does not
    v = result.validation
    assert v.held_out
    assert v.rms_torque_error_all["identified"] < 3 * NOISE_TAU
    assert v.rms_torque_error_all["cad"] > 100 * v.rms_torque_error_all["identified"]
    assert v.rms_torque_error_all["cad_friction"] > 10 * v.rms_torque_error_all["identified"]
    for j, f in fr.items():
        got = result.friction[j]
        assert got.viscous == pytest.approx(f.viscous, rel=1e-2, abs=1e-3)
        assert got.coulomb == pytest.approx(f.coulomb, rel=1e-2, abs=1e-3)
    assert S.dof == len(fr)


@pytest.fixture(scope="module")
def ur5_fit():
    cad = mechbal.Mechanism.from_urdf(_ur5())
    true, pi = _true_model(cad, 7)
    result, fr = _round_trip(cad, true, 11)
    return cad, true, pi, result, fr


def test_ur5_round_trip(ur5_fit):
    cad, true, pi, result, fr = ur5_fit
    _check_round_trip(result, pi, fr)
    # the regrouping is reported, and the base has fewer parameters than the standard set
    assert result.base.count < len(result.parameter_names)
    assert result.base.regrouping and result.base.unidentifiable
    assert "shoulder_link.m" in result.base.unidentifiable   # the first link's mass moves nothing


def test_random_six_joint_tree_round_trip():
    rng = np.random.default_rng(5)
    tree = random_tree(rng, 6, types="RRRP")
    cad = mechbal.Mechanism.from_urdf_string(tree.urdf(), name="tree")
    assert cad.dof == 6
    true, pi = _true_model(cad, 3)
    result, fr = _round_trip(cad, true, 21)
    _check_round_trip(result, pi, fr)


def test_identified_urdf_matches_pinocchio_and_the_fit(ur5_fit, tmp_path):
    pin = pytest.importorskip("pinocchio")
    from mechbal.identify.report import write_identified

    cad, true, pi, result, fr = ur5_fit
    summary = write_identified(result, tmp_path)
    urdf = tmp_path / "identified.urdf"
    mech = mechbal.Mechanism.from_urdf(urdf, strict=True)
    pm = pin.buildModelFromUrdf(str(urdf))
    pd = pm.createData()
    rng = np.random.default_rng(0)
    S = structure_of(mech)
    for _ in range(5):
        q, v, a = (rng.uniform(-2, 2, mech.dof) for _ in range(3))
        tau = np.asarray(mech.inverse_dynamics(q, v, a))
        ref = pin.rnea(pm, pd, q, v, a)
        assert np.max(np.abs(tau - ref)) <= 1e-12 * max(1.0, np.max(np.abs(ref)))
        # and it is the fitted model: the regressor times the identified parameters
        fitted = S.regressor(q[None], v[None], a[None], friction=False) @ result.parameters[:S.n_inertial]
        assert np.max(np.abs(tau - fitted)) <= 1e-12 * max(1.0, np.max(np.abs(ref)))
    # every body of the file physically consistent
    for b in mech.bodies:
        if b.mass == 0.0:
            continue
        assert consistency(b.name, body_parameters(b.mass, b.com, b.inertia)).consistent
    # the case file is the same model
    toml_mech = mechbal.Mechanism.from_toml(tmp_path / "identified.toml")
    q, v, a = (rng.uniform(-2, 2, mech.dof) for _ in range(3))
    assert np.allclose(toml_mech.inverse_dynamics(q, v, a), mech.inverse_dynamics(q, v, a), rtol=1e-12, atol=1e-12)
    # summary.json: base, full parameters, friction and validation as documented
    data = json.loads((tmp_path / "summary.json").read_text())
    assert data["command"] == "identify" and data["ok"] is True
    assert set(data["friction"]) == set(cad.joint_names)
    assert set(data["friction"]["elbow_joint"]) == {"viscous", "coulomb", "offset"}
    assert set(data["validation"]["rms_torque_error"]) == set(cad.joint_names)
    assert data["validation"]["rms_torque_error_all"] == pytest.approx(
        result.validation.rms_torque_error_all["identified"])
    assert data["base_parameters"] and data["full_parameters"]
    assert summary["files"] == ["identified.urdf", "identified.toml", "validation.png", "parameters.png"]


# ---- the pieces ------------------------------------------------------------------------------

def test_base_parameters_reproduce_the_regressor():
    # W x == W_b (x_b + K x_d) for any x, at states the QR never saw: the regrouping is exact
    cad = mechbal.Mechanism.from_urdf(_ur5())
    S = structure_of(cad)
    bs = base_structure(S)
    rng = np.random.default_rng(42)
    q, v, a = random_states(S, 20, rng)
    W = S.regressor(q, v, a)
    x = rng.normal(size=W.shape[1])
    assert np.allclose(W @ x, W[:, bs.independent] @ bs.project(x), rtol=1e-9, atol=1e-9)
    assert np.linalg.matrix_rank(W[:, bs.independent]) == bs.count


def test_consistency_is_the_pseudo_inertia_test_and_the_fit_keeps_it():
    rng = np.random.default_rng(1)
    # random bodies: consistent exactly when their pseudo-inertia is positive semi-definite
    for _ in range(200):
        pi = rng.normal(size=10)
        psd = np.linalg.eigvalsh(pseudo_inertia(pi)).min() >= 0
        assert consistency("b", pi).consistent == psd
    # a rod's inertia broken: one principal moment above the sum of the other two; a negative mass
    bad = body_parameters(1.0, np.zeros(3), np.diag([0.01, 0.01, 0.05]))
    assert not consistency("b", bad).consistent
    assert not consistency("b", body_parameters(-1.0, np.zeros(3), np.eye(3) * 0.01)).consistent
    # data that pull towards that broken body: least squares takes it, the consistent fit does not,
    # and lands on the closest consistent body (the triangle inequality active: I3 = I1 + I2)
    A = rng.normal(size=(40, 10))
    z = A @ bad
    Rm = np.linalg.qr(A, mode="r")
    Q = np.linalg.qr(A)[0]
    x, report = consistent_fit(Rm, Q.T @ z, 1, 0, body_parameters(1.0, np.zeros(3), np.eye(3) * 0.01),
                               regularisation=0.0)
    assert report.converged
    assert consistency("b", x).consistent
    assert np.linalg.eigvalsh(pseudo_inertia(x)).min() > -1e-12
    lam = consistency("b", x).principal_moments
    assert lam[2] == pytest.approx(lam[0] + lam[1], rel=1e-5)
    assert np.linalg.norm(A @ x - z) > 1e-4


def _lmi_problem(seed: int):
    """A least-squares problem over 3 bodies and 2 joints' friction whose data pull towards
    inconsistent bodies (a broken triangle inequality, a negative mass) and negative friction."""
    rng = np.random.default_rng(seed)
    rod = body_parameters(1.0, np.array([0.1, 0.0, 0.0]), np.diag([0.01, 0.01, 0.05]))
    neg = body_parameters(-0.5, np.zeros(3), np.eye(3) * 0.01)
    ok = body_parameters(2.0, np.array([0.0, 0.05, 0.1]), np.diag([0.03, 0.02, 0.04]))
    x_bad = np.concatenate([rod, neg, ok, [-0.2, 0.5, 0.1, 0.3, -0.4, 0.0]])
    A = rng.normal(size=(300, 36)) * np.concatenate([np.tile([1, .3, .3, .3, .1, .1, .1, .1, .1, .1], 3), np.ones(6)])
    b = A @ x_bad + 1e-3 * rng.normal(size=300)
    Raug = np.linalg.qr(np.column_stack([A, b]), mode="r")
    cad = np.concatenate([body_parameters(1.0, np.zeros(3), np.eye(3) * 0.01),
                          body_parameters(0.8, np.zeros(3), np.eye(3) * 0.01), ok])
    return A, b, Raug[:36, :36], Raug[:36, 36], cad


def test_the_lmi_fit_is_the_one_cvxpy_finds_and_keeps_every_constraint():
    # the same problem written independently with cvxpy (its own PSD constraint J >> 0 and its
    # own canonicalisation) and solved by another solver (SCS): the same minimiser
    cp = pytest.importorskip("cvxpy")
    A, b, R, z, cad = _lmi_problem(3)
    bounds = (0.5, 1.5)
    x, report = consistent_fit(R, z, 3, 6, cad, regularisation=0.0, mass_bounds=bounds)
    assert report.converged and max(report.primal_residual, report.dual_residual, report.gap) <= 1e-7
    X = cp.Variable(36)
    cons = [X[30] >= 0, X[31] >= 0, X[33] >= 0, X[34] >= 0]
    for k in range(3):
        p = X[10 * k:10 * k + 10]
        Io = cp.bmat([[p[4], p[5], p[7]], [p[5], p[6], p[8]], [p[7], p[8], p[9]]])
        Sigma = 0.5 * cp.trace(Io) * np.eye(3) - Io
        h = cp.reshape(p[1:4], (3, 1), order="F")
        J = cp.bmat([[Sigma, h], [h.T, cp.reshape(p[0], (1, 1), order="F")]])
        cons += [0.5 * (J + J.T) >> 0, p[0] >= bounds[0] * cad[10 * k], p[0] <= bounds[1] * cad[10 * k]]
    prob = cp.Problem(cp.Minimize(cp.sum_squares(A @ X - b)), cons)
    prob.solve(solver=cp.SCS, eps_abs=1e-9, eps_rel=1e-9, max_iters=100000)
    ref = np.asarray(X.value)
    cost = float(np.sum((A @ x - b) ** 2))
    assert cost <= prob.value * (1 + 1e-6) + 1e-12
    assert cost == pytest.approx(prob.value, rel=1e-5)
    assert np.max(np.abs(x - ref)) <= 1e-4 * np.max(np.abs(ref))
    # least squares breaks the constraints; the fit keeps each one (rounding aside) and pays for it
    x_ls = np.linalg.lstsq(A, b, rcond=None)[0]
    assert not consistency("rod", x_ls[:10]).consistent and not consistency("neg", x_ls[10:20]).consistent
    assert cost > 1.5 * float(np.sum((A @ x_ls - b) ** 2))
    for k in range(3):
        pi = x[10 * k:10 * k + 10]
        assert consistency(f"b{k}", pi).consistent
        assert np.linalg.eigvalsh(pseudo_inertia(pi)).min() >= 0.0
        assert bounds[0] * cad[10 * k] * (1 - 1e-7) <= pi[0] <= bounds[1] * cad[10 * k] * (1 + 1e-7)
    assert np.all(x[[30, 31, 33, 34]] >= 0)


def _arm(seed: int = 2, n: int = 3):
    return mechbal.Mechanism.from_urdf_string(random_tree(np.random.default_rng(seed), n, types="R",
                                                          branching=False).urdf(), name="arm")


def test_a_solver_that_does_not_converge_is_a_missed_goal():
    arm = _arm()
    log = simulate_log(arm, _motion(arm.dof, 8, duration=6.0), friction=_friction(arm.joint_names),
                       noise_tau=1e-2, seed=8)
    good = fit(arm, [log])
    assert good.ok and good.solver["status"] == "Solved" and good.solver["iterations"] > 2
    starved = fit(arm, [log], max_iterations=2)
    assert not starved.ok and starved.solver["converged"] is False
    assert "conic solver did not converge: status MaxIterations after 2 iterations" in starved.limited_by[0]
    # what it returns is still a consistent model (the verdict says it is not the fit's optimum)
    assert all(c.consistent for c in starved.consistency)
    assert starved.summary()["ok"] is False


def test_without_the_extra_the_consistent_fit_names_it(monkeypatch, tmp_path, capsys):
    from mechbal.identify.consistent import MissingExtra

    arm = _arm()
    log = simulate_log(arm, _motion(arm.dof, 8, duration=3.0), friction=_friction(arm.joint_names),
                       noise_tau=1e-2, seed=8)
    monkeypatch.setitem(sys.modules, "clarabel", None)      # import clarabel raises ImportError
    with pytest.raises(MissingExtra, match=r"'identify' extra: pip install 'mechbal\[identify\]'"):
        fit(arm, [log])
    assert fit(arm, [log], consistent=False).solver == {}
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(random_tree(np.random.default_rng(2), 3, types="R", branching=False).urdf())
    log.to_csv(tmp_path / "a.csv")
    err = _cli_error(capsys, ["identify", str(urdf), str(tmp_path / "a.csv"), "--out", str(tmp_path / "o")])
    assert "mechbal[identify]" in err


def _small_log(mech, n=2000, seed=0):
    return simulate_log(mech, _motion(mech.dof, seed, duration=n / RATE), friction=_friction(mech.joint_names),
                        noise_tau=1e-3, seed=seed, source="small")


def test_csv_and_npz_logs_round_trip(tmp_path):
    cad = mechbal.Mechanism.from_urdf(_ur5())
    log = _small_log(cad)
    back = read_log(log.to_csv(tmp_path / "log.csv")).for_model(cad.joint_names)
    assert np.array_equal(back.q, log.q) and np.array_equal(back.tau, log.tau) and np.array_equal(back.v, log.v)
    np.savez(tmp_path / "log.npz", t=log.t, q=log.q, tau=log.tau, joint_names=np.array(log.joint_names))
    z = read_log(tmp_path / "log.npz")
    assert z.v is None and np.array_equal(z.tau, log.tau)
    # columns in another order are put in the model's
    shuffled = Log(t=log.t, q=log.q[:, ::-1], tau=log.tau[:, ::-1], joint_names=log.joint_names[::-1])
    assert np.array_equal(shuffled.for_model(cad.joint_names).q, log.q)


def test_irregular_sampling_gaps_and_nan_are_handled_and_reported():
    cad = mechbal.Mechanism.from_urdf(_ur5())
    log = _small_log(cad, n=6000)
    rng = np.random.default_rng(3)
    t = log.t + rng.uniform(-0.2, 0.2, log.t.size) / RATE       # jitter
    keep = np.ones(t.size, bool)
    keep[2500:2600] = False                                       # a gap of 0.2 s
    tau = log.tau.copy()
    tau[4000, 2] = np.nan                                         # a NaN row
    bad = Log(t=t[keep], q=log.q[keep], v=log.v[keep], tau=tau[keep], joint_names=log.joint_names, source="rough")
    p = prepare(bad, cutoff_hz=5.0)
    notes = " | ".join(p.notes)
    assert len(p.segments) == 2, notes
    assert "1 gap(s)" in notes and "1 row(s) with a non-finite value dropped" in notes and "resampled" in notes
    for s in p.segments:
        assert np.all(np.isfinite(s.tau)) and np.allclose(np.diff(s.t), np.diff(s.t)[0])


def _cli_error(capsys, argv) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("mechbal: error:")
    return err


def test_bad_logs_are_refused_with_one_line(tmp_path, capsys):
    path = _ur5()
    cad = mechbal.Mechanism.from_urdf(path)
    log = _small_log(cad)
    out = str(tmp_path / "out")
    # a missing joint column
    csv = log.to_csv(tmp_path / "good.csv")
    lines = csv.read_text().splitlines()
    header = lines[0].split(",")
    drop = header.index("tau_elbow_joint")
    (tmp_path / "missing.csv").write_text("\n".join(",".join(c for k, c in enumerate(line.split(",")) if k != drop)
                                                    for line in lines) + "\n")
    err = _cli_error(capsys, ["identify", str(path), str(tmp_path / "missing.csv"), "--out", out])
    assert "missing.csv" in err and "tau_elbow_joint" in err
    # an unknown joint name
    (tmp_path / "unknown.csv").write_text(csv.read_text().replace("elbow_joint", "elbow_jiont"))
    err = _cli_error(capsys, ["identify", str(path), str(tmp_path / "unknown.csv"), "--out", out])
    assert "unknown joint 'elbow_jiont'" in err and "did you mean 'elbow_joint'" in err
    # non-monotonic time
    t = log.t.copy()
    t[100] = t[98]
    Log(t=t, q=log.q, v=log.v, tau=log.tau, joint_names=log.joint_names).to_csv(tmp_path / "time.csv")
    err = _cli_error(capsys, ["identify", str(path), str(tmp_path / "time.csv"), "--out", out])
    assert "non-monotonic time at row 101" in err
    # fewer samples than parameters
    log.slice(0, 5).to_csv(tmp_path / "short.csv")
    err = _cli_error(capsys, ["identify", str(path), str(tmp_path / "short.csv"), "--out", out])
    assert "fewer samples than parameters" in err and "5 samples" in err
    # a constant trajectory
    const = Log(t=log.t, q=np.ones_like(log.q), v=np.zeros_like(log.v), tau=log.tau, joint_names=log.joint_names)
    const.to_csv(tmp_path / "constant.csv")
    err = _cli_error(capsys, ["identify", str(path), str(tmp_path / "constant.csv"), "--out", out])
    assert "constant trajectory" in err
    # a joint that never moves: the parameters it would reveal are named
    t, q, v, a = _motion(cad.dof, 4, duration=8.0)
    q[:, 5] = 0.3
    v[:, 5] = 0.0
    a[:, 5] = 0.0
    still = simulate_log(cad, (t, q, v, a), friction=_friction(cad.joint_names), noise_tau=1e-3, source="still")
    still.to_csv(tmp_path / "still.csv")
    err = _cli_error(capsys, ["identify", str(path), str(tmp_path / "still.csv"), "--out", out])
    assert "do not determine" in err and "wrist_3_joint.viscous" in err
    with pytest.raises(IdentifyError, match="wrist_3_joint.coulomb"):
        fit(cad, [still])
    assert not (tmp_path / "out").exists()


def test_identify_command_line_writes_the_model(tmp_path, capsys):
    path = _ur5()
    cad = mechbal.Mechanism.from_urdf(path)
    true, _ = _true_model(cad, 7)
    fr = _friction(cad.joint_names)
    for name, seed in (("a", 31), ("b", 32)):
        simulate_log(true, _motion(cad.dof, seed, duration=10.0), friction=fr, noise_tau=1e-2,
                     seed=seed).to_csv(tmp_path / f"{name}.csv")
    out = tmp_path / "id"
    assert main(["identify", str(path), str(tmp_path / "a.csv"), "--validate", str(tmp_path / "b.csv"),
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "RMS torque error on the held-out logs" in text
    for f in ("identified.urdf", "identified.toml", "summary.json", "validation.png", "parameters.png"):
        assert (out / f).is_file(), f
    data = json.loads((out / "summary.json").read_text())
    assert data["validation"]["held_out"] is True
    assert data["validation"]["rms_torque_error_all"] < 0.03
    assert data["validation"]["models"]["cad"]["rms_torque_error_all"] > 10 * data["validation"]["rms_torque_error_all"]


def test_a_tolerance_that_cannot_be_met_is_exit_6(tmp_path, capsys):
    # --tolerance 0.5: the consistent model cannot beat unconstrained least squares by 2x
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(random_tree(np.random.default_rng(2), 3, types="R", branching=False).urdf())
    arm = mechbal.Mechanism.from_urdf(urdf)
    simulate_log(arm, _motion(arm.dof, 8, duration=6.0), friction=_friction(arm.joint_names), noise_tau=1e-2,
                 seed=8).to_csv(tmp_path / "a.csv")
    out = tmp_path / "id"
    argv = ["identify", str(urdf), str(tmp_path / "a.csv"), "--out", str(out), "--tolerance", "0.5", "-q"]
    assert main(argv) == 6
    assert "--allow-degraded" in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["ok"] is False and "exceeds 0.5 x least squares'" in summary["limited_by"][0]
    assert main(argv + ["--allow-degraded"]) == 0
    assert main(argv[:-3] + ["-q"]) == 0      # the default tolerance 1.2 is met


# ---- excitation --------------------------------------------------------------------------------

def _planar_arm(n=3):
    rng = np.random.default_rng(2)
    tree = random_tree(rng, n, types="R", branching=False)
    return mechbal.Mechanism.from_urdf_string(tree.urdf(), name="arm")


def test_excitation_keeps_its_limits_starts_at_rest_and_improves_the_condition(tmp_path, capsys):
    from mechbal.identify import excite

    mech = _planar_arm()
    ex = excite(mech, 6.0, 3, max_velocity=1.0, max_acceleration=3.0, max_iterations=15, seed=1)
    t, q, v, a = ex.sample(2000.0)
    assert np.all(q >= ex.lower - 1e-12) and np.all(q <= ex.upper + 1e-12)
    assert np.all(np.abs(v) <= 1.0 + 1e-12) and np.all(np.abs(a) <= 3.0 + 1e-12)
    assert np.allclose(v[0], 0, atol=1e-12) and np.allclose(v[-1], 0, atol=1e-12)
    assert np.allclose(a[0], 0, atol=1e-12) and np.allclose(q[0], q[-1], atol=1e-12)
    assert ex.condition_number < ex.initial_condition_number
    # the finite differences of the written positions are the written velocities
    assert np.allclose(np.gradient(q, t, axis=0)[1:-1], v[1:-1], atol=1e-5)
    # the command line: a CSV a controller can play; an acceleration limit is required
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(random_tree(np.random.default_rng(2), 3, types="R", branching=False).urdf())
    assert main(["excite", str(urdf), "--duration", "6", "--harmonics", "3", "--max-acceleration", "3",
                 "--max-velocity", "1", "--iterations", "3", "--out", str(tmp_path / "traj.csv"), "-q"]) == 0
    header = (tmp_path / "traj.csv").read_text().splitlines()[0].split(",")
    assert header[0] == "t" and header[1] == f"q_{mech.joint_names[0]}" and len(header) == 1 + 3 * mech.dof
    err = _cli_error(capsys, ["excite", str(urdf), "--duration", "6", "--out", str(tmp_path / "x.csv")])
    assert "max_acceleration" in err and "--max-acceleration" in err


def test_log_errors_name_the_file(tmp_path):
    with pytest.raises(LogError, match="not found"):
        read_log(tmp_path / "nope.csv")
    (tmp_path / "x.parquet").write_text("")
    with pytest.raises(LogError, match="unknown log format"):
        read_log(tmp_path / "x.parquet")
    (tmp_path / "bad.csv").write_text("t,q_a,tau_a,speed_a\n0,0,0,0\n")
    with pytest.raises(LogError, match="unknown column 'speed_a'"):
        read_log(tmp_path / "bad.csv")


def test_ros2_bag_joint_states_are_read(tmp_path):
    pytest.importorskip("rosbags")
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    JointState = ts.types["sensor_msgs/msg/JointState"]
    Header = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    bag = tmp_path / "bag"
    with Writer(bag, version=9) as w:
        conn = w.add_connection("/joint_states", JointState.__msgtype__, typestore=ts)
        for k in range(5):
            ns = 1_000_000_000 + 10_000_000 * k
            msg = JointState(header=Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=""),
                             name=["b", "a"] if k % 2 else ["a", "b"],     # the order may change
                             position=np.array([k, -k], float) if k % 2 else np.array([-k, k], float),
                             velocity=np.array([1.0, -1.0]) if k % 2 else np.array([-1.0, 1.0]),
                             effort=np.array([0.5, 0.25]) if k % 2 else np.array([0.25, 0.5]))
            w.write(conn, ns, ts.serialize_cdr(msg, JointState.__msgtype__))
    log = read_log(bag).for_model(["a", "b"])
    assert np.allclose(log.t, 1.0 + 0.01 * np.arange(5))
    assert np.allclose(log.q[:, 0], -np.arange(5)) and np.allclose(log.q[:, 1], np.arange(5))
    assert np.allclose(log.tau, [[0.25, 0.5]] * 5) and np.allclose(log.v, [[-1.0, 1.0]] * 5)
    with pytest.raises(LogError, match="no sensor_msgs/msg/JointState messages on topic '/other'"):
        read_log(bag, topic="/other")
