"""A URDF controlled and verified (issue 37, point 5): ``mechbal init --from robot.urdf`` writes a
complete case that reads back as the same model; ``run`` / ``verify`` / ``run --engine mujoco``
take ``--design FILE`` (``[trajectory]``, ``[control]``) on a URDF; ``[trajectory] law = "line"``
moves the task frame on a straight line (and about one fixed axis) by a displacement and / or a
rotation; bad design files are refused with one line naming the field."""
from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from mechbal.cases.panda import START, TOOL_FRAME, urdf_path
from mechbal.cli import main
from mechbal.export import read_bodies
from mechbal.mechanism import Mechanism

from cli_checks import one_line_error, summary_of

PANDA = urdf_path()
JOINTS = [f"panda_joint{i}" for i in range(1, 8)]


def _design(tmp_path, trajectory: str = "", control: str | None = None, name: str = "design.toml") -> Path:
    """A design file: the line law from the Panda's folded start (0.2 s, 1 kHz) and the
    operational-space reactionless controller, or the tables given."""
    if not trajectory:
        trajectory = (f'law = "line"\nstart = {list(START)}\ndisplacement = [0.01, 0.0, 0.005]\n'
                      "duration = 0.2\nsamples = 201\n")
    if control is None:
        control = (f'kind = "reactionless"\ntask_frame = "{TOOL_FRAME}"\ntask_rows = ["linear"]\n'
                   f"balancing_joints = {JOINTS!r}\n".replace("'", '"') + 'cancel = ["moment"]\n')
    path = tmp_path / name
    path.write_text(f"[trajectory]\n{trajectory}\n" + (f"[control]\n{control}" if control else ""))
    return path


def _same_dynamics(a: Mechanism, b: Mechanism, seed: int = 0) -> float:
    rng = np.random.default_rng(seed)
    q, v, acc = (rng.uniform(-2.0, 2.0, (20, a.dof)) for _ in range(3))
    worst = 0.0
    for x, y in ((a.inverse_dynamics(q, v, acc), b.inverse_dynamics(q, v, acc)),
                 (a.mass_matrix(q), b.mass_matrix(q)),
                 (a.shaking_wrench(q, v, acc).shaking_moment, b.shaking_wrench(q, v, acc).shaking_moment),
                 (a.center_of_mass(q), b.center_of_mass(q))):
        worst = max(worst, float(np.max(np.abs(np.asarray(x) - np.asarray(y)))))
    return worst


def _urdfs():
    from test_urdf import ROBOTS, _robot_file

    yield PANDA
    try:
        yield _robot_file(*ROBOTS["ur5"])
    except pytest.skip.Exception:
        return


def test_init_from_urdf_reads_back_as_the_same_model(tmp_path, capsys):
    for urdf in _urdfs():
        assert main(["init", "--from", str(urdf)]) == 0
        text = capsys.readouterr().out
        assert text.startswith("#") and "# [control]" in text   # commented
        case = tmp_path / f"{Path(urdf).stem}.toml"
        case.write_text(text)
        raw = tomllib.loads(text)
        assert raw["case"]["kind"] == "mechanism" and set(raw) == {"case", "mechanism", "trajectory"}
        original, back = Mechanism.from_urdf(urdf), Mechanism.from_toml(case)
        assert back.joint_names == original.joint_names
        # a link named 'base' is the frame 'base_frame' (the case format's base is the fixed root)
        assert back.frame_names == ["base_frame" if f == "base" else f for f in original.frame_names]
        assert back.total_mass == pytest.approx(original.total_mass, rel=1e-15)
        assert _same_dynamics(original, back) <= 1e-12
        for key in ("lower_limits", "upper_limits", "velocity_limits", "effort_limits"):
            np.testing.assert_array_equal(getattr(back.model, key), getattr(original.model, key))
        # and the written case runs as it stands
        assert main(["run", str(case), "--out", str(tmp_path / f"run_{case.stem}"), "-q"]) == 0


