"""Issue 24: property tests of the file parsers. Random and mutated URDF documents and TOML case
files never crash the interpreter, never raise anything but a one-line ConfigError (a ValueError),
and never give a non-physical model: every accepted file yields bodies of finite, non-negative
mass with a physical inertia, and finite algorithm results. Bounded (max_examples, no deadline)
to keep `make test` short; the C++ reader's deterministic corpus under ASan is
tests/cpp/test_parser_fuzz.cpp."""
from __future__ import annotations

import warnings

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import mechbal
from mechbal import _core
from mechbal.config import CASES_DIR, ConfigError, parse_toml

SETTINGS = settings(max_examples=120, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(-10, 10).map(lambda x: f"{x:.6g}"),
    st.sampled_from(["nan", "inf", "-inf", "NaN", "abc", "", "1e999", "-1e999", "0x10", "1,5",
                     "+1", " 2 ", "1e-320", "-0", "1 2", "1e308"]),
)
FRAGMENTS = st.sampled_from([
    "<", ">", "/>", "</link>", "</joint>", "<link name=\"l1\"/>", "\"", "'", "<a>" * 80,
    "<joint name=\"jc\" type=\"fixed\"><parent link=\"l2\"/><child link=\"l1\"/></joint>",
    "<joint name=\"js\" type=\"revolute\"><parent link=\"l1\"/><child link=\"l1\"/></joint>",
    "<!--", "-->", "<![CDATA[", "]]>", "&amp;", "&bogus;", "\x00", "\u00e9", " mass=\"1\"",
])


def physical(mech: mechbal.Mechanism) -> None:
    for b in mech.model.bodies:
        assert np.isfinite(b.mass) and b.mass >= 0.0, b.name
        I = np.asarray(b.inertia)
        assert np.all(np.isfinite(I)) and np.all(np.isfinite(np.asarray(b.com)))
        w = np.linalg.eigvalsh(0.5 * (I + I.T))
        scale = max(1.0, np.abs(w).max())
        assert w.min() >= -1e-9 * scale, (b.name, w)
        assert w[0] + w[1] >= w[2] - 1e-9 * scale, (b.name, w)  # triangle inequality
    q = np.full(mech.dof, 0.1)
    assert np.all(np.isfinite(mech.center_of_mass(q)))
    assert np.all(np.isfinite(mech.gravity_torque(q)))


@st.composite
def urdf_documents(draw):
    n = draw(st.integers(1, 5))
    parts = ['<robot name="p">', '<link name="base"/>']
    for i in range(1, n + 1):
        num = [draw(NUMBERS) for _ in range(5)]
        parts.append(f'<link name="l{i}"><inertial><origin xyz="{num[0]} 0 0" rpy="0 0 {num[1]}"/>'
                     f'<mass value="{num[2]}"/><inertia ixx="{num[3]}" ixy="0" ixz="0" iyy="{num[3]}" '
                     f'iyz="0" izz="{num[4]}"/></inertial></link>')
        parent = "base" if i == 1 else f"l{draw(st.integers(1, i - 1))}"
        jt = draw(st.sampled_from(["revolute", "continuous", "prismatic", "fixed", "floating"]))
        lim = [draw(NUMBERS) for _ in range(4)]
        parts.append(f'<joint name="j{i}" type="{jt}"><parent link="{parent}"/><child link="l{i}"/>'
                     f'<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="{lim[0]}" '
                     f'upper="{lim[1]}" effort="{lim[2]}" velocity="{lim[3]}"/></joint>')
    parts.append("</robot>")
    doc = "".join(parts)
    for _ in range(draw(st.integers(0, 3))):  # mutations
        i = draw(st.integers(0, len(doc)))
        if draw(st.booleans()):
            doc = doc[:i] + draw(FRAGMENTS) + doc[i:]
        else:
            doc = doc[:i] + doc[i + draw(st.integers(1, 30)):]
    return doc


@SETTINGS
@given(urdf_documents())
def test_urdf_never_crashes_and_never_gives_a_non_physical_model(doc):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # PlausibilityWarning for a huge mass is allowed here
        try:
            mech = mechbal.Mechanism.from_urdf_string(doc)
        except ConfigError as e:
            assert "\n" not in str(e)
            return
    physical(mech)


@SETTINGS
@given(st.text(max_size=400))
def test_urdf_arbitrary_text(doc):
    try:
        mech = mechbal.Mechanism.from_urdf_string(doc)
    except ConfigError as e:
        assert "\n" not in str(e)
        return
    physical(mech)


TOML_VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(lambda x: "nan" if x != x else ("inf" if x == float("inf") else ("-inf" if x == float("-inf") else repr(x)))),
    st.integers(-10**30, 10**30).map(str),
    st.sampled_from(['"x"', "true", "[]", "[1, 2]", "[[1]]", "{}", '"revolute"', "1e308", "-1e-320",
                     "[" * 50 + "]" * 50, '"' + "a" * 100 + '"']),
)


@st.composite
def case_files(draw):
    text = (CASES_DIR / draw(st.sampled_from(["arm2link.toml", "four-bar.toml", "ur5-dh.toml"]))).read_text()
    lines = text.splitlines()
    for _ in range(draw(st.integers(1, 4))):
        if not lines:
            break
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(st.integers(0, 2))
        if op == 0 and "=" in lines[i]:  # replace a value
            key = lines[i].split("=", 1)[0]
            lines[i] = f"{key}= {draw(TOML_VALUES)}"
        elif op == 1:
            del lines[i]
        else:
            lines.insert(i, lines[draw(st.integers(0, len(lines) - 1))])
    return "\n".join(lines) + "\n"


@SETTINGS
@given(case_files())
def test_mutated_case_files_never_crash_and_never_give_a_non_physical_model(text):
    from mechbal.schema import validate_case

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            case = validate_case(parse_toml(text.encode(), "case.toml"))
        except ConfigError as e:
            assert "\n" not in str(e)
            return
        spec = getattr(case, "spec", None)
        if spec is None:
            return
        try:
            mech = mechbal.Mechanism.from_spec(spec)
        except ConfigError as e:
            assert "\n" not in str(e)
            return
    physical(mech)


@SETTINGS
@given(st.binary(max_size=300))
def test_arbitrary_bytes_as_toml(raw):
    try:
        parse_toml(raw, "x.toml")
    except ConfigError as e:
        assert "\n" not in str(e)


def test_core_urdf_reader_is_the_one_tested():
    assert _core.MAX_URDF_DEPTH == 64
