"""One format, two readers (issue 27): the C++ case reader (mechbal::load_mechanism, toml++) and
the Python reader (mechbal.spec + Mechanism.from_spec) build the same model from every built-in
case with a [mechanism] table, every balanced.toml that `mechbal balance` writes, and a corpus of
random valid cases (every joint form, spherical joints, gears, bodies with rpy, frames, loops,
springs, base, gravity): the same names, types, parents, gear couplings, limits, masses and kinds
exactly; placements, axes, centres of mass, inertias and spring anchors to a few ulps (numpy's
BLAS sums the 3x3 / 4x4 products with FMA in a CPU-dependent order; the C++ reader with plain
products), exactly where no rotation or DH frame applies; the mass matrix and gravity torque at
random states to 1e-15 relative. Both readers refuse the same invalid corpus, naming the same
field."""
from __future__ import annotations

import copy
import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import _core
from mechbal.export.toml import toml_text
from mechbal.errors import ConfigError
from mechbal.mechanism import Mechanism
from mechbal.spec import mechanism_spec

PKG = Path(mechbal.__file__).resolve().parent
EPS = np.finfo(float).eps
#: a few ulps of the largest entry (see the module docstring)
ULPS = 8


def builtin_mechanism_cases() -> list[Path]:
    """Every TOML file of the package with a [mechanism] table (cases/ and the papers' packages)."""
    out = []
    for p in sorted(PKG.rglob("*.toml")):
        try:
            data = tomllib.loads(p.read_text())
        except (tomllib.TOMLDecodeError, UnicodeDecodeError):
            continue
        if isinstance(data.get("mechanism"), dict):
            out.append(p)
    return out


def close(a, b, what: str, scale: float | None = None) -> None:
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, what
    s = max(1.0, float(np.max(np.abs(a)))) if scale is None else scale
    err = float(np.max(np.abs(a - b))) if a.size else 0.0
    assert err <= ULPS * EPS * s, f"{what}: differs by {err:.3g} (scale {s:.3g})"


def assert_same_model(py_model, cpp_model, rng: np.random.Generator, exact_geometry: bool = False) -> None:
    dp, dc = py_model.description, cpp_model.description
    assert dc.root_name == dp.root_name
    assert np.array_equal(np.asarray(dc.gravity), np.asarray(dp.gravity))
    geometry = (lambda a, b, what: np.testing.assert_array_equal(a, b, what)) if exact_geometry else close
    assert [j.name for j in dc.joints] == [j.name for j in dp.joints]
    for jc, jp in zip(dc.joints, dp.joints):
        assert (jc.type, jc.parent, jc.mimic_joint, jc.mimic_ratio, jc.mimic_offset) == \
            (jp.type, jp.parent, jp.mimic_joint, jp.mimic_ratio, jp.mimic_offset), jp.name
        assert (jc.lower, jc.upper, jc.velocity_limit, jc.effort_limit) == \
            (jp.lower, jp.upper, jp.velocity_limit, jp.effort_limit), jp.name
        geometry(jc.placement, jp.placement, f"joint {jp.name} placement")
        geometry(jc.axis, jp.axis, f"joint {jp.name} axis")
    assert [(b.name, b.kind, b.link) for b in dc.bodies] == [(b.name, b.kind, b.link) for b in dp.bodies]
    for bc, bp in zip(dc.bodies, dp.bodies):
        assert bc.mass == bp.mass, bp.name
        geometry(bc.com, bp.com, f"body {bp.name} com")
        geometry(bc.inertia, bp.inertia, f"body {bp.name} inertia")
    assert [(f.name, f.link) for f in dc.frames] == [(f.name, f.link) for f in dp.frames]
    for fc, fp in zip(dc.frames, dp.frames):
        geometry(fc.placement, fp.placement, f"frame {fp.name}")
    assert [(lp.name, lp.type, lp.frame_a, lp.frame_b) for lp in dc.loops] == \
        [(lp.name, lp.type, lp.frame_a, lp.frame_b) for lp in dp.loops]
    assert list(dc.actuated) == list(dp.actuated)
    key = lambda s: (s.name, s.link_a, s.link_b, s.rate, s.free_length, s.preload, s.count, s.pulley_ratio)  # noqa: E731
    assert [key(s) for s in dc.springs] == [key(s) for s in dp.springs]
    for sc, sp in zip(dc.springs, dp.springs):
        geometry(sc.anchor_a, sp.anchor_a, f"spring {sp.name} anchor_a")
        geometry(sc.anchor_b, sp.anchor_b, f"spring {sp.name} anchor_b")
    # the dynamics of the two models at random states
    mp, mc = Mechanism(py_model), Mechanism(cpp_model)
    assert mc.dof == mp.dof and list(cpp_model.coordinate_names) == list(py_model.coordinate_names)
    q = rng.uniform(-1.5, 1.5, size=(12, mp.dof))
    for name, fp, fc in (("mass matrix", mp.mass_matrix, mc.mass_matrix),
                         ("gravity torque", mp.gravity_torque, mc.gravity_torque)):
        a, b = fp(q), fc(q)
        scale = float(np.max(np.abs(a)))
        if scale == 0.0:
            assert np.array_equal(a, b), name
            continue
        err = float(np.max(np.abs(a - b)))
        assert err <= 1e-15 * scale, f"{name}: relative difference {err / scale:.3g}"


# ---- built-in cases ------------------------------------------------------------------------------

BUILTIN = builtin_mechanism_cases()


def test_the_builtin_corpus_is_found():
    names = {p.stem for p in BUILTIN}
    assert {"four-bar", "paminsa-linkage", "ur5-dh", "orthoglide", "rpsp"} <= names, names


@pytest.mark.parametrize("path", BUILTIN, ids=lambda p: p.stem)
def test_builtin_case(path):
    rng = np.random.default_rng(sum(path.stem.encode()))
    py = Mechanism.from_toml(path)
    cpp = _core.load_mechanism_file(str(path))
    assert_same_model(py.model, cpp, rng)


