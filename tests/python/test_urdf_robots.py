"""Real robot descriptions as they are (issue 23): the lenient URDF reading loads what Pinocchio
loads, repairing harmless defects with one warning each that names the URDF element; --strict
refuses them; a URDF with no <inertial> on a moving link is refused unless allow_massless.

The evidence over example-robot-data: every URDF of the package that Pinocchio loads with a fixed
base loads in mechbal; the strict reading refuses a file exactly when the lenient one warned (so
no repair is silent), and the repaired model has Pinocchio's total mass (the repairs change only
negligible bodies)."""
from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal.cli import main
from mechbal.config import ConfigError
from mechbal.mechanism import UrdfRepairWarning

pin = pytest.importorskip("pinocchio")

_LINK = """<link name="{name}"><inertial><origin xyz="{com} 0 0"/><mass value="{mass}"/>
  <inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial></link>"""


def _urdf(root_inertial: str = "", antenna=(0.5, 0.001, 0.001, 0.001), fixed_mimic: bool = False,
          arm_inertial: bool = True) -> str:
    m, ixx, iyy, izz = antenna
    arm = _LINK.format(name="arm", com=0.2, mass=1.5, ixx=0.01, iyy=0.02, izz=0.02) if arm_inertial \
        else '<link name="arm"/>'
    ant = _LINK.format(name="antenna", com=0.05, mass=m, ixx=ixx, iyy=iyy, izz=izz) if arm_inertial \
        else '<link name="antenna"/>'
    mimic = '<mimic joint="shoulder" multiplier="1"/>' if fixed_mimic else ""
    return f"""<robot name="r">
  <link name="base">{root_inertial}</link>
  {arm}
  {ant}
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="20" velocity="3"/></joint>
  <joint name="antenna_mount" type="fixed"><parent link="arm"/><child link="antenna"/>
    <origin xyz="0.4 0 0"/>{mimic}</joint>
</robot>"""


def _load(tmp_path, text, **kw):
    path = tmp_path / "r.urdf"
    path.write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mech = mechbal.Mechanism.from_urdf(path, **kw)
    return mech, [str(w.message) for w in caught if issubclass(w.category, UrdfRepairWarning)]


def test_mimic_on_a_fixed_joint_is_ignored_with_a_warning(tmp_path):
    mech, warned = _load(tmp_path, _urdf(fixed_mimic=True))
    assert mech.dof == 1 and len(warned) == 1
    assert "URDF joint 'antenna_mount'" in warned[0] and "ignored" in warned[0]
    with pytest.raises(ConfigError, match="URDF joint 'antenna_mount'.*mimic.*fixed joint"):
        _load(tmp_path, _urdf(fixed_mimic=True), strict=True)


def test_negligible_body_gets_the_nearest_physical_inertia(tmp_path):
    """A 1 mg antenna with a negative moment (as in the mobile manipulators' files)."""
    mech, warned = _load(tmp_path, _urdf(antenna=(1e-6, -3.5e-8, 1e-8, 1e-8)))
    assert len(warned) == 1 and "URDF link 'antenna' <inertial>" in warned[0] and "nearest physical" in warned[0]
    I = next(b for b in mech.bodies if b.name == "antenna").inertia
    lam = np.linalg.eigvalsh(I)
    assert lam[0] >= -1e-18 and lam[2] <= lam[0] + lam[1] + 1e-18        # physical now
    S = 0.5 * np.trace(I) * np.eye(3) - I                                  # its second moment is
    assert np.min(np.linalg.eigvalsh(S)) >= -1e-18                         # the clipped original's
    with pytest.raises(ConfigError, match="URDF link 'antenna' inertial"):
        _load(tmp_path, _urdf(antenna=(1e-6, -3.5e-8, 1e-8, 1e-8)), strict=True)
    # a body that is not negligible is repaired too (Pinocchio loads it), said louder
    _, warned = _load(tmp_path, _urdf(antenna=(0.5, -3.5e-2, 1e-2, 1e-2)))
    assert len(warned) == 1 and "not negligible" in warned[0] and "correct the file" in warned[0]


def test_root_placeholder_is_dropped(tmp_path):
    """A 1 mg rank-1 placeholder on the root (as in the quadrupeds' files)."""
    root = ('<inertial><mass value="1e-6"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" '
            'izz="1e-9"/></inertial>')
    mech, warned = _load(tmp_path, _urdf(root_inertial=root))
    assert len(warned) == 1 and "URDF link 'base' <inertial>: dropped" in warned[0]
    assert "base" not in mech.body_names
    with pytest.raises(ConfigError, match="URDF link 'base' inertial"):
        _load(tmp_path, _urdf(root_inertial=root), strict=True)


def test_massless_robot_is_refused_naming_the_option(tmp_path):
    with pytest.raises(ConfigError) as info:
        _load(tmp_path, _urdf(arm_inertial=False))
    text = str(info.value)
    assert f"URDF file '{tmp_path / 'r.urdf'}'" in text and "--allow-massless" in text and "<inertial>" in text
    mech, warned = _load(tmp_path, _urdf(arm_inertial=False), allow_massless=True)
    assert mech.dof == 1 and mech.bodies == [] and "kinematics only" in warned[0]


