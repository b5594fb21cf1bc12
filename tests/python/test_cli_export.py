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


def test_batch_shape_errors_name_the_argument():
    N, B = 4, 2
    ok3 = np.zeros((N, B, 3))
    R = np.tile(np.eye(3), (N, B, 1, 1))
    with pytest.raises(ValueError, match=r"rotation must have shape \(4, 2, 3, 3\)"):
        mechbal.shaking_wrench(np.ones(B), np.tile(np.eye(3), (B, 1, 1)), ok3, ok3, ok3,
                               R[:, :1], ok3, ok3)
    with pytest.raises(ValueError, match=r"bodies\[1\].mass"):
        mechbal.shaking_wrench(np.array([1.0, -1.0]), np.tile(np.eye(3), (B, 1, 1)), ok3, ok3,
                               ok3, R, ok3, ok3)


def test_non_finite_instant_gives_status_and_zeros():
    N, B = 3, 1
    z = np.zeros((N, B, 3))
    acc = z.copy()
    acc[1, 0, 0] = np.nan
    out = mechbal.shaking_wrench(np.ones(B), np.eye(3)[None], z, z, acc,
                                 np.tile(np.eye(3), (N, B, 1, 1)), z, z)
    assert out["status"] == mechbal.Status.non_finite_input
    assert np.isfinite(out["force"]).all()