def test_bodies_without_rotation_are_bitwise_equal():
    """Where no rotation or DH frame applies, the two readers do the same arithmetic: bit for bit."""
    path = PKG / "papers" / "paminsa" / "cases" / "paminsa-linkage.toml"
    dp, dc = Mechanism.from_toml(path).model.description, _core.load_mechanism_file(str(path)).description
    n = 0
    for bc, bp in zip(dc.bodies, dp.bodies):
        assert bc.mass == bp.mass
        np.testing.assert_array_equal(bc.com, bp.com)
        np.testing.assert_array_equal(bc.inertia, bp.inertia)
        n += 1
    assert n == 38


# ---- balanced.toml of `mechbal balance` (every method that applies to a built-in case) ----------

METHODS = ("static", "force", "moment", "springs", "rms")


@pytest.fixture(scope="module")
def balanced_files(tmp_path_factory):
    from mechbal.cli import main

    root = tmp_path_factory.mktemp("balanced")
    # every built-in case file (cases/ or a paper's package), by path
    cases = [p for p in sorted(PKG.rglob("*.toml")) if "sweeps" not in p.parts
             and isinstance(tomllib.loads(p.read_text()).get("case"), dict)]
    out, stems = [], [c.stem for c in cases]
    for case in cases:
        label = case.stem if stems.count(case.stem) == 1 else f"{case.parent.name}-{case.stem}"
        for method in METHODS:
            d = root / f"{label}-{method}"
            try:
                # a balance that is not reached is written all the same (--allow-partial: exit 0)
                rc = main(["balance", str(case), "--method", method, "--out", str(d), "-q", "--allow-partial"])
            except SystemExit as exc:  # argparse refusals
                rc = exc.code
            if rc == 0 and (d / "balanced.toml").exists():
                out.append(d / "balanced.toml")
    return out


def test_every_balanced_toml(balanced_files):
    written = {p.parent.name for p in balanced_files}
    # the methods of the built-in cases (test_balance_cli.py, test_balance_cases.py)
    assert {"arm2dof-rms", "four-bar-force", "paminsa-force", "rpsp-force", "orthoglide-springs",
            "discs-3r-moment", "ur5-dh-static"} <= written, written
    rng = np.random.default_rng(27)
    for path in balanced_files:
        assert "mechanism" in tomllib.loads(path.read_text()), path.parent.name
        assert_same_model(Mechanism.from_toml(path).model, _core.load_mechanism_file(str(path)), rng)


# ---- random valid cases --------------------------------------------------------------------------

def _inertia(rng) -> list | dict:
    a, c = rng.uniform(1.0, 2.0, 2)  # largest <= the sum of the two others
    p = np.array([a, c, 0.5 * (a + c)]) * 0.05
    form = rng.integers(3)
    # half the list forms are written in the named form, decided by a generator of their own so
    # that the corpus drawn from rng stays what it was
    pick = np.random.default_rng(int(a * 1e9))
    named = form != 2 and pick.uniform() < 0.5
    if form == 0:
        if named:  # principal axes: the products absent (0)
            return {"ixx": float(p[0]), "iyy": float(p[1]), "izz": float(p[2])}
        return p.tolist()
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    I = Q @ np.diag(p) @ Q.T
    I = 0.5 * (I + I.T)
    if form == 1:
        six = [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]
        if named:  # the named form, keys in any order
            keys = ["ixx", "iyy", "izz", "ixy", "ixz", "iyz"]
            return {keys[k]: float(six[k]) for k in pick.permutation(6)}
        return six
    return I.tolist()


def _vec(rng, lo, hi) -> list:
    return rng.uniform(lo, hi, 3).tolist()


