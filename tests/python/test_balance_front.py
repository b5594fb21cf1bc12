"""The trade-off front (issue 41): monotone, from the unbalanced mechanism to the lightest design of
the best residual, each point's file reproducing its residual; the objectives and the residual
target of the convex design; the files of ``mechbal balance --front``."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal.balance import CounterweightSlot, force, fronts, optimal, static
from mechbal.mechanism import Mechanism
from mechbal.spec import mechanism_spec

pytest.importorskip("clarabel")


def arm(seed: int = 3, n: int = 4) -> Mechanism:
    rng = np.random.default_rng(seed)
    joints = [{"name": f"j{i + 1}", "origin": {"xyz": rng.uniform(-0.3, 0.3, 3).tolist(),
                                                "rpy": rng.uniform(-1.5, 1.5, 3).tolist()},
               "axis": rng.normal(size=3).tolist(),
               "link": {"mass": float(rng.uniform(0.5, 3.0)), "com": rng.uniform(-0.2, 0.2, 3).tolist(),
                        "inertia": [0.02, 0.03, 0.04]}} for i in range(n)]
    return Mechanism.from_spec(mechanism_spec({"gravity": [0.0, 0.0, -9.81], "joints": joints}))


SLOTS = [CounterweightSlot("cw1", "j1", mass_max=20.0, max_radius=0.15),
         CounterweightSlot("cw2", "j2", mass_max=8.0, max_radius=0.2),
         CounterweightSlot("cw3", "j3", mass_max=3.0, max_radius=0.1)]


@pytest.fixture(scope="module")
def front_and_q():
    mech = arm()
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (200, mech.dof))
    return mech, q, fronts.front(mech, SLOTS, 8, samples=q)


def test_front_is_monotone_from_unbalanced_to_lightest(front_and_q):
    mech, q, fr = front_and_q
    pts = fr.points
    assert len(pts) == 8
    m = [p.added_mass for p in pts]
    r = [p.residual for p in pts]
    assert all(b >= a - 1e-9 for a, b in zip(m, m[1:]))
    assert all(b <= a * (1 + 1e-9) for a, b in zip(r, r[1:])), r
    assert r[-1] < 0.8 * r[0]                     # the slots do buy something
    # the zero-mass end is the unbalanced mechanism
    assert m[0] == 0.0
    G0 = mech.gravity_torque(q)
    assert pts[0].residual == pytest.approx(float(np.sqrt(np.mean(G0 ** 2))), rel=1e-12)
    assert np.allclose(pts[0].result.balanced.gravity_torque(q), G0, rtol=0, atol=1e-12)
    # the last point is the method's lightest design of the best residual
    best = static.balance(mech, SLOTS, q)
    assert r[-1] == pytest.approx(best.residual, rel=1e-9)
    assert m[-1] == pytest.approx(best.metrics["added_mass"], rel=1e-9)
    # every point spends its budget (the front is the epsilon-constraint: mass = budget short of the end)
    for p in pts[:-1]:
        assert p.added_mass <= p.budget * (1 + 1e-8) + 1e-9
    assert 0 < fr.knee < len(pts) - 1


def test_each_point_reloads_to_its_residual(front_and_q, tmp_path):
    mech, q, fr = front_and_q
    names = fronts.write(fr, tmp_path)
    assert names[:3] == ["front.csv", "front.json", "front.png"]
    rows = list(csv.DictReader(open(tmp_path / "front.csv")))
    assert list(rows[0]) == list(fronts.CSV_COLUMNS)
    for row, p in zip(rows, fr.points):
        reloaded = Mechanism.from_toml(tmp_path / row["design"])
        res = float(np.sqrt(np.mean(reloaded.gravity_torque(q) ** 2)))
        assert abs(res - float(row["residual"])) <= 1e-9 * max(p.residual, 1e-12), (res, row["residual"])
        assert float(row["added_mass_kg"]) == p.added_mass
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((Path(mechbal.__file__).resolve().parent / "cases" / "front.schema.json").read_text())
    jsonschema.validate(json.loads((tmp_path / "front.json").read_text()), schema)
    assert (tmp_path / "front.png").stat().st_size > 1000


def test_front_schema_file_is_current():
    shipped = json.loads((Path(mechbal.__file__).resolve().parent / "cases" / "front.schema.json").read_text())
    assert shipped == fronts.json_schema(), ("stale: regenerate python/mechbal/cases/front.schema.json from "
                                             "mechbal.balance.fronts.json_schema()")


def test_objectives_and_residual_target():
    mech = arm()
    q = np.random.default_rng(1).uniform(-np.pi, np.pi, (150, mech.dof))
    lightest = static.balance(mech, SLOTS, q)
    least = lightest.metrics["optimality"]["least_residual"]
    target = least + 0.5 * (lightest.residual_before - least)
    by = {}
    for kind in optimal.OBJECTIVES:
        r = static.balance(mech, SLOTS, q, objective=kind, residual_target=target)
        assert r.residual <= target * (1 + 1e-6)
        assert r.exact                               # the asked-for target is met
        assert r.metrics["optimality"]["objective"] == kind
        by[kind] = r
    # each objective is the least of its own measure among the three designs
    W = optimal.inertia_weights(mech, static.common.normalise_slots(mech, SLOTS), q)

    def inertia(r):
        return sum(float(np.r_[d.mass, d.mass * d.position] @ Wk @ np.r_[d.mass, d.mass * d.position]) / d.mass
                   for d, Wk in zip(r.design.values(), W) if d.mass > 1e-12)

    def peak(r):
        return float(np.max(np.abs(r.balanced.gravity_torque(q))))

    for kind in optimal.OBJECTIVES:
        assert by["mass"].metrics["added_mass"] <= by[kind].metrics["added_mass"] * (1 + 1e-6) + 1e-9
        assert inertia(by["inertia"]) <= inertia(by[kind]) * (1 + 1e-6) + 1e-9
        assert peak(by["torque"]) <= peak(by[kind]) * (1 + 1e-6) + 1e-9
    # the inertia weights are the mass matrix's: a point mass's added trace, measured directly
    d = by["inertia"].design["cw2"]
    body = mechbal._core.Body("x", "j2", d.mass, np.asarray(d.position), np.zeros((3, 3)), "counterweight")
    added = np.mean(np.trace(mech.with_bodies([body]).mass_matrix(q) - mech.mass_matrix(q), axis1=1, axis2=2))
    w = np.r_[d.mass, d.mass * d.position]
    assert float(w @ W[1] @ w) / d.mass == pytest.approx(float(added), rel=1e-9)
    # less mass buys a worse residual, and a target below the least residual is refused
    assert by["mass"].metrics["added_mass"] < lightest.metrics["added_mass"]
    with pytest.raises(ValueError, match="residual_target"):
        static.balance(mech, SLOTS, q, residual_target=0.5 * least)


def test_force_front_and_budgeted_partial_force_balance():
    """The force method's front, and its API for a partial force balance under a mass budget
    (what motion planning combines with)."""
    mech = arm(5, 3)
    slots = [CounterweightSlot("cw1", "j1", mass_max=30.0, max_radius=0.3),
             CounterweightSlot("cw2", "j2", mass_max=10.0, max_radius=0.3)]
    fr = fronts.front(mech, slots, 5, method="force", samples=60)
    r = [p.residual for p in fr.points]
    assert all(b <= a * (1 + 1e-9) for a, b in zip(r, r[1:]))
    prob = force.problem(mech, slots, 60)
    half = 0.5 * fr.points[-1].added_mass
    res = prob.result(prob.solve(mass_budget=half))
    assert res.metrics["added_mass"] <= half * (1 + 1e-8)
    assert fr.points[-1].residual <= res.residual <= fr.points[0].residual


def test_missing_extra_names_it(monkeypatch):
    def missing():
        raise optimal.MissingExtra("the certified convex solve needs the 'optimal' extra: pip install "
                                   "'mechbal[optimal]'")

    monkeypatch.setattr(optimal, "clarabel_module", missing)
    monkeypatch.setattr(optimal, "available", lambda: False)
    mech = arm()
    with pytest.raises(optimal.MissingExtra, match="optimal"):
        static.balance(mech, SLOTS, 50, objective="inertia")
    r = static.balance(mech, SLOTS, 50)            # the uncertified path still balances
    assert "optimality" not in r.metrics


def test_cli_front(tmp_path, capsys):
    from mechbal.cli import main

    out = tmp_path / "o"
    code = main(["balance", "arm2link", "--front", "4", "--out", str(out), "-q"])
    assert code in (0, 5)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["optimality"]["duality_gap"] is not None
    assert summary["front"]["points"] == 4
    rows = list(csv.DictReader(open(out / "front.csv")))
    assert len(rows) == 4 and all((out / r["design"]).is_file() for r in rows)
    assert float(rows[0]["added_mass_kg"]) == 0.0
    assert main(["balance", "arm2link", "--method", "rms", "--front", "3", "--out", str(tmp_path / "x"), "-q"]) == 2
    assert "--front" in capsys.readouterr().err


@pytest.mark.parametrize("method, reason", [("moment", "second moment"), ("springs", "carries no mass")])
def test_methods_outside_the_convex_path_are_refused_with_the_reason(tmp_path, capsys, method, reason):
    """The force-vs-moment front, and a lightest spring or disc design, are not convex programs
    over what the model designs: the options say why instead of running something else."""
    from mechbal.cli import main

    for flags in (["--objective", "mass"], ["--residual-target", "1.0"]):
        code = main(["balance", "arm2link", "--method", method, *flags, "--out", str(tmp_path / method), "-q"])
        assert code == 2
        assert reason in capsys.readouterr().err
