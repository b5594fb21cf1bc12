"""`mechbal export --format mjcf` and `mechbal balance` validate the MJCF they write (issue 39):
MuJoCo loads it and runs mj_forward at its keyframe without a warning and with every equality
within 1e-9; a failure is an exit-2 error naming the body (or the equality and its bodies) and
the reason, and nothing is written; without MuJoCo a one-line note says the file was not
validated."""
from __future__ import annotations

import json
import re

import pytest

import mechbal
from mechbal.cli import main
from mechbal.export.common import ExportError

mujoco = pytest.importorskip("mujoco")

from mechbal.export import mujoco_engine  # noqa: E402
from mechbal.export.mujoco_engine import validate_mjcf  # noqa: E402


def _four_bar_mjcf() -> str:
    from mechbal.balance.run import balance_case

    bc = balance_case("four-bar")
    q0 = bc.mechanism.closed_motion(bc.motion[0][0], q_guess=bc.q_guess).q
    return bc.mechanism.to_mjcf(q=q0, q_guess=bc.q_guess)


def _break_inertia(text: str, body: str) -> str:
    """``text`` with the inertial of ``body`` breaking A + B >= C (1, 1, 5)."""
    i = text.index(f'<body name="{body}"')
    j = text.index("diaginertia=", i)
    k = text.index('"', j + len("diaginertia=") + 1)
    return text[:j] + 'diaginertia="1 1 5' + text[k:]


def test_a_valid_export_is_validated():
    r = validate_mjcf(_four_bar_mjcf())
    assert r["validated"] and r["max_equality_violation"] <= 1e-9
    assert r["integrator"] == "RK4" and r["timestep"] == pytest.approx(2.5e-4)


def test_an_inertia_mujoco_refuses_names_the_body():
    with pytest.raises(ExportError) as err:
        validate_mjcf(_break_inertia(_four_bar_mjcf(), "coupler"))
    text = str(err.value)
    assert "\n" not in text and "body 'coupler'" in text and "A + B >= C" in text


def test_a_keyframe_off_its_loop_names_the_equality_and_its_bodies():
    text = _four_bar_mjcf()
    key = re.search(r'qpos="([^"]*)"', text)
    values = key.group(1).split()
    values[0] = repr(float(values[0]) + 0.01)          # the crank turned, the loop left open
    bad = text.replace(key.group(0), f'qpos="{" ".join(values)}"')
    with pytest.raises(ExportError) as err:
        validate_mjcf(bad)
    msg = str(err.value)
    assert "\n" not in msg and "equality '" in msg and "'coupler'" in msg and "'rocker'" in msg and "violated" in msg


def test_cli_export_refuses_a_file_mujoco_refuses(tmp_path, capsys, monkeypatch):
    real = mechbal.Mechanism.to_mjcf
    monkeypatch.setattr(mechbal.Mechanism, "to_mjcf", lambda self, *a, **kw: _break_inertia(real(self, *a, **kw), "coupler"))
    out = tmp_path / "f.xml"
    assert main(["export", "four-bar", "--format", "mjcf", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "body 'coupler'" in err and "A + B >= C" in err
    assert not out.exists()


def test_cli_export_validates_or_says_it_could_not(tmp_path, capsys, monkeypatch):
    out = tmp_path / "f.xml"
    assert main(["export", "paminsa", "--format", "mjcf", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert out.exists() and "note" not in captured.err

    def missing():
        raise ImportError("no mujoco")

    monkeypatch.setattr(mujoco_engine, "require_mujoco", missing)
    assert main(["export", "four-bar", "--format", "mjcf", "--out", str(tmp_path / "g.xml")]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not validated" in err and "mechbal[mujoco]" in err
    assert (tmp_path / "g.xml").exists()


def test_balance_validates_balanced_xml(tmp_path, capsys, monkeypatch):
    out = tmp_path / "b"
    assert main(["balance", "four-bar", "--out", str(out), "-q"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["mjcf_validation"]["validated"] and s["mjcf_validation"]["max_equality_violation"] <= 1e-9
    real = mechbal.Mechanism.to_mjcf
    monkeypatch.setattr(mechbal.Mechanism, "to_mjcf", lambda self, *a, **kw: _break_inertia(real(self, *a, **kw), "crank"))
    assert main(["balance", "four-bar", "--out", str(tmp_path / "c"), "-q"]) == 2
    err = capsys.readouterr().err
    assert "balanced.xml" in err and "body 'crank'" in err and not (tmp_path / "c" / "summary.json").exists()