def random_mechanism(seed: int) -> dict:
    """A random valid [mechanism] table using every form of the format."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7))
    joints, names = [], []
    for i in range(n):
        unnamed = rng.uniform() < 0.2  # the default name joint<i>
        name = f"joint{i + 1}" if unnamed else f"j{i}"
        j: dict = {} if unnamed else {"name": name}
        kinds = ["revolute", "prismatic", "fixed", "spherical"]
        t = kinds[int(rng.choice(4, p=[0.55, 0.2, 0.1, 0.15]))] if i > 0 else "revolute"
        j["type"] = t
        if i > 0 and rng.uniform() < 0.4:
            j["parent"] = str(rng.choice(["base"] + names))
        form = int(rng.integers(4))
        if form == 0:
            j["origin"] = {"xyz": _vec(rng, -0.4, 0.4), "rpy": _vec(rng, -1.5, 1.5)}
            if t in ("revolute", "prismatic") and rng.uniform() < 0.8:
                j["axis"] = rng.normal(size=3).tolist()
        elif form == 1:
            j["mdh"] = {"a": float(rng.uniform(-0.4, 0.4)), "alpha": float(rng.uniform(-1.5, 1.5)),
                        "d": float(rng.uniform(-0.3, 0.3)), "theta": float(rng.uniform(-1, 1))}
        elif form == 2:
            j["dh"] = {"a": float(rng.uniform(-0.4, 0.4)), "alpha": float(rng.uniform(-1.5, 1.5)),
                       "d": float(rng.uniform(-0.3, 0.3)), "theta": float(rng.uniform(-1, 1))}
        if t in ("revolute", "prismatic") and rng.uniform() < 0.3:
            j["limits"] = {"lower": -1.0, "upper": float(rng.uniform(0, 2)), "velocity": 3.0, "effort": 40.0}
        movers = [names[k] for k, x in enumerate(joints) if x["type"] in ("revolute", "prismatic") and "mimic" not in x]
        if t in ("revolute", "prismatic") and movers and rng.uniform() < 0.25:
            j["mimic"] = {"joint": str(rng.choice(movers)), "ratio": float(rng.uniform(-3, 3)),
                          "offset": float(rng.uniform(-0.5, 0.5))}
        if rng.uniform() < 0.85:
            j["link"] = {"mass": float(rng.uniform(0.1, 3)), "com": _vec(rng, -0.3, 0.3), "inertia": _inertia(rng)}
        joints.append(j)
        names.append(name)
    links = ["base"] + names + [f"{names[k]}_y" for k, j in enumerate(joints) if j["type"] == "spherical"]
    table: dict = {"gravity": _vec(rng, -10, 10), "joints": joints}
    if rng.uniform() < 0.5:
        table["base"] = {"xyz": _vec(rng, -1, 1), "rpy": _vec(rng, -1, 1)}
    table["bodies"] = [{"name": f"b{k}", "kind": str(rng.choice(["counterweight", "motor", "disc", "payload", "other"])),
                        "link": str(rng.choice(links)), "mass": float(rng.uniform(0, 2)), "com": _vec(rng, -0.5, 0.5),
                        "inertia": _inertia(rng), "rpy": _vec(rng, -2, 2)} for k in range(int(rng.integers(0, 4)))]
    table["frames"] = [{"name": f"f{k}", "link": str(rng.choice(links)),
                        "origin": {"xyz": _vec(rng, -0.5, 0.5), "rpy": _vec(rng, -1, 1)}}
                       for k in range(int(rng.integers(0, 4)))]
    spring_links = list(links)
    table["springs"] = []
    for k in range(int(rng.integers(0, 3))):
        la, lb = rng.choice(spring_links, 2, replace=False)
        table["springs"].append({"name": f"s{k}", "link_a": str(la), "anchor_a": _vec(rng, -0.3, 0.3),
                                 "link_b": str(lb), "anchor_b": _vec(rng, -0.3, 0.3),
                                 "rate": float(rng.uniform(0, 500)), "free_length": float(rng.uniform(0, 0.2)),
                                 "preload": float(rng.uniform(0, 10)), "count": int(rng.integers(1, 4)),
                                 "pulley_ratio": float(rng.uniform(0.5, 3))})
    if len(table["frames"]) >= 2 and rng.uniform() < 0.5:
        if table["frames"][1]["link"] == table["frames"][0]["link"]:  # a loop closes two links
            table["frames"][1]["link"] = "base" if table["frames"][0]["link"] != "base" else names[-1]
        table["loops"] = [{"name": "loop", "type": str(rng.choice(["point", "planar_point", "axis", "weld"])),
                           "frame_a": "f0", "frame_b": "f1"}]
        spec = mechanism_spec({k: v for k, v in copy.deepcopy(table).items() if k != "loops"})
        table["actuated"] = spec.independent_joints[:1]
    return {k: v for k, v in table.items() if v != []}


def write_case(tmp_path: Path, mechanism: dict, name: str = "case") -> Path:
    path = tmp_path / f"{name}.toml"
    path.write_text(toml_text({"case": {"name": name, "kind": "mechanism"}, "mechanism": mechanism}))
    return path


@pytest.mark.parametrize("seed", range(40))
def test_random_valid_case(tmp_path, seed):
    path = write_case(tmp_path, random_mechanism(seed))
    assert_same_model(Mechanism.from_toml(path).model, _core.load_mechanism_file(str(path)),
                      np.random.default_rng(seed))


def test_the_random_corpus_covers_the_format():
    seen = set()
    for seed in range(40):
        m = random_mechanism(seed)
        for j in m["joints"]:
            seen.add(j["type"])
            seen.update(["unnamed"] if "name" not in j else [])
            seen.update(k for k in ("origin", "mdh", "dh", "axis", "mimic", "limits", "parent") if k in j)
        seen.update(k for k in ("base", "bodies", "frames", "loops", "springs", "actuated") if k in m)
        inertias = [j["link"]["inertia"] for j in m["joints"] if "link" in j] + [b["inertia"] for b in m.get("bodies", [])]
        seen.update("named inertia" if isinstance(x, dict) else f"inertia of {len(x)}" for x in inertias)
        seen.update("named inertia without products" for x in inertias if isinstance(x, dict) and len(x) == 3)
    assert seen >= {"named inertia", "named inertia without products", "inertia of 3", "inertia of 6",
                    "unnamed", "revolute", "prismatic", "fixed", "spherical", "origin", "mdh", "dh", "axis", "mimic",
                    "limits", "parent", "base", "bodies", "frames", "loops", "springs", "actuated"}, seen


# ---- the invalid corpus: both readers refuse it, naming the same field ---------------------------

NAN, INF = "__nan__", "__inf__"


def _set(path: tuple, value):
    def mutate(m):
        t = m
        for k in path[:-1]:
            t = t[k]
        t[path[-1]] = value
    return mutate


def _drop(path: tuple):
    def mutate(m):
        t = m
        for k in path[:-1]:
            t = t[k]
        del t[path[-1]]
    return mutate


def _append(key: str, item):
    return lambda m: m.setdefault(key, []).append(item)


def base_table() -> dict:
    return {"joints": [{"name": "a", "link": {"mass": 1.0, "com": [0.1, 0, 0], "inertia": [0.01, 0.02, 0.02]}},
                       {"name": "b", "origin": {"xyz": [0.3, 0, 0]}, "axis": [0, 1, 0],
                        "link": {"mass": 0.5, "inertia": [0.01, 0.01, 0.01]}},
                       {"name": "s", "type": "spherical", "parent": "b"}],
            "frames": [{"name": "fa", "link": "a"}, {"name": "fb", "link": "s"}]}


SPRING = {"name": "k", "link_a": "base", "anchor_a": [0, 0, 1], "link_b": "a", "anchor_b": [0.1, 0, 0], "rate": 10.0}
BODY = {"name": "cw", "link": "a", "mass": 1.0, "inertia": [0, 0, 0]}

INVALID = {
    # names: printable, no control character or code point XML refuses (issue 40)
    "joint name with a control character": _set(("joints", 0, "name"), "a\x01b"),
    "frame name with a line feed": _set(("frames", 0, "name"), "f\na"),
    "body name with a NUL": _append("bodies", {**BODY, "name": "c\x00w"}),
    "frame name with U+FFFE": _set(("frames", 1, "name"), "f\ufffe"),
    "parent with a C1 control": _set(("joints", 1, "parent"), "a\x85"),
    "unknown key": _set(("joints", 0, "nme"), "x"),
    "unknown table key": _set(("bodys",), []),
    "misspelled nested": _set(("joints", 1, "origin", "xzy"), [0, 0, 0]),
    "mass negative": _set(("joints", 0, "link", "mass"), -1.0),
    "mass a string": _set(("joints", 0, "link", "mass"), "1.0"),
    "mass a boolean": _set(("joints", 0, "link", "mass"), True),
    "mass nan": _set(("joints", 0, "link", "mass"), NAN),
    "mass inf": _set(("joints", 0, "link", "mass"), INF),
    "mass absurd": _set(("joints", 0, "link", "mass"), 1e13),
    "mass missing": _drop(("joints", 0, "link", "mass")),
    "inertia missing": _drop(("joints", 0, "link", "inertia")),
    "inertia shape": _set(("joints", 0, "link", "inertia"), [1.0, 2.0]),
    "inertia not symmetric": _set(("joints", 0, "link", "inertia"), [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]),
    "inertia negative": _set(("joints", 0, "link", "inertia"), [-1.0, 1.0, 1.0]),
    "inertia triangle": _set(("joints", 0, "link", "inertia"), [1.0, 1.0, 3.0]),
    "inertia entry nan": _set(("joints", 0, "link", "inertia"), [1.0, NAN, 1.0]),
    "inertia named unknown key": _set(("joints", 0, "link", "inertia"), {"ixx": 1.0, "iyy": 1.0, "izz": 1.0, "ixq": 0.0}),
    "inertia named upper case": _set(("joints", 0, "link", "inertia"), {"Ixx": 1.0, "iyy": 1.0, "izz": 1.0}),
    "inertia named moment missing": _set(("joints", 0, "link", "inertia"), {"ixx": 1.0, "izz": 1.0}),
    "inertia named entry string": _set(("joints", 0, "link", "inertia"), {"ixx": 1.0, "iyy": "1", "izz": 1.0}),
    "inertia named entry bool": _set(("joints", 0, "link", "inertia"), {"ixx": 1.0, "iyy": 1.0, "izz": 1.0, "ixy": True}),
    "inertia named entry nan": _set(("joints", 0, "link", "inertia"), {"ixx": 1.0, "iyy": NAN, "izz": 1.0}),
    "inertia named entry list": _set(("joints", 0, "link", "inertia"), {"ixx": [1.0], "iyy": 1.0, "izz": 1.0}),
    "inertia named triangle": _set(("joints", 0, "link", "inertia"), {"ixx": 1.0, "iyy": 1.0, "izz": 3.0}),
    "inertia named negative": _set(("joints", 0, "link", "inertia"), {"ixx": 1.0, "iyy": 1.0, "izz": 1.0, "ixy": 2.0}),
    "body inertia named unknown key": _append("bodies", {**BODY, "inertia": {"ixx": 0.0, "iyy": 0.0, "izz": 0.0, "iyx": 0.0}}),
    "com short": _set(("joints", 0, "link", "com"), [0.1, 0.0]),
    "com entry string": _set(("joints", 0, "link", "com"), [0.1, "x", 0.0]),
    "xyz absurd": _set(("joints", 1, "origin", "xyz"), [0.3, 0, 2e12]),
    "rpy inf": _set(("joints", 1, "origin", "rpy"), [0, INF, 0]),
    "joint type": _set(("joints", 0, "type"), "revolut"),
    "joint name empty": _set(("joints", 0, "name"), ""),
    "joint name long": _set(("joints", 0, "name"), "x" * 129),
    "joint name base": _set(("joints", 0, "name"), "base"),
    "joint name duplicate": _set(("joints", 1, "name"), "a"),
    "spherical name clash": _set(("joints", 1, "name"), "s_y"),
    "unknown parent": _set(("joints", 1, "parent"), "c"),
    "own parent": _set(("joints", 1, "parent"), "b"),
    "cycle": lambda m: (m["joints"][0].__setitem__("parent", "b")),
    "origin and mdh": _set(("joints", 1, "mdh"), {"a": 0.1, "alpha": 0.0}),
    "axis on dh": lambda m: m["joints"][0].update({"dh": {"a": 0.1, "alpha": 0.0}, "axis": [1, 0, 0]}),
    "axis zero": _set(("joints", 1, "axis"), [0, 0, 0]),
    "axis on spherical": _set(("joints", 2, "axis"), [0, 0, 1]),
    "dh missing alpha": _set(("joints", 0, "mdh"), {"a": 0.1}),
    "limits reversed": _set(("joints", 0, "limits"), {"lower": 1.0, "upper": 0.0}),
    "velocity limit zero": _set(("joints", 0, "limits"), {"velocity": 0.0}),
    "limits on spherical": _set(("joints", 2, "limits"), {"lower": -1.0}),
    "mimic unknown": _set(("joints", 1, "mimic"), {"joint": "zz"}),
    "mimic itself": _set(("joints", 1, "mimic"), {"joint": "b"}),
    "mimic base": _set(("joints", 1, "mimic"), {"joint": "base"}),
    "mimic spherical": _set(("joints", 1, "mimic"), {"joint": "s"}),
    "mimic of a mimic": lambda m: (m["joints"][1].__setitem__("mimic", {"joint": "a"}),
                                   m["joints"].append({"name": "c", "mimic": {"joint": "b"}})),
    "mimic ratio string": _set(("joints", 1, "mimic"), {"joint": "a", "ratio": "2"}),
    "no joints": _set(("joints",), []),
    "joints not a list": _set(("joints",), {"name": "a"}),
    "gravity short": _set(("gravity",), [0, -9.81]),
    "base unknown key": _set(("base",), {"xyz": [0, 0, 0], "rot": [0, 0, 0]}),
    "body kind": _append("bodies", {**BODY, "kind": "weight"}),
    "body link unknown": _append("bodies", {**BODY, "link": "zz"}),
    "body name duplicate": _append("bodies", {**BODY, "name": "a"}),
    "body mass missing": _append("bodies", {k: v for k, v in BODY.items() if k != "mass"}),
    "frame duplicate": _append("frames", {"name": "fa", "link": "b"}),
    "frame named base": _append("frames", {"name": "base", "link": "b"}),
    "frame link unknown": _append("frames", {"name": "fc", "link": "q"}),
    "loop frame unknown": _append("loops", {"name": "l", "frame_a": "fa", "frame_b": "fz"}),
    "loop type": _append("loops", {"name": "l", "type": "hinge", "frame_a": "fa", "frame_b": "fb"}),
    "loop without actuated": _append("loops", {"name": "l", "frame_a": "fa", "frame_b": "fb"}),
    "loop on one link": lambda m: (m["frames"].append({"name": "fc", "link": "a"}), m.update(actuated=["a"]),
                                   m.setdefault("loops", []).append({"name": "l", "frame_a": "fa", "frame_b": "fc"})),
    "actuated unknown": _set(("actuated",), ["zz"]),
    "actuated twice": _set(("actuated",), ["a", "a"]),
    "spring same link": _append("springs", {**SPRING, "link_b": "base"}),
    "spring count float": _append("springs", {**SPRING, "count": 2.0}),
    "spring count zero": _append("springs", {**SPRING, "count": 0}),
    "spring rate negative": _append("springs", {**SPRING, "rate": -1.0}),
    "spring pulley zero": _append("springs", {**SPRING, "pulley_ratio": 0.0}),
    "spring anchor missing": _append("springs", {k: v for k, v in SPRING.items() if k != "anchor_b"}),
    "spring link unknown": _append("springs", {**SPRING, "link_a": "zz"}),
    "spring duplicate": lambda m: m.update(springs=[SPRING, dict(SPRING)]),
    # izz alone: only where the mechanism is planar (this one has a spherical joint), not with inertia
    "izz not planar": _set(("joints", 0, "link"), {"mass": 1.0, "izz": 0.01}),
    "izz and inertia": _set(("joints", 0, "link", "izz"), 0.01),
    "izz negative": _set(("joints", 0, "link"), {"mass": 1.0, "izz": -0.01}),
    "body izz with rpy": _append("bodies", {"name": "cw", "link": "a", "mass": 1.0, "izz": 0.01, "rpy": [0, 0, 1]}),
    "body izz not planar": _append("bodies", {"name": "cw", "link": "a", "mass": 1.0, "izz": 0.01}),
}


def invalid_text(mutate) -> str:
    m = base_table()
    mutate(m)
    text = toml_text({"case": {"name": "bad", "kind": "mechanism"}, "mechanism": m})
    return text.replace(f'"{NAN}"', "nan").replace(f'"{INF}"', "inf")


def test_the_base_of_the_invalid_corpus_is_valid(tmp_path):
    text = invalid_text(lambda m: None)
    (tmp_path / "ok.toml").write_text(text)
    assert_same_model(Mechanism.from_toml(tmp_path / "ok.toml").model, _core.mechanism_from_toml(text),
                      np.random.default_rng(0))


@pytest.mark.parametrize("name", list(INVALID))
def test_both_readers_refuse(tmp_path, name):
    text = invalid_text(INVALID[name])
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as py_exc:
        Mechanism.from_toml(path)
    with pytest.raises(ValueError) as cpp_exc:
        _core.load_mechanism_file(str(path))
    py_field, cpp_message = py_exc.value.field, str(cpp_exc.value)
    assert cpp_message.startswith(py_field + ": "), f"Python: {py_exc.value}\nC++:    {cpp_message}"
    assert "\n" not in cpp_message


def test_cpp_messages_name_the_value():
    msg = lambda name: str(pytest.raises(ValueError, _core.mechanism_from_toml, invalid_text(INVALID[name])).value)  # noqa: E731
    assert msg("mass negative") == "mechanism.joints[0].link.mass: must be >= 0 (got -1.0)"
    assert msg("mass nan") == "mechanism.joints[0].link.mass: must be finite (got nan)"
    assert msg("unknown key").startswith("mechanism.joints[0].nme: unknown key (did you mean 'name'?)") or \
        msg("unknown key").startswith("mechanism.joints[0].nme: unknown key")
    assert msg("unknown parent") == "mechanism.joints[1].parent: unknown parent joint (allowed: a, b, s_z, s_y, s_x, s, base) (got 'c')" \
        or "(got 'c')" in msg("unknown parent")
    assert "(got 'revolut')" in msg("joint type") and "did you mean 'revolute'" in msg("joint type")


# ---- text that breaks toml++ 3.3.0's own assumptions: both readers refuse it at the same place ------
# toml++ 3.3.0 asserts (an abort in a debug build, undefined behaviour in a release one) on a table
# header that starts no key (fixed upstream after 3.4.0) and on a `}` where an array expects a
# value, and reaches __builtin_unreachable on most characters that are not ASCII outside strings and
# comments (fixed upstream after 3.4.0): the C++ reader refuses them before toml++ reads them.
# Found by the C++ case-reader fuzz corpus (tests/cpp/case_fuzz.cpp); each is invalid TOML.

TOML_HAZARDS = {
    "header, fuzz corpus minimised": (b"[.", "a table header must start with a key"),
    "header, fuzz corpus line": (b"[.2, 0.0, 0.0] }   # crank length 0.2 m\n", "a table header must start with a key"),
    "header, bracket alone": (b"[\n", "a table header must start with a key"),
    "header, three brackets": (b"[[[1]]]\n", "a table header must start with a key"),
    "header, array spaced": (b"[[ =]]\n", "a table header must start with a key"),
    "header, comment": (b"  [\t# x\n", "a table header must start with a key"),
    "header, crlf": (b"[\r\n", "a table header must start with a key"),
    "header, non-ascii": ("[\u00e9]\n".encode(), "a table header must start with a key"),
    "brace, fuzz corpus minimised": (b"s=[}", "expected a value or ']' in an array"),
    "brace, fuzz corpus line": (b"axis = [0.0, }\n", "expected a value or ']' in an array"),
    "brace, multi-line": (b"x = [\n  1,\n# }\n}\n", "expected a value or ']' in an array"),
    "brace, in an inline table": (b"x = { a = [} }\n", "expected a value or ']' in an array"),
    "non-ascii key": ("\u00e9 = 1\n".encode(), "is not ASCII"),
    "non-ascii after a number": ("x = 1\u00e9\n".encode(), "is not ASCII"),
    "ideographic space": ('x = "a" \u3000\n'.encode(), "is not ASCII"),
    "line separator in an array": ("x = [\u2028]\n".encode(), "is not ASCII"),
    "non-ascii after a header": ("[a]\u032a\n".encode(), "is not ASCII"),
}


@pytest.mark.parametrize("name", list(TOML_HAZARDS))
def test_both_readers_refuse_toml_hazards(tmp_path, name):
    tail, cpp_says = TOML_HAZARDS[name]
    path = tmp_path / "hazard.toml"
    path.write_bytes((PKG / "cases" / "reaction-wheel-arm.toml").read_bytes() + tail)
    with pytest.raises(ConfigError) as py_exc:
        Mechanism.from_toml(path)
    with pytest.raises(ValueError) as cpp_exc:
        _core.load_mechanism_file(str(path))
    py_msg, cpp_msg = str(py_exc.value), str(cpp_exc.value)
    assert py_exc.value.field == str(path) and "is not valid TOML" in py_msg, py_msg
    assert cpp_msg.startswith(f"{path}: is not valid TOML: ") and cpp_says in cpp_msg, cpp_msg
    # the same place: tomllib's "(at line L, column C)", the C++ reader's "(line L, column C)"
    where = lambda msg: re.search(r"line (\d+), column (\d+)\)$", msg).groups()  # noqa: E731
    assert where(py_msg) == where(cpp_msg), f"Python: {py_msg}\nC++:    {cpp_msg}"


def test_both_readers_read_non_ascii_after_a_line_ending_backslash(tmp_path):
    """A multi-line string wrapped by a line-ending backslash onto a line that starts with a
    character that is not ASCII (which the C++ reader hands to toml++ as its escape)."""
    text = (PKG / "cases" / "reaction-wheel-arm.toml").read_text()
    text = text.replace('name = "elbow"', 'name = """el\\\n    b\u00f6w\\\n\n \u2028\u00e9"""')
    path = tmp_path / "wrapped.toml"
    path.write_text(text, encoding="utf-8")
    py = Mechanism.from_toml(path)
    cpp = _core.load_mechanism_file(str(path))
    assert [j.name for j in cpp.description.joints] == [j.name for j in py.model.description.joints]
    assert "elb\u00f6w\u2028\u00e9" in [j.name for j in py.model.description.joints]


# ---- [control] through the C++ reader ---------------------------------------------------------------

def test_load_case_file_reads_control(tmp_path):
    model, control, name = _core.load_case_file(str(PKG / "papers" / "paminsa" / "cases" / "paminsa-linkage.toml"))
    assert name == "paminsa-linkage" and control.kind == "none" and len(model.actuated_coordinates) == 6
    path = tmp_path / "c.toml"
    path.write_text(invalid_text(lambda m: None) + '\n[control]\nkind = "computed_torque"\nrate_hz = 500\n'
                    'kp = [100.0, 100.0, 100.0, 100.0, 100.0]\nkd = [20, 20, 20, 20, 20]\n')
    model, control, name = _core.load_case_file(str(path))
    assert (control.kind, control.rate_hz, control.kp, control.kd) == ("computed_torque", 500.0, [100.0] * 5, [20.0] * 5)
    path.write_text(path.read_text().replace("kd = [20, 20, 20, 20, 20]", "kd = [20, 20]"))
    with pytest.raises(ValueError, match=r"^control\.kd: must have 5 values"):
        _core.load_case_file(str(path))


# ---- [control]: the same configuration, the same refusals (issue 27 with issue 21's table) ----------

from mechbal.config import read_toml  # noqa: E402
from mechbal.schema import validate_case  # noqa: E402

CONTROL_KEYS = ("kind", "balancing_joints", "cancel", "integrator", "rate_hz", "damping", "max_rate",
                "home_gain", "limit_gain", "task_frame", "kp", "kd", "torque_limit", "k")


def wheel_arm() -> dict:
    """The reaction-wheel arm with a tool frame on its forearm (for task_frame)."""
    data = tomllib.loads((PKG / "cases" / "reaction-wheel-arm.toml").read_text())
    data["mechanism"]["frames"] = [{"name": "tool", "link": "elbow", "origin": {"xyz": [0.4, 0.0, 0.0]}}]
    return data


def builtin_control_cases() -> list[Path]:
    return [p for p in builtin_mechanism_cases() if isinstance(tomllib.loads(p.read_text()).get("control"), dict)]


def both_controls(tmp_path: Path, data: dict):
    text = toml_text(data).replace(f'"{NAN}"', "nan").replace(f'"{INF}"', "inf")
    path = tmp_path / "control.toml"
    path.write_text(text)
    py = validate_case(read_toml(path), warn=False).control
    _, cpp, _ = _core.load_case_file(str(path))
    _, from_text, _ = _core.case_from_toml(text)  # the same reader on the text
    assert all(getattr(from_text, k) == getattr(cpp, k) for k in CONTROL_KEYS)
    return py, cpp


def assert_same_control(py, cpp) -> None:
    """Every field of the C++ ControlConfig equals the Python reader's (absent lists: empty)."""
    for key in CONTROL_KEYS:
        p, c = getattr(py, key), getattr(cpp, key)
        if key == "task_frame":
            p = p or ""
        elif key in ("kp", "kd", "torque_limit", "k"):
            p = [] if p is None else [float(x) for x in p]
        elif isinstance(c, list):
            p = [] if p is None else list(p)
        elif isinstance(c, float):
            p = float("inf") if p is None and key == "max_rate" else float(p)  # undeclared: no limit
        assert c == p, (key, p, c)
    # the numbers bitwise (what the controller is built from)
    for key in ("rate_hz", "damping", "max_rate", "home_gain", "limit_gain"):
        value = getattr(py, key)
        value = float("inf") if value is None else value
        assert np.float64(getattr(cpp, key)).tobytes() == np.float64(value).tobytes(), key


