"""Bad configuration: one test per kind of bad input, each asserting the message names the field
and the value; nothing is half-built."""
import copy
import math
from pathlib import Path

import numpy as np
import pytest

from mechbal.config import ConfigError, read_case, read_toml, trajectory_from_config
from mechbal.mechanism import Mechanism
from mechbal.spec import mechanism_spec


def chain_from_config(table):
    """The general model of a ``[mechanism]`` table (errors name the field: ConfigError)."""
    return Mechanism.from_spec(mechanism_spec(table, "mechanism"))

BASE = read_toml(Path(__file__).resolve().parents[2] / "python/mechbal/cases/arm2link.toml")


def mech(**joint1_link):
    cfg = copy.deepcopy(BASE["mechanism"])
    cfg["joints"][1]["link"].update(joint1_link)
    return cfg


def expect_error(fn, field, value_text=None):
    with pytest.raises(ConfigError) as exc:
        fn()
    msg = str(exc.value)
    assert field in msg, msg
    if value_text is not None:
        assert value_text in msg, msg
    return exc.value


def test_valid_case_builds():
    model = chain_from_config(BASE["mechanism"])
    assert model.dof == 2
    traj, t = trajectory_from_config(BASE["trajectory"], 2)
    assert len(t) == BASE["trajectory"]["samples"]


def test_negative_mass():
    expect_error(lambda: chain_from_config(mech(mass=-2.0)), "mechanism.joints[1].link.mass", "-2.0")


def test_nan_mass():
    e = expect_error(lambda: chain_from_config(mech(mass=math.nan)), "mechanism.joints[1].link.mass", "nan")
    assert "finite" in str(e)


def test_wrong_type():
    expect_error(lambda: chain_from_config(mech(mass="heavy")), "mechanism.joints[1].link.mass", "'heavy'")


def test_bool_is_not_a_number():
    expect_error(lambda: chain_from_config(mech(mass=True)), "mechanism.joints[1].link.mass", "True")


def test_missing_field():
    cfg = copy.deepcopy(BASE["mechanism"])
    del cfg["joints"][0]["link"]["mass"]
    e = expect_error(lambda: chain_from_config(cfg), "mechanism.joints[0].link.mass")
    assert "required" in str(e)


def test_inertia_not_symmetric():
    expect_error(lambda: chain_from_config(mech(inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])),
                 "mechanism.joints[1].link.inertia", "0.5")


def test_inertia_not_positive_semidefinite():
    e = expect_error(lambda: chain_from_config(mech(inertia=[0.1, -0.1, 0.1])),
                     "mechanism.joints[1].link.inertia", "-0.1")
    assert "positive semi-definite" in str(e)


def test_inertia_violates_triangle_inequality():
    e = expect_error(lambda: chain_from_config(mech(inertia=[0.01, 0.01, 0.5])),
                     "mechanism.joints[1].link.inertia")
    assert "triangle" in str(e)


def test_inertia_wrong_shape():
    expect_error(lambda: chain_from_config(mech(inertia=[1.0, 2.0])), "mechanism.joints[1].link.inertia")


def test_com_wrong_length():
    expect_error(lambda: chain_from_config(mech(com=[0.1, 0.0])), "mechanism.joints[1].link.com", "[0.1, 0.0]")


def test_unknown_joint_type():
    cfg = copy.deepcopy(BASE["mechanism"])
    cfg["joints"][0]["type"] = "helical"
    expect_error(lambda: chain_from_config(cfg), "mechanism.joints[0].type", "'helical'")
    cfg["joints"][0]["type"] = "revolut"
    e = expect_error(lambda: chain_from_config(cfg), "mechanism.joints[0].type", "'revolut'")
    assert "did you mean 'revolute'?" in str(e)


def test_zero_axis():
    cfg = copy.deepcopy(BASE["mechanism"])
    cfg["joints"][1]["axis"] = [0.0, 0.0, 0.0]
    expect_error(lambda: chain_from_config(cfg), "mechanism.joints[1].axis")


def test_empty_joints():
    expect_error(lambda: chain_from_config({"joints": []}), "mechanism.joints", "[]")


def test_two_origin_kinds():
    cfg = copy.deepcopy(BASE["mechanism"])
    cfg["joints"][0]["mdh"] = {"a": 0.0, "alpha": 0.0}
    expect_error(lambda: chain_from_config(cfg), "mechanism.joints[0]")


def test_trajectory_bad_duration_and_size():
    bad = dict(BASE["trajectory"], duration=0.0)
    expect_error(lambda: trajectory_from_config(bad, 2), "trajectory.duration", "0.0")
    bad = dict(BASE["trajectory"], start=[0.0])
    expect_error(lambda: trajectory_from_config(bad, 2), "trajectory.start", "[0.0]")
    bad = dict(BASE["trajectory"], law="sine")
    expect_error(lambda: trajectory_from_config(bad, 2), "trajectory.law", "'sine'")
    bad = dict(BASE["trajectory"], samples=2)
    expect_error(lambda: trajectory_from_config(bad, 2), "trajectory.samples", "2")


def test_unknown_case_and_bad_toml(tmp_path):
    expect_error(lambda: read_case("no_such_case"), "case", "no_such_case")
    p = tmp_path / "broken.toml"
    p.write_text("[case\nname = ")
    expect_error(lambda: read_case(p), str(p))
    p.write_text("[case]\nname = 'x'\n")
    expect_error(lambda: read_case(p), "case.kind")


def test_dh_and_mdh_give_the_same_chain_as_origins():
    """A planar 2R arm written three ways gives the same link poses."""
    import mechbal

    link = {"mass": 1.0, "com": [0.0, 0.0, 0.0], "inertia": [0.01, 0.01, 0.01]}
    by_origin = {"joints": [
        {"name": "a", "axis": [0, 0, 1], "link": dict(link)},
        {"name": "b", "axis": [0, 0, 1], "origin": {"xyz": [0.5, 0, 0]}, "link": dict(link)}]}
    by_mdh = {"joints": [
        {"name": "a", "mdh": {"a": 0.0, "alpha": 0.0}, "link": dict(link)},
        {"name": "b", "mdh": {"a": 0.5, "alpha": 0.0}, "link": dict(link)}]}
    # standard DH: link 1 frame at the elbow; its centre of mass at -0.5 along its x
    by_dh = {"joints": [
        {"name": "a", "dh": {"a": 0.5, "alpha": 0.0}, "link": dict(link, com=[-0.5, 0, 0])},
        {"name": "b", "dh": {"a": 0.0, "alpha": 0.0}, "link": dict(link)}]}
    q = np.array([[0.3, -0.7]])
    z = np.zeros_like(q)
    coms = [chain_from_config(c).body_motion(q, z, z).com for c in (by_origin, by_mdh, by_dh)]
    assert np.allclose(coms[0], coms[1], atol=1e-12)
    assert np.allclose(coms[0], coms[2], atol=1e-12)
