"""`izz` alone for the links of a planar mechanism (issue 23): accepted only where every revolute
axis is parallel (and every prismatic axis perpendicular) to one normal, refused otherwise naming
the field; a lamina in the plane of motion (izz about the normal, izz / 2 in the plane), which
gives the same torques and shaking wrench as any inertia with that moment about the normal. Both
readers (Python and C++) build the same model from it and refuse the same files."""
from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.export.toml import toml_text
from mechbal.errors import ConfigError
from mechbal.mechanism import Mechanism
from mechbal.schema import validate_case
from mechbal.tables import lamina_inertia

from test_io_parity import assert_same_model

PKG = Path(mechbal.__file__).resolve().parent
FOUR_BAR = tomllib.loads((PKG / "cases" / "four-bar.toml").read_text())


def with_izz(cfg: dict) -> dict:
    """The four-bar with every link's inertia replaced by izz alone: its moment about y, the axis
    of the joints (the four-bar moves in the x-z plane)."""
    out = copy.deepcopy(cfg)
    for j in out["mechanism"]["joints"]:
        iyy = j["link"]["inertia"][1]
        j["link"] = {k: v for k, v in j["link"].items() if k != "inertia"} | {"izz": iyy}
    for b in out["mechanism"]["bodies"]:
        b["izz"] = b.pop("inertia")[1]
    return out


def write(tmp_path: Path, cfg: dict, name: str = "m.toml") -> Path:
    path = tmp_path / name
    path.write_text(toml_text(cfg))
    return path


def test_lamina():
    I = lamina_inertia(0.4, [0, 3.0, 0])
    assert np.allclose(I, np.diag([0.2, 0.4, 0.2]), atol=0)
    p = np.linalg.eigvalsh(lamina_inertia(1.0, [1, 2, 3]))
    assert p == pytest.approx([0.5, 0.5, 1.0]) and p[0] + p[1] >= p[2] - 1e-15   # physical: a lamina


def test_izz_alone_gives_the_dynamics_of_the_full_inertia(tmp_path):
    full = Mechanism.from_toml(write(tmp_path, FOUR_BAR, "full.toml"))
    lam = Mechanism.from_toml(write(tmp_path, with_izz(FOUR_BAR), "izz.toml"))
    rng = np.random.default_rng(3)
    qa = np.linspace(0.0, 2 * np.pi, 50)[:, None]
    va, aa = rng.normal(size=(50, 1)) * 5, rng.normal(size=(50, 1)) * 20
    guess = np.array([1.0, -0.6, 1.3])
    a, b = (m.closed_motion(qa, va, aa, q_guess=guess, with_forces=True) for m in (full, lam))
    assert np.allclose(a.q, b.q, atol=0) and np.allclose(a.actuated_force, b.actuated_force, rtol=1e-13, atol=1e-13)
    wa, wb = full.shaking_wrench(a.q, a.v, a.a), lam.shaking_wrench(b.q, b.v, b.a)
    assert np.max(np.abs(wa.shaking_moment - wb.shaking_moment)) < 1e-12 * np.max(np.abs(wa.shaking_moment))
    assert np.max(np.abs(wa.shaking_force - wb.shaking_force)) < 1e-12 * np.max(np.abs(wa.shaking_force))
    # the links' inertia is the lamina in the x-z plane: izz about y, izz / 2 about x and z
    crank = lam.model.description.bodies[lam.body_names.index("crank")]
    assert np.allclose(np.asarray(crank.inertia), np.diag([0.0015, 0.003, 0.0015]), atol=1e-18)