def test_the_builtin_control_corpus_is_found():
    assert "reaction-wheel-arm.toml" in {p.name for p in builtin_control_cases()}


@pytest.mark.parametrize("path", builtin_control_cases(), ids=lambda p: p.stem)
def test_builtin_control(path, tmp_path):
    py = validate_case(read_toml(path), warn=False).control
    _, cpp, _ = _core.load_case_file(str(path))
    assert_same_control(py, cpp)


def random_control(seed: int) -> dict:
    """A valid [control] of the wheel arm (3 actuated joints, frame 'tool'): each optional field
    present or not, of every kind, integers where the format allows them."""
    rng = np.random.default_rng(seed)
    kind = ["reactionless", "computed_torque", "decoupled"][seed % 3]
    pick = lambda p=0.5: rng.random() < p  # noqa: E731
    num = lambda lo, hi: int(rng.integers(max(1, int(lo)), int(hi) + 1)) if pick(0.3) else float(rng.uniform(lo, hi))  # noqa: E731
    per_joint = lambda: [num(0.5, 500.0) for _ in range(3)]  # noqa: E731
    c: dict = {"kind": kind}
    if pick():
        c["rate_hz"] = num(1.0, 1e5)
    if kind == "reactionless":
        if pick(0.2):
            c["task_frame"] = "tool"
        if "task_frame" not in c or pick():
            joints = ["shoulder", "elbow", "wheel"]
            # the joint mode keeps one actuated joint out to follow [trajectory]; the task mode may list all
            most = 4 if "task_frame" in c else 3
            c["balancing_joints"] = [str(j) for j in rng.choice(joints, size=int(rng.integers(1, most)), replace=False)]
        if pick():
            names = ["moment", "force", "both", "moment_x", "moment_y", "moment_z", "force_x", "force_y", "force_z"]
            c["cancel"] = [str(n) for n in rng.choice(names, size=int(rng.integers(1, 10)))]
        if pick():
            c["integrator"] = str(rng.choice(["euler", "rk4"]))
        if pick():
            c["damping"] = float(rng.uniform(1e-6, 0.999))
        for key in ("max_rate", "home_gain", "limit_gain"):
            if pick():
                c[key] = num(0.01, 1e3)
        if pick(0.3):
            c["kp"], c["kd"] = per_joint(), per_joint()
    else:
        c["kp"], c["kd"] = per_joint(), per_joint()
        if kind == "decoupled" and pick():
            c["k"] = per_joint()
    if "kp" in c and pick():
        c["torque_limit"] = per_joint()
    return c


