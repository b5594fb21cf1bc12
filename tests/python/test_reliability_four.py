"""Issue 40, reliability's fourth round: one test (or a few) per defect, each failing on the code
before the fix. Names are untrusted input (every writer's output parses back to the same names),
work is bounded before a run starts, every table validation accepts runs, output errors and sweep
workers are handled, both case readers give one verdict.

Test names carry the defect's number in the issue (``test_d01_...`` .. ``test_d13_...``)."""
from __future__ import annotations

import re

import json
import os
import signal
import subprocess
import sys
import time
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from mechbal import _core
from mechbal.cli import main
from mechbal.errors import ConfigError
from mechbal.export.toml import toml_text
from mechbal.mechanism import Mechanism
from mechbal.schema import validate_case

from cli_checks import one_line_error

CASES = Path(__file__).resolve().parents[2] / "python" / "mechbal" / "cases"


def wheel_arm() -> dict:
    return tomllib.loads((CASES / "reaction-wheel-arm.toml").read_text())


def write_case(tmp_path: Path, data: dict, name: str = "case.toml") -> Path:
    path = tmp_path / name
    path.write_text(toml_text(data))
    return path


# ---- 1. names: no injection, a documented character set, every writer escapes ---------------------

def named_arm(names: list[str], zero_mass: str | None = None) -> dict:
    """A three-joint arm whose joints, bodies and frames carry ``names`` (three joint names, then
    a body and a frame), with a body of zero mass named ``zero_mass``."""
    j1, j2, j3, body, frame = names
    bodies = [{"name": body, "link": j2, "mass": 0.7, "com": [0.1, 0.0, 0.0], "inertia": [1e-3, 2e-3, 2e-3]}]
    if zero_mass is not None:
        bodies.append({"name": zero_mass, "link": j3, "mass": 0.0, "com": [0.0, 0.0, 0.0], "inertia": [0, 0, 0]})
    link = lambda m: {"mass": m, "com": [0.15, 0.0, 0.0], "inertia": [1e-3, 5e-3, 5e-3]}  # noqa: E731
    return {"case": {"name": "named", "kind": "mechanism"},
            "mechanism": {"joints": [{"name": j1, "axis": [0, 0, 1], "link": link(1.0)},
                                     {"name": j2, "origin": {"xyz": [0.3, 0, 0]}, "axis": [0, 1, 0], "link": link(0.8)},
                                     {"name": j3, "origin": {"xyz": [0.3, 0, 0]}, "axis": [0, 1, 0], "link": link(0.5)}],
                          "bodies": bodies,
                          "frames": [{"name": frame, "link": j3, "origin": {"xyz": [0.2, 0, 0]}}]}}


INJECTION = '--> <body name="evil"><inertial pos="0 0 0" mass="50" diaginertia="1 1 1"/></body> <!--'
INCLUDE = '--><include file="/etc/passwd"/><!--'


def _mechanism(tmp_path: Path, data: dict) -> Mechanism:
    return Mechanism.from_toml(write_case(tmp_path, data))


