"""The strict case-file schema: every shipped case validates, every misspelled key or unknown table
of every shipped case is refused with a hint before any runner starts, random input never escapes
as anything but ConfigError, and the published JSON Schema is the generated one."""
import copy
import json
import math
import warnings

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mechbal.config import CASES_DIR, ConfigError, builtin_cases, read_case
from mechbal.errors import ConfigWarning
from mechbal.schema import KINDS, SCHEMA_FILE, json_schema, schema_text, validate_case

CASE_FILES = sorted(builtin_cases().values())
CASES = {p.stem: read_case(p) for p in CASE_FILES}


def test_every_shipped_case_validates_without_warnings():
    assert len(CASES) >= 7
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name, config in CASES.items():
            model = validate_case(copy.deepcopy(config))
            assert model.case.name == name


def test_every_shipped_case_points_editors_at_the_schema():
    for p in CASE_FILES:
        first = p.read_text().splitlines()[0]
        assert first.startswith("#:schema "), p
        assert (p.parent / first.removeprefix("#:schema ")).resolve() == SCHEMA_FILE.resolve(), p


def test_schema_kinds_are_the_runners_kinds():
    from mechbal.cases import _load_runners, _RUNNERS

    _load_runners()
    # a URDF robot's run is built in code from the URDF file (mechbal.cases.urdf_robot): no TOML kind
    assert set(KINDS) == set(_RUNNERS) - {"urdf"}


def test_shipped_json_schema_is_the_generated_one():
    shipped = json.loads(SCHEMA_FILE.read_text())
    assert shipped == json.loads(schema_text()), (
        "regenerate: .venv/bin/python -m mechbal.schema > python/mechbal/cases/mechbal.schema.json")


def test_json_schema_per_kind():
    for kind in KINDS:
        s = json_schema(kind)
        assert s["$schema"].startswith("http://json-schema.org/")
        assert "$defs" in s or "properties" in s
    joint = json_schema("mechanism")["$defs"]["Joint"]
    assert joint["additionalProperties"] is False
    assert set(joint["properties"]) == {"name", "type", "parent", "origin", "mdh", "dh", "axis",
                                        "limits", "mimic", "link"}
    assert "null" not in json.dumps(json_schema())  # TOML has no null: optional keys are absent
    with pytest.raises(ValueError, match="unknown kind"):
        json_schema("no_such_kind")


def test_json_schema_accepts_the_shipped_cases_and_refuses_unknown_keys():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json_schema()
    for name, config in CASES.items():
        jsonschema.validate(config, schema)
    bad = copy.deepcopy(CASES["arm2link"])
    bad["mechanism"]["gravty"] = [0, 0, -9.81]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, schema)


# ---- misspellings -------------------------------------------------------------------------------