@pytest.mark.parametrize("seed", range(60))
def test_random_valid_control(tmp_path, seed):
    data = wheel_arm()
    data["control"] = random_control(seed)
    assert_same_control(*both_controls(tmp_path, data))


def _control(**changes):
    """The wheel arm's [control] with keys set (None: removed)."""
    def mutate(c: dict):
        for k, v in changes.items():
            if v is None:
                c.pop(k, None)
            else:
                c[k] = v
    return mutate


REACTIONLESS_ONLY = dict(balancing_joints=None, cancel=None, integrator=None, damping=None)
GAINS = dict(kp=[1.0, 2.0, 3.0], kd=[1.0, 1.0, 1.0])

INVALID_CONTROL = {
    "not a table": lambda c: "__replace__",
    "kind missing": _control(kind=None),
    "kind misspelled": _control(kind="reactionles"),
    "kind a number": _control(kind=1),
    "unknown key": _control(balancing=["wheel"]),
    "unknown table": _control(limits={"max_rate": 1.0}),
    "balancing missing": _control(balancing_joints=None),
    "balancing empty": _control(balancing_joints=[]),
    "balancing a string": _control(balancing_joints="wheel"),
    "balancing entry a number": _control(balancing_joints=[1]),
    "balancing entry empty": _control(balancing_joints=[""]),
    "balancing entry long": _control(balancing_joints=["w" * 129]),
    "balancing unknown": _control(balancing_joints=["wheal"]),
    "balancing twice": _control(balancing_joints=["wheel", "wheel"]),
    "balancing too many": _control(balancing_joints=[f"j{i}" for i in range(257)]),
    "balancing every actuated joint": _control(balancing_joints=["shoulder", "elbow", "wheel"]),
    "balancing entry with a control character": _control(balancing_joints=["whe\x01el"]),
    "cancel empty": _control(cancel=[]),
    "cancel a string": _control(cancel="moment"),
    "cancel unknown": _control(cancel=["moment_w"]),
    "cancel too long": _control(cancel=["moment"] * 10),
    "integrator unknown": _control(integrator="rk5"),
    "integrator a number": _control(integrator=4),
    "rate zero": _control(rate_hz=0),
    "rate huge": _control(rate_hz=2e6),
    "rate nan": _control(rate_hz=NAN),
    "rate inf": _control(rate_hz=INF),
    "rate a string": _control(rate_hz="1000"),
    "rate a boolean": _control(rate_hz=True),
    "damping zero": _control(damping=0.0),
    "damping one": _control(damping=1),
    "damping negative": _control(damping=-0.1),
    "damping nan": _control(damping=NAN),
    "max_rate zero": _control(max_rate=0.0),
    "max_rate absurd": _control(max_rate=1e13),
    "home_gain negative": _control(home_gain=-1.0),
    "limit_gain a string": _control(limit_gain="x"),
    "task_frame unknown": _control(task_frame="tool0"),
    "task_frame empty": _control(task_frame=""),
    "task_frame a list": _control(task_frame=["tool"]),
    "kp without kd": _control(kp=[1.0, 2.0, 3.0]),
    "kd without kp": _control(kd=[1.0, 2.0, 3.0]),
    "kp short": _control(kp=[1.0, 2.0], kd=[1.0, 1.0, 1.0]),
    "kp entry zero": _control(kp=[1.0, 0.0, 3.0], kd=[1.0, 1.0, 1.0]),
    "kp entry a boolean": _control(kp=[True, 1.0, 3.0], kd=[1.0, 1.0, 1.0]),
    "kd entry nan": _control(kp=[1.0, 1.0, 3.0], kd=[1.0, NAN, 1.0]),
    "torque_limit long": _control(**GAINS, torque_limit=[1.0, 1.0, 1.0, 1.0]),
    "torque_limit negative": _control(**GAINS, torque_limit=[1.0, -1.0, 1.0]),
    "k on reactionless": _control(k=[1.0, 1.0, 1.0]),
    "balancing on computed_torque": _control(kind="computed_torque", **GAINS),
    "damping on decoupled": _control(kind="decoupled", **GAINS, **{**REACTIONLESS_ONLY, "damping": 0.1}),
    "computed_torque without kp": _control(kind="computed_torque", kd=[1.0, 1.0, 1.0], **REACTIONLESS_ONLY),
    "decoupled without kd": _control(kind="decoupled", kp=[1.0, 1.0, 1.0], **REACTIONLESS_ONLY),
    "decoupled k short": _control(kind="decoupled", **GAINS, k=[1.0], **REACTIONLESS_ONLY),
}