def test_d01_a_name_cannot_inject_xml_into_the_mjcf(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    for evil in (INJECTION, INCLUDE, "a -- b", "x-->"):
        mech = _mechanism(tmp_path, named_arm(["j1", "j2", "j3", "cw", "tool"], zero_mass=evil))
        text = mech.to_mjcf()
        root = ET.fromstring(text)  # well-formed
        assert not list(root.iter("include")), evil
        assert evil not in text  # never written raw (not into a comment either)
        model = mujoco.MjModel.from_xml_string(text)
        assert float(np.sum(model.body_mass)) == pytest.approx(mech.total_mass, rel=1e-9, abs=1e-6), evil


def test_d01_control_characters_and_xml_invalid_code_points_are_refused(tmp_path):
    for bad, code in (("a\x01b", "U+0001"), ("a\x00b", "U+0000"), ("a\x7fb", "U+007F"), ("a\x85b", "U+0085"),
                      ("a\ufffeb", "U+FFFE"), ("a\uffffb", "U+FFFF"), ("tab\there", "U+0009")):
        for where in range(5):
            names = ["j1", "j2", "j3", "cw", "tool"]
            names[where] = bad
            with pytest.raises(ConfigError) as exc:
                validate_case(named_arm(names), warn=False)
            assert code in str(exc.value) and exc.value.field.endswith(".name"), exc.value
        # the C++ reader the same
        text = toml_text(named_arm([bad, "j2", "j3", "cw", "tool"]))
        with pytest.raises(ValueError, match=re.escape(code) if ord(bad[1]) < 0x80 else None):
            _core.case_from_toml(text)
        # and every constructor: the model (the URDF reader's and Python's), the Mechanism's name
        with pytest.raises((ValueError, TypeError), match=re.escape(code)):
            Mechanism.from_description([_core.Joint(bad, parent="base")])
    with pytest.raises(ValueError):  # the XML reader's refusal of &#1; or the name's
        Mechanism.from_urdf_string('<robot name="r"><link name="base"/><link name="a&#1;"/>'
                                   '<joint name="j" type="revolute"><parent link="base"/><child link="a&#1;"/>'
                                   '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
                                   '</robot>')
    mech = _mechanism(tmp_path, named_arm(["j1", "j2", "j3", "cw", "tool"]))
    with pytest.raises(ValueError, match=re.escape("U+0007")):
        Mechanism(mech.model, name="bell\x07")


#: the characters a random name draws from: XML's and TOML's special characters, quotes, spaces,
#: dashes (comments), non-ASCII letters and symbols, astral code points
ALPHABET = list("abcXYZ019_-.:/\\'\"<>&;=#[]{}!?* ~$,%") + ["é", "ß", "Ω", "中", "—", "\u2028", "😀", "𝔸", "--", "-->", "]]>"]


def random_names(rng: np.random.Generator, n: int) -> list[str]:
    out: list[str] = []
    while len(out) < n:
        k = int(rng.integers(1, 12))
        s = "".join(ALPHABET[int(i)] for i in rng.integers(0, len(ALPHABET), k))[:128]
        if s and s != "base" and s not in out:
            out.append(s)
    return out


@pytest.mark.parametrize("seed", range(6))
def test_d01_random_names_round_trip_through_every_writer(tmp_path, seed):
    rng = np.random.default_rng(seed)
    names = random_names(rng, 6)
    mech = _mechanism(tmp_path, named_arm(names[:5], zero_mass=names[5]))
    # TOML: parses, and reads back with the same names
    toml = mech.to_toml()
    tomllib.loads(toml)
    (tmp_path / "back.toml").write_text(toml)
    back = Mechanism.from_toml(tmp_path / "back.toml")
    assert back.joint_names == mech.joint_names and back.body_names == mech.body_names
    assert back.frame_names == mech.frame_names
    # URDF: well-formed XML, read back with the same joint names and the same mass
    urdf = mech.to_urdf()
    ET.fromstring(urdf.encode())
    u = Mechanism.from_urdf_string(urdf)
    assert [n for n in u.joint_names] == mech.joint_names
    assert u.total_mass == pytest.approx(mech.total_mass, rel=1e-12)
    # MJCF: well-formed, MuJoCo loads it with the same total mass and the joints by name
    mjcf = mech.to_mjcf()
    ET.fromstring(mjcf.encode())
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(mjcf)
    assert float(np.sum(model.body_mass)) == pytest.approx(mech.total_mass, rel=1e-9)
    assert [model.joint(i).name for i in range(model.njnt)] == mech.joint_names
    # JSON (summary.json's writer) and the bodies file (npz): the same names back
    from mechbal.export.bodies import read_bodies, to_json, write_bodies

    assert json.loads(to_json({"names": names})[0])["names"] == names
    B, N = len(mech.body_names), 2
    write_bodies(tmp_path / "b.npz", t=np.arange(N, dtype=float), names=mech.body_names, mass=np.ones(B),
                 inertia_body=np.zeros((B, 3, 3)), com=np.zeros((N, B, 3)), rotation=np.zeros((N, B, 3, 3)),
                 shaking_force=np.zeros((N, 3)), shaking_moment=np.zeros((N, 3)))
    assert list(read_bodies(tmp_path / "b.npz")["names"]) == mech.body_names
    # plots: a name is drawn as text (never parsed as mathtext)
    from mechbal.report import plot_series

    t = np.linspace(0.0, 1.0, 5)
    plot_series(tmp_path / "p.png", t, {names[0]: np.zeros((5, 3)), "b": np.ones((5, 3))}, mech.joint_names,
                "rad", title=f"{names[4]} $\\frac{{" + names[3])
    assert (tmp_path / "p.png").stat().st_size > 0


def test_d01_the_one_toml_string_writer_escapes_control_characters():
    from mechbal.export.toml import _string

    for s in ("plain", 'q"uote', "back\\slash", "line\nfeed", "nul\x00", "del\x7f", "bell\x07", "é😀\u2028"):
        assert tomllib.loads(f"k = {_string(s)}")["k"] == s
    with pytest.raises(ValueError, match="surrogate"):
        _string("\ud800")


# ---- 2. the tick limit, checked before a run starts ---------------------------------------------

def test_d02_the_tick_limit_is_enforced_by_both_readers(tmp_path):
    data = wheel_arm()
    data["control"]["rate_hz"] = 1e6          # 2 s at 1 MHz: 2e6 ticks
    path = write_case(tmp_path, data)
    with pytest.raises(ConfigError) as py:
        validate_case(tomllib.loads(path.read_text()), warn=False)
    assert py.value.field == "control.rate_hz" and "1000000 ticks" in str(py.value)
    with pytest.raises(ValueError) as cpp:
        _core.load_case_file(str(path))
    assert str(cpp.value) == str(py.value)
    data = wheel_arm()
    data["trajectory"]["duration"] = 1e5      # 1e5 s at 1 kHz
    with pytest.raises(ConfigError, match="ticks"):
        validate_case(data, warn=False)


def test_d02_the_command_line_refuses_it_before_running(tmp_path, capsys):
    data = wheel_arm()
    data["control"]["rate_hz"] = 1e6
    path = write_case(tmp_path, data)
    t0 = time.perf_counter()
    for cmd in (["run", str(path), "--out", str(tmp_path / "o")], ["verify", str(path), "--out", str(tmp_path / "v")]):
        assert main(cmd + ["--quiet"]) == 2
        one_line_error(capsys, "control.rate_hz", "1000000 ticks")
    assert time.perf_counter() - t0 < 30.0
    assert not (tmp_path / "o").exists()


def test_d02_the_python_api_refuses_it_too(tmp_path):
    from mechbal.control import ReactionlessController
    from mechbal.trajectory import RestToRest

    mech = _mechanism(tmp_path, {k: v for k, v in wheel_arm().items() if k != "control"})
    ctrl = ReactionlessController(mech, ["wheel"], "moment_z", "rk4", 1e6, 1e-3, q0=np.zeros(3))
    traj = RestToRest([0.0, 0.0, 0.0], [1.0, -1.2, 0.0], 2.0)
    with pytest.raises(ConfigError, match="ticks"):
        ctrl.follow(traj)


# ---- 3. cancel: what the balancing joints cannot cancel is refused, not reported as done ----------

def test_d03_cancel_both_with_one_wheel_is_not_a_success(tmp_path, capsys):
    data = wheel_arm()
    data["control"]["cancel"] = ["both"]
    path = write_case(tmp_path, data)
    out = tmp_path / "o"
    code = main(["run", str(path), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    assert code == 6, "cancel = both with one balancing wheel reported the goal met"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["ok"] is False
    # the ticks that did not cancel the force say so (they were all ok)
    singular = [e for e in summary["limited_by"] if e.get("status") == "singular"]
    assert singular and singular[0]["ticks"] > 0, summary["limited_by"]


# ---- 4. every table validation accepts runs (no exit 3) -------------------------------------------

@pytest.mark.parametrize("command", ["run", "verify"])
def test_d04_every_actuated_joint_balancing_is_refused_at_validation(tmp_path, capsys, command):
    data = wheel_arm()
    data["control"]["balancing_joints"] = ["shoulder", "elbow", "wheel"]
    data["control"]["cancel"] = ["moment_z"]
    data["trajectory"]["duration"] = 0.2
    path = write_case(tmp_path, data)
    # nothing would be left to follow [trajectory]: refused at validation (both readers), not exit 3
    assert main([command, str(path), "--out", str(tmp_path / command), "--quiet"]) == 2
    one_line_error(capsys, "control.balancing_joints", "every actuated joint")
    with pytest.raises(ValueError, match="every actuated joint"):
        _core.load_case_file(str(path))


def test_d04_task_frame_without_balancing_joints_runs(tmp_path, capsys):
    data = tomllib.loads((CASES / "panda-reactionless.toml").read_text())
    del data["control"]["balancing_joints"]
    data["trajectory"]["duration"] = 0.05
    path = write_case(tmp_path, data)
    code = main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err
    assert code in (0, 6) and "internal error" not in err and "Traceback" not in err, (code, err)


# ---- 5. the text entry points have the file API's size limit -------------------------------------

def test_d05_text_entry_points_refuse_more_than_a_case_file_can_be():
    big = "[case]\nname = 'x'\n" + "# " + "x" * (4 * 1024 * 1024) + "\n"
    for read in (_core.case_from_toml, _core.mechanism_from_toml):
        t0 = time.perf_counter()
        with pytest.raises(ValueError, match="4194304 bytes"):
            read(big)
        assert time.perf_counter() - t0 < 1.0


# ---- 6. export: validated, then written atomically; output errors are exit 2 ----------------------

def test_d06_export_output_errors_are_exit_2_naming_the_path(tmp_path, capsys):
    (tmp_path / "file").write_text("x")
    (tmp_path / "dangling").symlink_to(tmp_path / "nowhere" / "x.xml")
    for out in (tmp_path / "file" / "below.xml", tmp_path / "dangling", Path("/dev/full"),
                Path("/proc/mechbal.xml")):
        code = main(["export", "arm2link", "--format", "mjcf", "--out", str(out), "--quiet"])
        assert code == 2, out
        one_line_error(capsys, str(out))


def test_d06_a_failed_write_keeps_the_previous_file(tmp_path, capsys, monkeypatch):
    import errno

    out = tmp_path / "robot.urdf"
    assert main(["export", "arm2link", "--out", str(out), "--quiet"]) == 0
    good = out.read_text()

    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("mechbal.output.os.fsync", full)
    assert main(["export", "arm2link-balanced", "--format", "urdf", "--out", str(out), "--quiet"]) == 2
    one_line_error(capsys, str(out), "No space left on device")
    assert out.read_text() == good
    assert sorted(p.name for p in tmp_path.iterdir()) == ["robot.urdf"]  # no temporary file left


# ---- 8. --scheduler ------------------------------------------------------------------------------

def test_d08_scheduler_without_the_dask_backend_is_refused(tmp_path, capsys):
    for backend in ([], ["--backend", "processes"], ["--backend", "serial"]):
        code = main(["sweep", "four-bar", "--spec", "four-bar-tolerance", "--out", str(tmp_path / "s"),
                     "--scheduler", "tcp://127.0.0.1:9", *backend, "--quiet"])
        assert code == 2
        one_line_error(capsys, "--scheduler", "--backend dask")


def _closed_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_d08_no_scheduler_at_the_address_is_one_line_exit_2(tmp_path, capsys):
    pytest.importorskip("distributed")
    import socket
    import threading

    import dask

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(4)

    def garbage():  # a peer that is not a Dask scheduler
        while True:
            try:
                c, _ = server.accept()
            except OSError:
                return
            with c:
                c.sendall(b"\xff" * 64 + b"HTTP/1.1 400 Bad Request\r\n\r\n")

    threading.Thread(target=garbage, daemon=True).start()
    try:
        with dask.config.set({"distributed.comm.timeouts.connect": "3s"}):
            for port in (_closed_port(), server.getsockname()[1]):
                code = main(["sweep", "four-bar", "--spec", "four-bar-tolerance", "--out", str(tmp_path / "s"),
                             "--backend", "dask", "--scheduler", f"tcp://127.0.0.1:{port}", "--quiet"])
                assert code == 2
                err = one_line_error(capsys, f"127.0.0.1:{port}", "Dask scheduler")
                assert "out of memory" not in err
    finally:
        server.close()


# ---- 10. URDF: frames keep their places whatever the naming ---------------------------------------

def test_d10_urdf_round_trip_keeps_frames_when_links_are_named_as_other_joints():
    xml = ('<robot name="swap"><link name="base"/>'
           '<link name="j2"><inertial><origin xyz="0.1 0 0" rpy="0 0 0"/><mass value="1"/>'
           '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
           '<link name="j1"><inertial><origin xyz="0.1 0 0" rpy="0 0 0"/><mass value="2"/>'
           '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
           '<joint name="j1" type="revolute"><parent link="base"/><child link="j2"/><origin xyz="0 0 0.1"/>'
           '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
           '<joint name="j2" type="revolute"><parent link="j2"/><child link="j1"/><origin xyz="0.3 0 0"/>'
           '<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    a = Mechanism.from_urdf_string(xml)
    b = Mechanism.from_urdf_string(a.to_urdf())
    assert b.joint_names == a.joint_names
    q = np.array([0.4, -0.7])
    for name in a.frame_names:
        fa = {f.name: f.link for f in a.model.description.frames}[name]
        fb = {f.name: f.link for f in b.model.description.frames}[name]
        assert fa == fb, (name, fa, fb)
    assert b.total_mass == a.total_mass
    np.testing.assert_allclose(b.mass_matrix(q), a.mass_matrix(q), rtol=1e-12, atol=1e-14)


# ---- 11. zombies count as dead ------------------------------------------------------------------

def test_d11_a_zombie_is_not_alive_and_its_partial_folder_is_removed(tmp_path):
    from mechbal.output import _pid_alive, recover_stale

    child = subprocess.Popen([sys.executable, "-c", "pass"])
    deadline = time.time() + 20
    while time.time() < deadline:  # not reaped: a zombie once it has ended
        state = Path(f"/proc/{child.pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        if state == "Z":
            break
        time.sleep(0.02)
    try:
        assert state == "Z"
        assert not _pid_alive(child.pid)
        stale = tmp_path / f".D.partial-{child.pid}-abc"
        stale.mkdir()
        recover_stale(tmp_path / "D")
        assert not stale.exists()
    finally:
        child.wait()
    assert _pid_alive(os.getpid())


# ---- 12. the task controller validates its start --------------------------------------------------

def test_d12_the_task_controller_refuses_a_start_outside_the_declared_limits(tmp_path):
    from mechbal.control import ReactionlessTaskController

    data = tomllib.loads((CASES / "panda-reactionless.toml").read_text())
    mech = Mechanism.from_toml(CASES / "panda-reactionless.toml")
    start = np.array(data["trajectory"]["start"], float)
    ReactionlessTaskController(mech, "panda_hand_tcp", ["linear"], "moment", "rk4", 1000.0, 1e-2, q0=start)
    for k, bad in ((0, 1e300), (3, 0.5), (1, -1e300)):
        q0 = start.copy()
        q0[k] = bad
        with pytest.raises(ValueError, match=rf"q0\[{k}\] \(panda_joint{k + 1}\)"):
            ReactionlessTaskController(mech, "panda_hand_tcp", ["linear"], "moment", "rk4", 1000.0, 1e-2, q0=q0)


# ---- 13. low tick rates: no scipy message --------------------------------------------------------

@pytest.mark.parametrize("rate", [1.0, 2.0, 3.0])
def test_d13_low_tick_rates_run_without_a_scipy_message(tmp_path, capsys, rate):
    data = tomllib.loads((CASES / "panda-reactionless.toml").read_text())
    data["control"]["rate_hz"] = rate
    path = write_case(tmp_path, data)
    code = main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err
    assert code in (0, 6), (code, err)
    assert "scipy" not in err.lower() and "at least" not in err, err


# ---- 7. sweep workers die with the command -------------------------------------------------------

def _children(pid: int) -> list[int]:
    out = []
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                stat = (p / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(p.name))
    return out


def _gone(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return True
    return stat.rsplit(")", 1)[1].split()[0] in ("Z", "X")


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_d07_sweep_workers_die_with_the_command(tmp_path, sig):
    pytest.importorskip("dask")
    spec = (CASES / "sweeps" / "four-bar-tolerance.toml").read_text().replace("evaluations = 5000",
                                                                             "evaluations = 2000000")
    (tmp_path / "long.toml").write_text(spec)
    cmd = [sys.executable, "-m", "mechbal", "sweep", "four-bar", "--spec", str(tmp_path / "long.toml"),
           "--backend", "processes", "--workers", "2", "--out", str(tmp_path / "out"), "--quiet"]
    parent = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    kids: list[int] = []
    try:
        deadline = time.time() + 120
        while time.time() < deadline and len(kids) < 3:   # two workers and the resource tracker
            assert parent.poll() is None, "the sweep ended before its workers started"
            kids = _children(parent.pid)
            time.sleep(0.2)
        assert len(kids) >= 2, kids
        time.sleep(1.0)
        kids = _children(parent.pid)
        parent.send_signal(sig)
        parent.wait(timeout=30)
        deadline = time.time() + 20
        while time.time() < deadline and not all(_gone(k) for k in kids):
            time.sleep(0.2)
        alive = [k for k in kids if not _gone(k)]
        assert alive == [], f"{len(alive)} of the sweep's processes outlived it"
    finally:
        if parent.poll() is None:
            parent.kill()
            parent.wait()
        for k in kids:  # a failing run leaves nothing behind either
            if not _gone(k):
                os.kill(k, signal.SIGKILL)
