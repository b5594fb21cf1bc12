"""summary.json follows one documented JSON Schema (issue 25): the shipped schema is the generated
one and a valid JSON Schema 2020-12; every built-in case's run, the balance, verify and sweep
summaries validate against it (and so does every summary.json the rest of the test suite writes:
conftest.py validates them at the end of the session); a planted wrong key, a key with its unit
left in, a missing or wrong schema_version fail."""
from __future__ import annotations

import copy
import json
import warnings
from pathlib import Path

import pytest

jsonschema = pytest.importorskip("jsonschema")

import mechbal  # noqa: E402
from mechbal.summary_schema import schema_text  # noqa: E402

SCHEMA_FILE = Path(mechbal.__file__).resolve().parent / "cases" / "summary.schema.json"


def validator():
    schema = json.loads(SCHEMA_FILE.read_text())
    return jsonschema.Draft202012Validator(schema)


def errors(summary: dict) -> list[str]:
    return [f"{'.'.join(map(str, e.absolute_path)) or '<top>'}: {e.message}"
            for e in validator().iter_errors(summary)]


def assert_valid(path: Path) -> dict:
    data = json.loads(path.read_text())
    problems = errors(data)
    assert not problems, f"{path}:\n  " + "\n  ".join(problems[:20])
    return data


def test_shipped_schema_is_the_generated_one():
    assert json.loads(SCHEMA_FILE.read_text()) == json.loads(schema_text()), (
        "regenerate: .venv/bin/python -m mechbal.summary_schema > python/mechbal/cases/summary.schema.json")


def test_the_schema_is_a_valid_json_schema():
    jsonschema.Draft202012Validator.check_schema(json.loads(SCHEMA_FILE.read_text()))


def _case_names() -> list[str]:
    from mechbal.cases import available

    return sorted(name for name, _, _ in available())


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Every built-in case run once (the summaries that `mechbal run` writes)."""
    from mechbal.cases import run_case

    out = {}
    for name in _case_names():
        d = tmp_path_factory.mktemp(f"run-{name}")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            summary = run_case(name, d / "out")
        out[name] = (d / "out" / "summary.json", summary)
    return out


def test_every_builtin_case_run_follows_the_schema(runs):
    assert len(runs) >= 15
    kinds = set()
    for name, (path, returned) in runs.items():
        data = assert_valid(path)
        assert data["schema_version"] == 2 and data["command"] == "run", name
        assert list(data)[:2] == ["schema_version", "command"], name
        assert json.loads(json.dumps(returned, default=str))["schema_version"] == 2
        kinds.add(data["kind"])
    assert kinds >= {"serial_chain", "mechanism", "arm2dof", "discs", "orthoglide", "paminsa", "rpsp"}


def test_no_unit_is_left_in_a_key(runs):
    """SI units are named in the schema, never in the keys (the paper's own mm and N/mm and the
    percentages say so in theirs, docs/summary.md)."""
    import re

    unit = re.compile(r"_(N|Nm|kg|s|m|rad|rad_s|J|W|kg_m2)$")

    def keys(x, path=""):
        if isinstance(x, dict):
            for k, v in x.items():
                yield f"{path}.{k}", k
                yield from keys(v, f"{path}.{k}")
        elif isinstance(x, list):
            for v in x:
                yield from keys(v, path + "[]")

    bad = {f"{name}: {p}" for name, (path, _) in runs.items()
           for p, k in keys(json.loads(path.read_text())) if unit.search(k) and k not in ("m_N",)}
    assert not bad, sorted(bad)


def test_the_metric_names_are_the_sweeps(runs):
    from mechbal.sweep.metrics import BUILTIN

    data = json.loads(runs["arm2link"][0].read_text())
    for name in ("peak_shaking_force", "peak_shaking_moment", "peak_joint_torque", "rms_joint_torque"):
        assert name in data
    assert {"peak_shaking_force", "peak_shaking_moment", "peak_joint_torque", "rms_joint_torque",
            "peak_gravity_torque"} <= set(BUILTIN)


@pytest.mark.parametrize("case, method", [("arm2link", "static"), ("four-bar", "force"), ("paminsa", None),
                                          ("orthoglide", "springs"), ("rpsp", "force"), ("arm2dof", None)])
def test_balance_summaries_follow_the_schema(tmp_path, case, method):
    from mechbal.balance.run import run_balance

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_balance(case, method, tmp_path)
    data = assert_valid(tmp_path / "summary.json")
    assert data["command"] == "balance"
    text = (tmp_path / "balanced.toml").read_text()
    if method in ("static", "force"):  # the counterweights it adds, in the named inertia form (the
        assert "inertia = { ixx = " in text  # user's own bodies stay as written)


def test_sweep_summary_follows_the_schema(tmp_path):
    pytest.importorskip("pandas")
    from mechbal.sweep.config import run_file

    run_file("arm2link-balanced", "arm2link-balanced-sensitivity", tmp_path, backend="serial", progress=False)
    data = assert_valid(tmp_path / "summary.json")
    assert data["command"] == "sweep" and "peak_gravity_torque" in data["metrics"]


def test_verify_and_cosimulation_summaries_follow_the_schema(tmp_path):
    pytest.importorskip("mujoco")
    from mechbal.verify import run_cosimulation, run_verify

    run_verify("arm2link", tmp_path / "verify", simulate=False)
    assert assert_valid(tmp_path / "verify" / "summary.json")["command"] == "verify"
    run_cosimulation("arm2link", tmp_path / "cosim")
    data = assert_valid(tmp_path / "cosim" / "summary.json")
    assert data["command"] == "run" and data["engine"] == "mujoco"


# ---- what must fail ------------------------------------------------------------------------------

def test_planted_wrong_keys_fail(runs):
    good = json.loads(runs["arm2link"][0].read_text())
    assert not errors(good)
    for mutate, where in [
        (lambda d: d.update(peak_torque_Nm=d["peak_joint_torque"]), "peak_torque_Nm"),       # an old key
        (lambda d: d.update(peak_shaking_force_N=d.pop("peak_shaking_force")), "peak_shaking_force_N"),
        (lambda d: d.update(shaking_force_peak=1.0), "shaking_force_peak"),                   # turned around
        (lambda d: d.pop("schema_version"), "schema_version"),
        (lambda d: d.update(schema_version=0), "schema_version"),
        (lambda d: d.update(command="plot"), "command"),
        (lambda d: d.update(duration="1 s"), "duration"),
        (lambda d: d["peak_shaking_force"].update(nominal=[1.0, "x", 0.0]), "peak_shaking_force"),
    ]:
        d = copy.deepcopy(good)
        mutate(d)
        problems = errors(d)
        assert problems and any(where in p for p in problems), (where, problems)


def test_planted_wrong_nested_keys_fail(runs, tmp_path):
    controlled = json.loads(runs["reaction-wheel-arm"][0].read_text())
    assert not errors(controlled)
    controlled["control"]["rate"] = 1000.0
    assert any("rate" in p for p in errors(controlled))
    paper = json.loads(runs["paminsa"][0].read_text())
    paper["peak_wrist_rate_rad_s"] = paper["peak_wrist_rate"]
    assert any("peak_wrist_rate_rad_s" in p for p in errors(paper))
    # a paper's key on another kind's summary is refused too
    general = json.loads(runs["arm2link"][0].read_text())
    general["peak_wrist_rate"] = [1.0]
    assert errors(general)