def invalid_control(mutate) -> dict:
    data = wheel_arm()
    if mutate(data["control"]) == "__replace__":
        data["control"] = 5
    return data


def test_the_base_of_the_invalid_control_corpus_is_valid(tmp_path):
    assert_same_control(*both_controls(tmp_path, invalid_control(lambda c: None)))


@pytest.mark.parametrize("name", list(INVALID_CONTROL))
def test_both_readers_refuse_the_control(tmp_path, name):
    data = invalid_control(INVALID_CONTROL[name])
    text = toml_text(data).replace(f'"{NAN}"', "nan").replace(f'"{INF}"', "inf")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as py_exc:
        validate_case(read_toml(path), warn=False)
    with pytest.raises(ValueError) as cpp_exc:
        _core.load_case_file(str(path))
    py_field, cpp_message = py_exc.value.field, str(cpp_exc.value)
    assert py_field.startswith("control"), py_exc.value
    # the same field, and here the same whole message (the value shown as Python shows it)
    assert cpp_message.startswith(py_field + ": "), f"Python: {py_exc.value}\nC++:    {cpp_message}"
    assert cpp_message == str(py_exc.value)

# ---- izz alone and the [trajectory] through both readers ---------------------------------------------

PLANAR = {"joints": [{"name": "crank", "axis": [0, -1, 0], "link": {"mass": 0.8, "com": [0.1, 0, 0], "izz": 0.003}},
                     {"name": "coupler", "origin": {"xyz": [0.2, 0, 0]}, "axis": [0, -1, 0],
                      "link": {"mass": 1.5, "com": [0.25, 0, 0], "izz": 0.032}},
                     {"name": "rocker", "parent": "base", "origin": {"xyz": [0.45, 0, 0]}, "axis": [0, 1, 0],
                      "link": {"mass": 1.1, "com": [0.2, 0, 0], "izz": 0.015}}],
          "bodies": [{"name": "cw", "link": "crank", "mass": 0.6, "com": [-0.08, 0, 0], "izz": 0.0001}],
          "frames": [{"name": "ct", "link": "coupler", "origin": {"xyz": [0.5, 0, 0]}},
                     {"name": "rt", "link": "rocker", "origin": {"xyz": [0.4, 0, 0]}}],
          "loops": [{"name": "pin", "frame_a": "ct", "frame_b": "rt"}], "actuated": ["crank"]}