def test_cli_warns_once_per_repair_and_strict_refuses(tmp_path, capsys):
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(fixed_mimic=True, antenna=(1e-6, -3.5e-8, 1e-8, 1e-8)))
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "-q", "--samples", "21"]) == 0
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("mechbal: warning:")]
    assert len(err) == 2 and any("antenna_mount" in ln for ln in err) and any("'antenna'" in ln for ln in err)
    assert main(["run", str(path), "--out", str(tmp_path / "o2"), "-q", "--strict"]) == 2
    assert "antenna_mount" in capsys.readouterr().err
    path.write_text(_urdf(arm_inertial=False))
    assert main(["run", str(path), "--out", str(tmp_path / "o3"), "-q"]) == 2
    assert "--allow-massless" in capsys.readouterr().err


# ---- every robot of example-robot-data ------------------------------------------------------------

def _robots_dir() -> Path:
    for entry in sys.path:
        for robots in (Path(entry) / "cmeel.prefix" / "share" / "example-robot-data" / "robots",):
            if robots.is_dir():
                return robots
    pytest.skip("example-robot-data is not installed (pip install '.[test]')")


def _pin_loads(path: Path):
    try:
        return pin.buildModelFromUrdf(str(path))
    except Exception:  # noqa: BLE001 - what Pinocchio refuses is out of scope
        return None


def test_every_example_robot_that_pinocchio_loads_loads():
    robots = _robots_dir()
    files = sorted(robots.rglob("*.urdf"))
    assert len(files) > 30
    loaded, repaired, refused = 0, {}, []
    for path in files:
        pm = _pin_loads(path)
        if pm is None:
            continue
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                mech = mechbal.Mechanism.from_urdf(path, allow_massless=True)
        except ConfigError as exc:
            refused.append(f"{path.relative_to(robots)}: {exc}")
            continue
        loaded += 1
        warned = [str(w.message) for w in caught if issubclass(w.category, UrdfRepairWarning)
                  and "kinematics only" not in str(w.message)]
        if warned:
            repaired[str(path.relative_to(robots))] = warned
            for w in warned:                      # each names an element of the file
                assert "URDF joint '" in w or "URDF link '" in w, w
        # strict refuses exactly the files that were repaired: no repair is silent
        strict_ok = True
        try:
            mechbal.Mechanism.from_urdf(path, strict=True, allow_massless=True)
        except ConfigError:
            strict_ok = False
        assert strict_ok == (not warned), (path, warned)
        # the repairs touch only negligible bodies: Pinocchio's total mass
        total = sum(float(I.mass) for I in pm.inertias)
        assert mech.total_mass == pytest.approx(total, rel=1e-4, abs=1e-9), path
    assert not refused, "\n".join(refused)
    assert loaded > 30


# ---- the default motion respects the URDF's limits ----------------------------------------------

def test_default_motions_respect_velocity_and_effort_limits(tmp_path):
    """run and balance on a URDF without a [trajectory]: the move is lengthened to the velocity
    limit (3 rad/s) and the effort limit; summary.json echoes the limits and the peaks, checked
    here against the written trajectory."""
    import json

    from mechbal.export import read_bodies

    text = _urdf().replace('effort="20" velocity="3"', 'effort="12" velocity="0.5"')
    path = tmp_path / "r.urdf"
    path.write_text(text)
    design = tmp_path / "design.toml"
    design.write_text('[balance]\nmethod = "static"\nsamples = 50\n[[balance.counterweights]]\n'
                      'name = "cw"\nlink = "arm"\nmass_max = 20.0\nmax_radius = 0.3\n')
    out = tmp_path / "b"
    assert main(["balance", str(path), "--design", str(design), "--out", str(out), "-q", "--allow-partial"]) == 0
    s = json.loads((out / "summary.json").read_text())
    dm = s["case_notes"]["default_motion"]
    assert dm["velocity_limit"] == [0.5] and dm["effort_limit"] == [12.0] and dm["respected"]
    b = read_bodies(out / "bodies_unbalanced.npz")
    assert np.max(np.abs(b["qd"])) <= 0.5 * (1 + 1e-6)
    assert np.max(np.abs(b["torque"])) <= 12.0
    assert s["trajectory"]["duration"] == pytest.approx(dm["duration"]) and dm["duration"] >= 1.0
    out = tmp_path / "r"
    assert main(["run", str(path), "--out", str(out), "-q", "--duration", "0.2"]) == 0
    dm = json.loads((out / "summary.json").read_text())["default_motion"]
    assert dm["respected"] and dm["duration"] > 0.2
    assert max(dm["peak_velocity"]) <= 0.5 * (1 + 1e-6) and max(dm["peak_torque"]) <= 12.0


def test_rounding_that_breaks_the_triangle_inequality_is_judged_to_the_inertia_s_own_scale(tmp_path):
    """icub's feet: products of inertia of 1e-20 on a zero tensor, within the absolute tolerance
    (1e-12 kg m^2) but a triangle broken by 100 % of the tensor's size, which MuJoCo refuses.
    The lenient reading repairs it with a warning, keeping 1e-12 of the trace off the boundary;
    strict refuses it."""
    text = _urdf().replace('<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/>',
                           '<inertia ixx="0" ixy="0" ixz="1.35525e-20" iyy="0" iyz="0" izz="0"/>')
    assert "1.35525e-20" in text
    mech, warned = _load(tmp_path, text)
    assert len(warned) == 1 and "URDF link 'antenna' <inertial>" in warned[0] and "nearest physical" in warned[0]
    lam = np.linalg.eigvalsh(next(b for b in mech.bodies if b.name == "antenna").inertia)
    assert lam[0] + lam[1] - lam[2] >= 0.5e-12 * np.sum(lam) > 0.0      # off the boundary
    with pytest.raises(ConfigError, match="URDF link 'antenna' inertial.*own scale"):
        _load(tmp_path, text, strict=True)