def test_to_toml_of_a_closed_mechanism_needs_a_trajectory():
    from mechbal.config import builtin_cases

    mech = Mechanism.from_toml(builtin_cases()["four-bar"])
    with pytest.raises(ValueError, match="trajectory="):
        mech.to_toml()
    text = mech.to_toml(trajectory={"law": "quintic", "start": [0.0], "end": [0.5], "duration": 1.0})
    assert tomllib.loads(text)["mechanism"]["loops"]


def _tool_path(mech, q):
    T = np.asarray(mech.frame_placement(q, TOOL_FRAME))
    return T[:, :3, 3], T[:, :3, :3]


def test_run_a_urdf_with_a_design_moves_the_tool_on_a_line(tmp_path, capsys):
    design = _design(tmp_path)
    out = tmp_path / "run"
    assert main(["run", str(PANDA), "--design", str(design), "--out", str(out)]) == 0
    assert "controlled" in capsys.readouterr().out
    s = summary_of(out)
    assert s["case"] == "panda" and s["law"] == "line"
    mech = Mechanism.from_urdf(PANDA)
    p0 = _tool_path(mech, np.array([START]))[0][0]
    d = np.array([0.01, 0.0, 0.005])
    for variant in ("uncontrolled", "controlled"):
        q = read_bodies(out / f"bodies_{variant}.npz")["q"]    # the exported poses
        p, _ = _tool_path(mech, q)
        s_along = (p - p0) @ d / (d @ d)
        off_line = np.linalg.norm(p - p0 - s_along[:, None] * d, axis=1)
        assert np.max(off_line) < 1e-9, variant
        assert s_along[0] == pytest.approx(0.0, abs=1e-12) and s_along[-1] == pytest.approx(1.0, abs=1e-6)
        assert np.all(np.diff(s_along) >= -1e-12)   # monotone along the line (quintic law)
    # the controlled run cancels the moment the uncontrolled one shows
    M = s["peak_shaking_moment"]
    assert max(map(abs, M["controlled"])) < 1e-6 * max(map(abs, M["uncontrolled"]))


def test_the_line_law_turns_the_tool_about_one_axis(tmp_path):
    rotation = [0.0, 0.0, 0.05]
    design = _design(tmp_path, trajectory=(f'law = "line"\nstart = {list(START)}\nrotation = {rotation}\n'
                                           "duration = 0.2\nsamples = 201\n"),
                     control=(f'kind = "reactionless"\ntask_frame = "{TOOL_FRAME}"\n'
                              f"balancing_joints = {JOINTS!r}\n".replace("'", '"') + 'cancel = ["moment_z"]\n'))
    out = tmp_path / "turn"
    assert main(["run", str(PANDA), "--design", str(design), "--out", str(out), "-q"]) == 0
    mech = Mechanism.from_urdf(PANDA)
    q = read_bodies(out / "bodies_controlled.npz")["q"]
    p, R = _tool_path(mech, q)
    np.testing.assert_allclose(p, np.broadcast_to(p[0], p.shape), rtol=0, atol=1e-9)   # the origin stays
    rel = np.einsum("nij,kj->nik", R, R[0])            # R(t) R0^T = exp(s theta [k]x)
    from scipy.spatial.transform import Rotation

    rv = Rotation.from_matrix(rel).as_rotvec()
    np.testing.assert_allclose(rv[-1], rotation, atol=1e-6)
    k = np.array(rotation) / np.linalg.norm(rotation)
    np.testing.assert_allclose(rv - (rv @ k)[:, None] * k, 0.0, atol=1e-9)   # about the fixed axis


def test_verify_and_mujoco_run_a_urdf_with_a_design(tmp_path):
    pytest.importorskip("mujoco")
    design = _design(tmp_path, trajectory=(f'law = "line"\nstart = {list(START)}\n'
                                           "displacement = [0.005, 0.0, 0.0]\nduration = 0.05\nsamples = 51\n"))
    out = tmp_path / "verify"
    assert main(["verify", str(PANDA), "--design", str(design), "--out", str(out), "-q"]) == 0
    assert summary_of(out)["case"] == "panda"
    out = tmp_path / "mujoco"
    assert main(["run", str(PANDA), "--engine", "mujoco", "--design", str(design), "--out", str(out), "-q"]) == 0
    s = summary_of(out)
    assert s["engine"] == "mujoco" and s["law"] == "line"