def test_planar_izz_case():
    """A four-bar whose links give izz alone (one joint axis reversed: still parallel)."""
    text = toml_text({"case": {"name": "planar", "kind": "mechanism"}, "mechanism": PLANAR})
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "p.toml"
        path.write_text(text)
        py = Mechanism.from_toml(path)
    assert_same_model(py.model, _core.mechanism_from_toml(text), np.random.default_rng(5))
    crank = py.model.description.bodies[0]
    np.testing.assert_array_equal(np.asarray(crank.inertia), np.diag([0.0015, 0.003, 0.0015]))


TRAJECTORIES = [
    {"law": "constant_speed", "start": [0.5], "rpm": 120, "revolutions": 2, "samples": 11, "branch": "crossed"},
    {"law": "constant_speed", "start": [0.5], "speed": [-3.0], "duration": 0.7, "initial_guess": [0.5]},
    {"law": "cubic", "start": [0.5], "end": [1.0], "duration": 2, "initial_guess": [0.5, -0.6, 1.3]},
]


@pytest.mark.parametrize("k", range(len(TRAJECTORIES)))
def test_both_readers_read_the_trajectory(tmp_path, k):
    from mechbal.schema import validate_case

    cfg = {"case": {"name": "planar", "kind": "mechanism"}, "mechanism": PLANAR, "trajectory": TRAJECTORIES[k]}
    path = tmp_path / "t.toml"
    path.write_text(toml_text(cfg))
    tr = validate_case(cfg, warn=False).trajectory
    c = _core.load_case_trajectory(str(path))
    assert c.present and c.constant_speed == (tr.law == "constant_speed")
    assert c.start == tr.start and c.samples == tr.samples and c.branch == (tr.branch or "")
    assert c.initial_guess == (tr.initial_guess or [])
    assert c.duration == pytest.approx(tr.motion_duration(), rel=1e-15)
    if tr.law == "constant_speed":
        assert c.speed == pytest.approx(tr.speeds(1), rel=1e-15) and c.end == []
    else:
        assert c.end == tr.end and c.law.name == tr.law