def test_both_readers_build_the_same_planar_model(tmp_path):
    """The four-bar with izz, and a planar chain in a tilted plane (base rpy, a rotated joint
    origin, a prismatic joint in the plane, a body on a link): the lamina follows the plane."""
    path = write(tmp_path, with_izz(FOUR_BAR))
    assert_same_model(Mechanism.from_toml(path).model, _core.load_mechanism_file(str(path)), np.random.default_rng(0))
    tilted = {"case": {"name": "tilted", "kind": "mechanism"}, "mechanism": {
        "base": {"xyz": [0.1, 0.2, 0.3], "rpy": [0.4, -0.3, 0.2]},
        "joints": [{"name": "a", "axis": [0, 0, 2.0], "link": {"mass": 1.0, "com": [0.1, 0, 0], "izz": 0.02}},
                   {"name": "s", "type": "prismatic", "axis": [1, 1, 0], "origin": {"xyz": [0.3, 0, 0], "rpy": [0, 0, 0.7]},
                    "link": {"mass": 0.4, "izz": 0.004}},
                   {"name": "b", "origin": {"xyz": [0.1, 0, 0], "rpy": [0, 0, -1.1]}, "axis": [0, 0, -1],
                    "link": {"mass": 0.5, "com": [0.2, 0.05, 0.01], "izz": 0.01}}],
        "bodies": [{"name": "cw", "link": "b", "mass": 0.3, "com": [-0.1, 0, 0], "izz": 0.001}]},
        "trajectory": {"start": [0, 0, 0], "end": [1, 0.1, -1], "duration": 1.0}}
    path = write(tmp_path, tilted, "tilted.toml")
    py = Mechanism.from_toml(path)
    assert_same_model(py.model, _core.load_mechanism_file(str(path)), np.random.default_rng(1))
    # the normal of the plane in O is the base's z: every body's inertia about it is its izz
    R = np.asarray(py.model.description.joints[0].placement)[:3, :3]
    n = R @ np.array([0, 0, 1.0])
    motion = py.body_motion(np.array([0.3, 0.05, -0.7]))
    for name, izz in (("a", 0.02), ("s", 0.004), ("b", 0.01), ("cw", 0.001)):
        k = py.body_names.index(name)
        Rb = motion.rotation[k]
        I_o = Rb @ np.asarray(py.model.description.bodies[k].inertia) @ Rb.T
        assert n @ I_o @ n == pytest.approx(izz, rel=1e-12)
        assert np.trace(I_o) == pytest.approx(2 * izz, rel=1e-12)


NOT_PLANAR = {
    "axes not parallel": (lambda m: m["joints"][1].update(axis=[0, 0, 1]), "mechanism.joints[0].link.izz"),
    "tilted origin": (lambda m: m["joints"][2].update(origin={"xyz": [0.45, 0, 0], "rpy": [0.1, 0, 0]}),
                      "mechanism.joints[0].link.izz"),
    "prismatic along the normal": (lambda m: m["joints"].append({"name": "z", "type": "prismatic", "parent": "rocker",
                                                                  "axis": [0, 1, 0]}), "mechanism.joints[0].link.izz"),
    "spherical": (lambda m: m["joints"].append({"name": "ball", "type": "spherical", "parent": "rocker"}),
                  "mechanism.joints[0].link.izz"),
    "inertia and izz": (lambda m: m["joints"][0]["link"].update(inertia=[0.1, 0.1, 0.1]), "mechanism.joints[0].link.izz"),
    "izz negative": (lambda m: m["joints"][1]["link"].update(izz=-0.1), "mechanism.joints[1].link.izz"),
    "izz a string": (lambda m: m["joints"][1]["link"].update(izz="0.1"), "mechanism.joints[1].link.izz"),
    "neither": (lambda m: m["joints"][1]["link"].pop("izz"), "mechanism.joints[1].link.inertia"),
    "body izz with rpy": (lambda m: m["bodies"][0].update(rpy=[0, 0, 0.3]), "mechanism.bodies[0].rpy"),
}


@pytest.mark.parametrize("name", list(NOT_PLANAR))
def test_refused_by_both_readers(tmp_path, name):
    mutate, field = NOT_PLANAR[name]
    cfg = with_izz(FOUR_BAR)
    cfg.pop("balance")
    mutate(cfg["mechanism"])
    with pytest.raises(ConfigError) as exc:
        validate_case(cfg, warn=False)
    assert exc.value.field == field, str(exc.value)
    with pytest.raises(ValueError) as cpp:
        _core.load_mechanism_file(str(write(tmp_path, cfg)))
    assert str(cpp.value).startswith(field + ": "), str(cpp.value)


def test_the_message_says_why(tmp_path):
    cfg = with_izz(FOUR_BAR)
    cfg["mechanism"]["joints"][1]["axis"] = [0, 0, 1]
    with pytest.raises(ConfigError) as exc:
        validate_case(cfg, warn=False)
    text = str(exc.value)
    assert "planar" in text and "'coupler'" in text and "inertia = [Ixx, Iyy, Izz]" in text and "0.003" in text