def _key_paths(node, path=()):
    """Every (path to the table, key) in a TOML document, through arrays of tables."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield path, k
            yield from _key_paths(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _key_paths(v, path + (i,))


def _one_edit(key):
    """Deletions, adjacent transpositions and insertions (a doubled letter, an extra 'x')."""
    out = set()
    for i in range(len(key)):
        out.add(key[:i] + key[i + 1:])
        out.add(key[:i] + key[i] + key[i:])
        if i + 1 < len(key):
            out.add(key[:i] + key[i + 1] + key[i] + key[i + 2:])
    out.add(key + "x")
    out.discard(key)
    return sorted(out)


def _dotted(path, key):
    s = ""
    for x in path + (key,):
        s += f"[{x}]" if isinstance(x, int) else (f".{x}" if s else x)
    return s


def _get(node, path):
    for x in path:
        node = node[x]
    return node


def _valid_keys(config, path):
    """Keys the schema accepts in the table at ``path`` (from the validated model)."""
    from mechbal.schema import _allowed_keys, _model_for

    return set(_allowed_keys(_model_for(config), path)) if path else set(_model_for(config).model_fields)


def _distinct_key_paths(config, first: int = 3):
    """_key_paths, but beyond the first entries of an array of tables only the keys not seen
    before at the same place (a generated 38-body mechanism repeats the same keys hundreds of times;
    mutating every repeat would only slow the suite down)."""
    seen = set()
    for path, key in _key_paths(config):
        generic = (tuple("*" if isinstance(x, int) else x for x in path), key)
        if all(x < first for x in path if isinstance(x, int)) or generic not in seen:
            seen.add(generic)
            yield path, key


def misspelled_cases():
    """(case name, mutated config, dotted path of the mutated key, original key)."""
    for name, config in CASES.items():
        for path, key in _distinct_key_paths(config):
            allowed = _valid_keys(config, path) if path[:1] != ("case",) else \
                {"name", "kind", "title", "mechanism"}
            for wrong in _one_edit(key):
                if wrong in allowed:
                    continue  # another valid key: not a misspelling
                bad = copy.deepcopy(config)
                table = _get(bad, path)
                table[wrong] = table.pop(key)
                yield name, bad, _dotted(path, wrong), key
        for table in ("counterweights", "controler", "mechansim", "trajectroy", "extra"):
            if table not in config and table not in _valid_keys(config, ()):
                bad = copy.deepcopy(config)
                bad[table] = {"m_cw1": 1.0}
                yield name, bad, table, None


MISSPELLED = list(misspelled_cases())


def test_every_misspelled_key_of_every_shipped_case_is_refused_with_a_hint():
    assert len(MISSPELLED) > 1500  # every key of every shipped file, mutated
    hinted = 0
    for name, bad, field, original in MISSPELLED:
        with pytest.raises(ConfigError) as exc:
            validate_case(bad)
        msg = str(exc.value)
        assert "\n" not in msg, msg
        assert exc.value.field == field, (name, msg)
        assert msg.startswith(f"{field}: unknown "), (name, msg)
        assert "did you mean" in msg or "allowed:" in msg, (name, msg)
        if original is not None and len(original) >= 3:
            assert f"did you mean {original!r}?" in msg, (name, msg)
            hinted += 1
    assert hinted > 1000


def test_the_issue_examples_are_refused():
    base = CASES["arm2link"]
    cases = [
        (("mechanism", "joints", 1, "link"), "com", "cmo", "mechanism.joints[1].link.cmo: unknown key (did you mean 'com'?)"),
        (("mechanism", "joints", 1, "link"), "mass", "mas", "mechanism.joints[1].link.mas: unknown key (did you mean 'mass'?)"),
        (("mechanism",), "gravity", "gravty", "mechanism.gravty: unknown key (did you mean 'gravity'?)"),
        (("trajectory",), "samples", "sample", "trajectory.sample: unknown key (did you mean 'samples'?)"),
    ]
    for path, key, wrong, message in cases:
        bad = copy.deepcopy(base)
        t = _get(bad, path)
        t[wrong] = t.pop(key)
        with pytest.raises(ConfigError) as exc:
            validate_case(bad)
        assert str(exc.value).startswith(message), str(exc.value)
    bad = copy.deepcopy(base)
    bad["mechanism"]["joints"][0]["dhh"] = {"a": 0.5, "alpha": 0.0}
    with pytest.raises(ConfigError, match=r"^mechanism\.joints\[0\]\.dhh: unknown table \(did you mean 'dh'\?\)"):
        validate_case(bad)
    bad = copy.deepcopy(base)
    bad["counterweights"] = {"m_cw1": 1.0}
    with pytest.raises(ConfigError, match=r"^counterweights: unknown table \(allowed: case, mechanism, trajectory, balance, control\)"):
        validate_case(bad)


def test_no_runner_is_reached_by_a_misspelled_file(monkeypatch, tmp_path):
    """run_case validates the whole file before any runner (or the output folder) is touched."""
    import mechbal.cases as cases
    from mechbal.case.load import LoadedCase

    cases._load_runners()
    called = []
    for kind in list(cases._RUNNERS):
        monkeypatch.setitem(cases._RUNNERS, kind, lambda config, out: called.append(config))
    for name, bad, field, _ in MISSPELLED[::7]:
        monkeypatch.setattr(cases, "load_case", lambda _name, bad=bad, **_: LoadedCase(copy.deepcopy(bad)))
        with pytest.raises(ConfigError, match=field.replace(".", r"\.").replace("[", r"\[").replace("]", r"\]")):
            cases.run_case(name, tmp_path / "out")
    assert called == []
    assert not (tmp_path / "out").exists()
    # and the text of real files, as a user types them
    text = (CASES_DIR / "arm2link.toml").read_text()
    monkeypatch.undo()
    cases._load_runners()
    for old, new in (("com = [0.25", "cmo = [0.25"), ("gravity =", "gravty ="), ("samples =", "sample ="),
                     ("link = { mass = 4.0", "link = { mas = 4.0"), ("[trajectory]", "[counterweights]\nm = 1.0\n\n[trajectory]")):
        assert old in text
        bad = tmp_path / "bad.toml"
        bad.write_text(text.replace(old, new, 1))
        with pytest.raises(ConfigError, match="unknown"):
            cases.run_case(bad, tmp_path / "out2")
        assert not (tmp_path / "out2").exists()


def test_unknown_kind_and_mechanism_are_hinted():
    bad = copy.deepcopy(CASES["arm2link"])
    bad["case"]["kind"] = "serial_chian"
    with pytest.raises(ConfigError, match=r"^case\.kind: unknown kind \(did you mean 'serial_chain'\?\)"):
        validate_case(bad)
    del bad["case"]["kind"]
    with pytest.raises(ConfigError, match=r"^case\.kind: is required"):
        validate_case(bad)
    bad = copy.deepcopy(CASES["discs-3r"])
    bad["case"]["mechanism"] = "planar3"
    with pytest.raises(ConfigError, match=r"^case\.mechanism: .*did you mean 'planar3r'\?"):
        validate_case(bad)


# ---- values, bounds, warnings -------------------------------------------------------------------

@pytest.mark.parametrize("case, path, value, message", [
    ("arm2link", ("trajectory", "samples"), 10 ** 9, "trajectory.samples: must be <= 1000000 (got 1000000000)"),
    ("arm2link", ("trajectory", "samples"), 501.0, "trajectory.samples: must be an integer (got 501.0)"),
    ("arm2link", ("trajectory", "duration"), "1.0", "trajectory.duration: must be a number (got '1.0')"),
    ("arm2link", ("mechanism", "gravity"), [0, 0, True], "mechanism.gravity[2]: must be a number (got True)"),
    ("arm2link", ("mechanism", "joints", 1, "link", "mass"), -2.0, "mechanism.joints[1].link.mass: must be >= 0 (got -2.0)"),
    ("arm2link", ("mechanism", "joints", 1, "axis"), [1e300, 0, 0], "mechanism.joints[1].axis[0]: must be <= 1e+12 (got 1e+300)"),
    ("arm2link", ("mechanism", "joints", 1, "type"), "revolut", "mechanism.joints[1].type: must be one of revolute, prismatic, fixed, spherical (did you mean 'revolute'?) (got 'revolut')"),
    ("arm2dof", ("controller", "rate_hz"), 5e-324, "controller.rate_hz: must be >= 1 (got 5e-324)"),
    ("arm2link", ("trajectory", "duration"), 5e-324, "trajectory.duration: must be >= 0.001 (got 5e-324)"),
    ("arm2dof", ("controller", "rate_hz"), 1e6, "controller.duration: duration x rate_hz must be <= 1000000 ticks"),
    ("arm2dof", ("counterweights", "m_cw1"), 1e300, "counterweights.m_cw1: must be <= 1e+12 (got 1e+300)"),
    ("arm2dof", ("trajectory", "law"), "cubic", "trajectory.law: unknown key"),
    ("paminsa", ("trajectory", "samples"), 10, "trajectory.samples: unknown key (allowed: law, start, end, duration)"),
    ("paminsa", ("trajectory", "duration"), 1e4, "trajectory.duration: duration x wrist.rate_hz must be <= 1000000 ticks"),
    ("paminsa", ("masses", "links"), [1.0] * 7, "masses.links: must have 8 values"),
    ("discs-3r", ("sampling", "configurations"), 10 ** 7, "sampling.configurations: must be <= 100000"),
    ("discs-3r", ("trajectory", "start"), [0.0, 0.0], "trajectory.start: must have 3 values (got [0.0, 0.0])"),
    ("five-bar", ("parameters", "mP1_share"), 5.0, "parameters.mP1_share: must be <= mP = 0.5 (got 5.0)"),
])
def test_bad_values_name_the_field_and_the_value(case, path, value, message):
    bad = copy.deepcopy(CASES[case])
    _get(bad, path[:-1])[path[-1]] = value
    with pytest.raises(ConfigError) as exc:
        validate_case(bad)
    assert str(exc.value).startswith(message), str(exc.value)


@pytest.mark.parametrize("path, value, field", [
    (("mechanism", "joints", 1, "link", "mass"), 5000.0, "mechanism.joints[1].link.mass"),
    (("mechanism", "joints", 1, "origin", "rpy"), [0.0, 90.0, 0.0], "mechanism.joints[1].origin.rpy[1]"),
    (("mechanism", "joints", 0, "origin", "xyz"), [500.0, 0.0, 0.0], "mechanism.joints[0].origin.xyz[0]"),
])
def test_likely_unit_mistakes_are_warned_about(path, value, field):
    bad = copy.deepcopy(CASES["arm2link"])
    _get(bad, path[:-1])[path[-1]] = value
    with pytest.warns(ConfigWarning, match=field.replace(".", r"\.").replace("[", r"\[").replace("]", r"\]")):
        validate_case(bad)


def test_dh_angles_in_degrees_and_heavy_arm_cases_are_warned_about():
    bad = copy.deepcopy(CASES["arm2link"])
    bad["mechanism"]["joints"][1] = {"name": "elbow", "dh": {"a": 0.5, "alpha": 90.0},
                                     "link": {"mass": 2.0, "inertia": [0.01, 0.01, 0.01]}}
    bad["mechanism"]["joints"][0].pop("axis")
    bad["mechanism"]["joints"][0].pop("origin")
    with pytest.warns(ConfigWarning, match=r"joints\[1\]\.dh\.alpha.*degrees"):
        validate_case(bad)
    bad = copy.deepcopy(CASES["arm2dof"])
    bad["arm"]["m1"] = 2500.0
    with pytest.warns(ConfigWarning, match=r"arm\.m1: 2500 kg"):
        validate_case(bad)
    bad = copy.deepcopy(CASES["paminsa"])
    bad["geometry"]["length_AE"] = 420.0
    with pytest.warns(ConfigWarning, match=r"geometry\.length_AE: 420 m"):
        validate_case(bad)


# ---- property tests ------------------------------------------------------------------------------

KEYS = sorted({k for c in CASES.values() for _, k in _key_paths(c)} | {"parent", "mimic", "bodies", "frames"})
scalars = (st.none() | st.booleans() | st.integers() | st.floats(allow_nan=True, allow_infinity=True)
           | st.text(max_size=12) | st.sampled_from(["revolute", "spherical", "fixed", "base", "shoulder",
                                                     "elbow", "centroid", "quintic", "planar3r"]))
values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=5)
                      | st.dictionaries(st.sampled_from(KEYS) | st.text(max_size=6), inner, max_size=5),
                      max_leaves=30)


def _check(config):
    try:
        validate_case(config, warn=False)
    except ConfigError as exc:
        assert str(exc) and "\n" not in str(exc)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(values)
def test_random_documents_only_raise_config_error(doc):
    _check(doc)


def _leaf_paths(node, path=()):
    yield path
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _leaf_paths(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _leaf_paths(v, path + (i,))


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(sorted(CASES)), st.data())
def test_shipped_cases_with_one_random_value_only_raise_config_error(name, data):
    config = copy.deepcopy(CASES[name])
    paths = [p for p in _leaf_paths(config) if p]
    path = data.draw(st.sampled_from(paths))
    _get(config, path[:-1])[path[-1]] = data.draw(values)
    _check(config)


def test_an_unknown_inertia_key_with_a_newline_stays_one_line():
    # found by the test above: a named inertia table's unknown key went into the field raw
    config = copy.deepcopy(CASES["arm2link-balanced"])
    config["mechanism"]["joints"][0]["link"]["inertia"] = {"\n": None}
    with pytest.raises(ConfigError) as exc:
        validate_case(config, warn=False)
    assert "\n" not in str(exc.value)
    assert str(exc.value).startswith("mechanism.joints[0].link.inertia.'\\n': unknown key")


names = st.sampled_from(["a", "b", "c", "s", "base", "s_z", "s_x", "d"])
joint_names = st.sampled_from(["a", "b", "c", "s"])
origin = st.fixed_dictionaries({}, optional={"xyz": st.lists(st.floats(-2, 2), min_size=3, max_size=3),
                                             "rpy": st.lists(st.floats(-7, 7), min_size=3, max_size=3)})
dh = st.fixed_dictionaries({"a": st.floats(-1, 1), "alpha": st.floats(-3, 3)},
                           optional={"d": st.floats(-1, 1), "theta": st.floats(-3, 3)})
inertial = st.fixed_dictionaries({"mass": st.floats(0, 5), "inertia": st.just([0.01, 0.02, 0.025])},
                                 optional={"com": st.lists(st.floats(-1, 1), min_size=3, max_size=3)})
unit3 = st.lists(st.floats(-1, 1), min_size=3, max_size=3)
limits = st.fixed_dictionaries({}, optional={"lower": st.floats(-3, 0), "upper": st.floats(0, 3),
                                             "velocity": st.floats(0.1, 5), "effort": st.floats(0.1, 5)})
mimic = st.fixed_dictionaries({"joint": joint_names | names}, optional={"ratio": st.floats(-3, 3), "offset": st.floats(-1, 1)})


@st.composite
def joint(draw):
    """Mostly well-formed joints (so that cross references are exercised), sometimes not."""
    j = draw(st.fixed_dictionaries({"name": joint_names}, optional={"link": inertial,
        "type": st.sampled_from(["revolute", "revolute", "prismatic", "fixed", "spherical"])}))
    placement = draw(st.sampled_from(["none", "origin", "origin", "dh", "mdh", "none", "origin", "any"]))
    if placement == "origin":
        j["origin"] = draw(origin)
    elif placement in ("dh", "mdh"):
        j[placement] = draw(dh)
    elif placement == "any":
        j.update(draw(st.fixed_dictionaries({}, optional={"origin": origin, "dh": dh, "mdh": dh})))
    if draw(st.booleans()):  # default: the previous joint
        j["parent"] = draw(names)
    movable = j.get("type", "revolute") in ("revolute", "prismatic")
    if draw(st.booleans()) and (movable and "dh" not in j and "mdh" not in j or draw(st.integers(0, 5)) == 0):
        j["axis"] = draw(unit3)
    if draw(st.booleans()) and (movable or draw(st.integers(0, 5)) == 0):
        j["limits"] = draw(limits)
    if draw(st.integers(0, 3)) == 0 and (movable or draw(st.integers(0, 5)) == 0):
        j["mimic"] = draw(mimic)
    return j


joint = joint()
body = st.fixed_dictionaries({"name": st.text(min_size=1, max_size=3), "link": joint_names | names, "mass": st.floats(0, 5),
                              "inertia": st.just([0.01, 0.01, 0.01])},
                             optional={"kind": st.sampled_from(["counterweight", "motor", "disc"]),
                                       "com": st.lists(st.floats(-1, 1), min_size=3, max_size=3),
                                       "rpy": st.lists(st.floats(-3, 3), min_size=3, max_size=3)})
frame = st.fixed_dictionaries({"name": st.text(min_size=1, max_size=3), "link": joint_names | names}, optional={"origin": origin})


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(joint, min_size=1, max_size=5, unique_by=lambda j: j.get("name")),
       st.lists(body, max_size=3), st.lists(frame, max_size=2))
def test_random_mechanisms_build_a_spec_or_raise_config_error(joints, bodies, frames):
    import numpy as np

    from mechbal.spec import mechanism_spec

    try:
        spec = mechanism_spec({"joints": joints, "bodies": bodies, "frames": frames})
    except ConfigError as exc:
        assert "\n" not in str(exc)
        return
    names_ = [j.name for j in spec.joints]
    assert len(set(names_)) == len(names_)
    seen = {"base"}
    for j in spec.joints:  # parents first
        assert j.parent in seen
        seen.add(j.name)
        assert j.type in ("revolute", "prismatic", "fixed")
        assert np.isclose(np.linalg.norm(j.axis), 1.0)
        R = j.placement[:3, :3]
        assert np.allclose(R.T @ R, np.eye(3), atol=1e-12)
    for b in spec.bodies:
        assert b.link in seen and np.all(np.isfinite(b.inertia)) and np.allclose(b.inertia, b.inertia.T)
    assert math.isfinite(sum(b.mass for b in spec.bodies))