@pytest.mark.parametrize("tables, needles", [
    ("[trajectory]\nlaw = 'line'\nstart = [0.0]\nduration = 1.0\n", ["trajectory.displacement", "needs displacement"]),
    ("[trajectory]\nlaw = 'line'\nstart = [0, 0, 0, -1, 0, 1, 0]\ndisplacement = [0.01, 0, 0]\nend = [0, 0, 0, -1, 0, 1, 0]\n"
     "duration = 1.0\n", ["trajectory.end", "not for law = 'line'"]),
    ("[trajectory]\nlaw = 'quintic'\nstart = [0, 0, 0, -1, 0, 1, 0]\nend = [0, 0, 0, -1, 0, 1, 0]\nduration = 1.0\n"
     "displacement = [0.01, 0, 0]\n", ["trajectory.displacement", "is for law = 'line'"]),
    ("[trajectory]\nlaw = 'quintic'\nstart = [0.0, 0.0]\nend = [0.1, 0.1]\nduration = 1.0\n", ["trajectory.start", "7 values"]),
    ("[control]\nkind = 'reactionless'\ntask_fram = 'panda_hand_tcp'\n", ["control.task_fram", "task_frame"]),
    ("[control]\nkind = 'reactionless'\ntask_frame = 'panda_hand_tpc'\nbalancing_joints = ['panda_joint1']\n",
     ["control.task_frame", "panda_hand_tcp"]),
    ("[trajectry]\nlaw = 'quintic'\n", ["trajectry", "not a table of a design file", "trajectory"]),
    ("[trajectory]\nlaw = 'line'\nstart = [0, 0, 0, -1, 0, 1, 0]\ndisplacement = [0.01, 0, 0]\nduration = 1.0\n",
     ["trajectory.law", "task_frame"]),
])
def test_bad_design_files_are_refused_naming_the_field(tmp_path, capsys, tables, needles):
    design = tmp_path / "bad.toml"
    design.write_text(tables)
    out = tmp_path / "o"
    assert main(["run", str(PANDA), "--design", str(design), "--out", str(out)]) == 2
    one_line_error(capsys, *needles)
    assert not out.exists()


def test_design_flags_are_checked(tmp_path, capsys):
    design = _design(tmp_path)
    out = str(tmp_path / "o")
    assert main(["run", "arm2link", "--design", str(design), "--out", out]) == 2
    one_line_error(capsys, "--design", "URDF")
    assert main(["run", str(PANDA), "--design", str(design), "--duration", "1", "--out", out]) == 2
    one_line_error(capsys, "--duration", "--design")
    assert main(["run", str(PANDA), "--design", str(tmp_path / "missing.toml"), "--out", out]) == 2
    one_line_error(capsys, "--design", "missing.toml")
    assert main(["init", "--from", str(design)]) == 2
    one_line_error(capsys, "--from", "URDF")
    assert main(["init", "serial", "--from", str(PANDA)]) == 2
    one_line_error(capsys, "--from")
    assert main(["init"]) == 2
    one_line_error(capsys, "--from")
    assert not Path(out).exists()


def test_the_guides_design_file_runs_on_ur5(tmp_path):
    """docs/guide.md's control.toml on example-robot-data's UR5 (its duration cut to 0.1 s)."""
    import re

    from test_urdf import ROBOTS, _robot_file

    urdf = _robot_file(*ROBOTS["ur5"])
    guide = (Path(__file__).resolve().parents[2] / "docs" / "guide.md").read_text()
    block = re.search(r"```toml\n(# control\.toml.*?)```", guide, re.S).group(1)
    design = tmp_path / "control.toml"
    design.write_text(block.replace("duration = 2.0", "duration = 0.1"))
    out = tmp_path / "ur5"
    assert main(["run", str(urdf), "--design", str(design), "--out", str(out), "-q"]) == 0
    s = summary_of(out)
    assert s["law"] == "line" and s["control"]["frame_path_error"]["controlled"]["position"] < 1e-9
    Mz = [abs(r[2]) for r in (s["peak_shaking_moment"]["uncontrolled"], s["peak_shaking_moment"]["controlled"])]
    assert Mz[1] < 1e-6 * Mz[0]