# ---- misspelled tables: one verdict for both readers (issue 40) ---------------------------------------

MISSPELLED = {"contrl": "control", "trajectry": "trajectory", "Control": "control", "controls": "control",
              "trajectories": "trajectory"}


@pytest.mark.parametrize("wrong", list(MISSPELLED) + ["balanse", "extra key"])
def test_both_readers_refuse_a_misspelled_table(tmp_path, wrong):
    data = wheel_arm()
    if wrong == "balanse":
        data["balanse"] = {"method": "force"}
    elif wrong == "extra key":
        data["extra"] = 1
    else:
        data[wrong] = data.pop(MISSPELLED[wrong])
    path = tmp_path / "bad.toml"
    path.write_text(toml_text(data))
    with pytest.raises(ConfigError) as py_exc:
        validate_case(read_toml(path), warn=False)
    with pytest.raises(ValueError) as cpp_exc:
        _core.load_case_file(str(path))
    # the same first problem, whole (Python goes on: "; also trajectory: is required")
    assert str(cpp_exc.value) == py_exc.value.problems[0][1], f"Python: {py_exc.value}\nC++:    {cpp_exc.value}"
    assert py_exc.value.field == wrong.split()[0] and "unknown" in str(cpp_exc.value)


@pytest.mark.parametrize("extra", [{}, {"objective": "moment_peak", "control_points": 10}])
def test_min_shaking_is_planned_in_python_and_refused_by_the_cpp_reader(tmp_path, extra):
    """law = "min_shaking" is a plan of the Python layer (mechbal.plan): the Python reader takes it,
    the C++ reader refuses it at trajectory.law (not as an unknown key, not run as another law)."""
    from mechbal.schema import validate_case

    tr = {"law": "min_shaking", "start": [0.5], "end": [1.0], "duration": 2, **extra}
    cfg = {"case": {"name": "planar", "kind": "mechanism"}, "mechanism": PLANAR, "trajectory": tr}
    path = tmp_path / "t.toml"
    path.write_text(toml_text(cfg))
    assert validate_case(cfg, warn=False).trajectory.law == "min_shaking"
    with pytest.raises(ValueError, match=r"^trajectory\.law: 'min_shaking' is a motion planned by the "
                                         r"Python layer .* \(got 'min_shaking'\)$"):
        _core.load_case_trajectory(str(path))
    with pytest.raises(ValueError, match=r"^trajectory\.law: "):
        _core.load_case_file(str(PKG / "cases" / "four-bar-min-shaking.toml"))
