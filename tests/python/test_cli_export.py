"""The command line and the shared data export: files, schema, and the shaking wrench recomputed
from the exported poses alone by finite differences."""
import json
import subprocess
import sys

import numpy as np
import pytest

import mechbal
from mechbal.cli import main
from mechbal.export import read_bodies, shaking_wrench_by_finite_differences


def test_help_documents_every_command(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--help"])
    assert e.value.code == 0
    text = capsys.readouterr().out
    for cmd in ("cases", "run", "demo"):
        assert cmd in text


def test_cases_lists_builtin(capsys):
    assert main(["cases"]) == 0
    assert "arm2link" in capsys.readouterr().out


def test_console_script_runs():
    r = subprocess.run([sys.executable, "-m", "mechbal", "cases"], capture_output=True, text=True)
    assert r.returncode == 0 and "arm2link" in r.stdout


def test_bad_case_is_a_clear_error(capsys):
    assert main(["run", "no_such_case", "--out", "unused"]) == 2
    assert "no_such_case" in capsys.readouterr().err


def test_run_writes_schema(demo_run):
    out, summary = demo_run
    on_disk = json.loads((out / "summary.json").read_text())
    assert on_disk["case"] == "arm2link"
    assert (out / "shaking_wrench.png").stat().st_size > 10_000
    data = read_bodies(out / "bodies_nominal.npz")
    N, B = data["t"].shape[0], data["names"].shape[0]
    assert data["mass"].shape == (B,) and data["inertia_body"].shape == (B, 3, 3)
    assert data["com"].shape == (N, B, 3) and data["rotation"].shape == (N, B, 3, 3)
    assert data["shaking_force"].shape == (N, 3) and data["shaking_moment"].shape == (N, 3)
    assert np.allclose(on_disk["peak_shaking_force"]["nominal"],
                       np.abs(data["shaking_force"]).max(axis=0))


def test_exported_wrench_matches_finite_differences_of_poses(demo_run):
    out, _ = demo_run
    data = read_bodies(out / "bodies_nominal.npz")
    F_fd, M_fd = shaking_wrench_by_finite_differences(data)
    inner = slice(2, -2)  # one-sided differences at the ends are less accurate
    F, M = data["shaking_force"], data["shaking_moment"]
    scale_F = np.linalg.norm(F, axis=1).max()
    scale_M = np.linalg.norm(M, axis=1).max()
    assert scale_F > 1.0 and scale_M > 1.0  # the motion really shakes the base
    assert np.abs(F_fd[inner] - F[inner]).max() < 1e-4 * scale_F
    assert np.abs(M_fd[inner] - M[inner]).max() < 1e-4 * scale_M


def test_shaking_force_is_total_mass_times_com_acceleration(demo_run):
    """Invariant: F = m_total * d^2/dt^2 (centre of mass of the system)."""
    out, _ = demo_run
    d = read_bodies(out / "bodies_nominal.npz")
    com_sys = np.einsum("b,nbi->ni", d["mass"], d["com"]) / d["mass"].sum()
    acc = np.gradient(np.gradient(com_sys, d["t"], axis=0), d["t"], axis=0)
    F = d["shaking_force"]
    assert np.abs(d["mass"].sum() * acc[3:-3] - F[3:-3]).max() < 1e-3 * np.abs(F).max()


# ---------------------------------------------------- the deprecated body-set shaking wrench
def test_deprecated_body_set_wrench_warns_and_checks_its_arguments():
    """mechbal.shaking_wrench (a set of bodies given their motion) stays one release: it warns,
    pointing to the general model and to the finite differences of poses, and keeps its checks."""
    N, B = 4, 2
    ok3 = np.zeros((N, B, 3))
    R = np.tile(np.eye(3), (N, B, 1, 1))
    for name in ("mechbal.shaking_wrench", "mechbal.papers.shaking_wrench"):
        fn = mechbal.shaking_wrench if name == "mechbal.shaking_wrench" else mechbal.papers.shaking_wrench
        with pytest.warns(DeprecationWarning, match=r"Mechanism\.shaking_wrench.*shaking_wrench_by_finite_differences"):
            with pytest.raises(ValueError, match=r"rotation must have shape \(4, 2, 3, 3\)"):
                fn(np.ones(B), np.tile(np.eye(3), (B, 1, 1)), ok3, ok3, ok3, R[:, :1], ok3, ok3)
        with pytest.warns(DeprecationWarning):
            with pytest.raises(ValueError, match=r"bodies\[1\].mass"):
                fn(np.array([1.0, -1.0]), np.tile(np.eye(3), (B, 1, 1)), ok3, ok3, ok3, R, ok3, ok3)


def test_deprecated_body_set_wrench_gives_a_status_and_zeros_per_bad_instant():
    N, B = 3, 1
    z = np.zeros((N, B, 3))
    acc = z.copy()
    acc[0, 0, 2] = -9.81
    acc[1, 0, 0] = np.nan
    acc[2, 0, 0] = 1e308
    with pytest.warns(DeprecationWarning):
        out = mechbal.shaking_wrench(np.full(B, 2.0), np.eye(3)[None], z, z, acc,
                                     np.tile(np.eye(3), (N, B, 1, 1)), z, z)
    S = mechbal.Status
    assert list(out["status_per_instant"]) == [S.ok, S.non_finite_input, S.out_of_range]
    assert int(out["status"]) == int(S.non_finite_input) | int(S.out_of_range)
    assert all(np.isfinite(v).all() for k, v in out.items() if k.startswith(("force", "moment", "linear", "angular")))
    assert out["force"][0] == pytest.approx([0.0, 0.0, -19.62], abs=1e-12)
    assert np.all(out["force"][1:] == 0.0)


def test_deprecated_body_set_wrench_equals_the_general_model():
    """Fed with the bodies' motion of a mechanism, the deprecated sum gives the mechanism's
    shaking wrench (Mechanism.shaking_wrench), momenta included."""
    from random_trees import random_tree

    tree = random_tree(np.random.default_rng(5), 5)
    mech = mechbal.Mechanism.from_urdf_string(tree.urdf())
    rng = np.random.default_rng(6)
    q, v, a = (rng.uniform(-1.5, 1.5, (7, mech.dof)) for _ in range(3))
    m, w = mech.body_motion(q, v, a), mech.shaking_wrench(q, v, a)
    bodies = mech.model.bodies
    with pytest.warns(DeprecationWarning):
        old = mechbal.shaking_wrench(np.array([b.mass for b in bodies]), np.array([b.inertia for b in bodies]),
                                     m.com, m.com_velocity, m.com_acceleration, m.rotation,
                                     m.angular_velocity, m.angular_acceleration)
    for key, general in (("force", w.shaking_force), ("moment", w.shaking_moment),
                         ("linear_momentum", w.linear_momentum), ("angular_momentum", w.angular_momentum)):
        assert np.abs(old[key] - general).max() < 1e-12 * max(1.0, np.abs(general).max()), key


def test_body_set_reference_matches_finite_differences_of_its_momenta():
    """The tests' numpy reference sum (body_set.py) on analytically known motions: its force and
    moment are the time derivatives of its momenta (central differences), so that it can stand as
    the independent check of the general model and of the papers' closed forms."""
    from body_set import body_set_wrench

    rng = np.random.default_rng(9)
    B = 4
    mass = rng.uniform(0.2, 2.0, B)
    Q = np.linalg.qr(rng.normal(size=(B, 3, 3)))[0]
    inertia = Q @ (np.eye(3) * rng.uniform(0.05, 0.1, (B, 1, 3))) @ np.swapaxes(Q, 1, 2)
    c0, c1, u = rng.normal(size=(B, 3)), rng.normal(size=(B, 3)), rng.normal(size=(B, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    f, g = rng.uniform(1.0, 3.0, B), rng.uniform(1.0, 4.0, B)
    K = np.cross(u[:, None, :], -np.eye(3)[None])  # [u]x per body

    def motion(t):
        th, thd, thdd = np.sin(g * t), g * np.cos(g * t), -g * g * np.sin(g * t)
        R = np.eye(3) + np.sin(th)[:, None, None] * K + (1 - np.cos(th))[:, None, None] * (K @ K)
        com = c0 + c1 * np.sin(f * t)[:, None]
        vel = c1 * (f * np.cos(f * t))[:, None]
        acc = -c1 * (f * f * np.sin(f * t))[:, None]
        return [x[None] for x in (com, vel, acc, R, u * thd[:, None], u * thdd[:, None])]

    h = 1e-5
    for t in (0.3, 0.9, 1.7):
        at, plus, minus = (body_set_wrench(mass, inertia, *motion(s)) for s in (t, t + h, t - h))
        dP = (plus["linear_momentum"] - minus["linear_momentum"]) / (2 * h)
        dH = (plus["angular_momentum"] - minus["angular_momentum"]) / (2 * h)
        assert np.abs(dP - at["force"]).max() < 1e-7 * np.abs(at["force"]).max()
        assert np.abs(dH - at["moment"]).max() < 1e-7 * np.abs(at["moment"]).max()
        # not a trivial comparison: the rotational terms (I alpha + w x I w) are 1e5 times the
        # tolerance above
        points = body_set_wrench(mass, 0.0 * inertia, *motion(t))
        assert np.abs(at["moment"] - points["moment"]).max() > 1e-2 * np.abs(at["moment"]).max()
