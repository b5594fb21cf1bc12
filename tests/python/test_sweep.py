"""Design sweeps (issue 16): batched evaluations equal rebuilt ones, the same seeded sweep gives the
same table serially, on local processes and on a Dask cluster, a worker killed mid-sweep loses
nothing, and the [sweep] file and command line are strict.

One Dask LocalCluster (2 worker processes, loopback only) serves the whole module: starting one
takes seconds."""
from __future__ import annotations

import copy
import json
import math
import os
import signal
import threading
import time

import numpy as np
import pytest

pd = pytest.importorskip("pandas")
pytest.importorskip("pyarrow")
distributed = pytest.importorskip("distributed")

from mechbal import Mechanism  # noqa: E402
from mechbal.config import read_case  # noqa: E402
from mechbal.errors import ConfigError  # noqa: E402
from mechbal.spec import mechanism_spec  # noqa: E402
from mechbal.sweep import Parameter, Sweep  # noqa: E402

ARM = "arm2link-balanced"

# A tree with a rotated fixed joint (folded into its moving ancestor by the model) that carries a
# body and the next joint: the batched path must map the body's link-frame parameters into the
# model's frames. (The tool has no rpy of its own so that its file values are its link-frame values,
# which the test's own setter relies on.)
TREE = {
    "gravity": [0.3, -0.2, -9.81],
    "joints": [
        {"name": "shoulder", "origin": {"xyz": [0.0, 0.0, 0.3], "rpy": [0.1, 0.0, 0.2]}, "axis": [0, 0, 1],
         "link": {"mass": 3.0, "com": [0.1, 0.02, 0.05], "inertia": [0.02, 0.03, 0.025, 0.001, 0.0, 0.002]}},
        {"name": "bracket", "type": "fixed", "origin": {"xyz": [0.2, 0.05, 0.1], "rpy": [0.4, -0.3, 0.7]}},
        {"name": "elbow", "parent": "bracket", "origin": {"xyz": [0.3, 0.0, 0.0], "rpy": [1.2, 0.0, 0.0]},
         "axis": [0, 1, 0.2], "link": {"mass": 1.5, "com": [0.15, 0.0, 0.01], "inertia": [0.004, 0.01, 0.01]}},
        {"name": "wrist", "parent": "elbow", "origin": {"xyz": [0.3, 0.0, 0.0]}, "axis": [1, 0, 0],
         "link": {"mass": 0.7, "com": [0.05, 0.01, 0.0], "inertia": [0.001, 0.002, 0.002]}},
    ],
    "bodies": [
        {"name": "tool", "link": "bracket", "mass": 0.9, "com": [0.05, -0.03, 0.02],
         "inertia": [0.003, 0.004, 0.005, 0.0002, 0.0001, -0.0003]},
        {"name": "counterweight", "kind": "counterweight", "link": "shoulder", "mass": 2.0,
         "com": [-0.15, 0.0, 0.0], "inertia": [0.001, 0.001, 0.001]},
    ],
}
TREE_TRAJECTORY = {"start": [0.0, 0.2, -0.3], "end": [1.0, -0.8, 0.9], "duration": 1.0, "samples": 41}


def tree_case():
    return {"case": {"name": "tree", "kind": "mechanism"}, "mechanism": copy.deepcopy(TREE),
            "trajectory": dict(TREE_TRAJECTORY)}


def _trajectory(spec_dof, table):
    from mechbal.config import trajectory_from_config

    traj, t = trajectory_from_config(table, spec_dof)
    return traj.evaluate_batch(t)


def _stat(x, statistic, joint=None):
    x = np.asarray(x, float)
    n2 = x[:, joint] ** 2 if joint is not None else np.sum(x * x, axis=1)
    return math.sqrt(n2.max()) if statistic == "peak" else math.sqrt(n2.mean())


def _direct(config: dict, poses, trajectory, q_guess=None) -> dict:
    """Every built-in metric of the mechanism of ``config`` (a TOML case as a dict), evaluated
    with the plain Mechanism API: no regressor, no sweep code."""
    mech = Mechanism.from_spec(mechanism_spec(config["mechanism"]))
    qa, va, aa = trajectory
    if mech.is_closed:
        guess = np.zeros(mech.dof) if q_guess is None else q_guess
        gravity = mech.reduced_mass_matrix(poses, q_guess=guess)[1]          # C^T G
        m = mech.closed_motion(qa, va, aa, q_guess=guess, with_forces=True)
        q, v, a, torque = m.q, m.v, m.a, m.actuated_force
    else:
        gravity = mech.gravity_torque(poses)
        q, v, a, torque = qa, va, aa, mech.inverse_dynamics(qa, va, aa)
    w = mech.shaking_wrench(q, v, a)
    out = {}
    for name, x in (("gravity_torque", gravity), ("joint_torque", torque),
                    ("shaking_force", w.shaking_force), ("shaking_moment", w.shaking_moment)):
        for s in ("peak", "rms"):
            out[f"{s}_{name}"] = _stat(x, s)
            if name in ("gravity_torque", "joint_torque"):
                for j, joint in enumerate(mech.actuated_names):
                    out[f"{s}_{name}.{joint}"] = _stat(x, s, j)
    return out


def _set_user_value(config: dict, path: str, value: float) -> None:
    """Set a parameter in the TOML dict, in the user's own terms (origin-given joints and bodies
    without DH frames: the spec's link-frame values are the file's values)."""
    m = config["mechanism"]
    kind, rest = path.split(".", 1)
    name, attr = rest.rsplit(".", 1) if "placement" not in rest else rest.split(".placement.")
    if kind == "bodies":
        body = next((b for b in m["bodies"] if b["name"] == name), None)
        if body is None:
            body = next(j for j in m["joints"] if j["name"] == name)["link"]
        if attr == "mass":
            body["mass"] = value
        elif attr.startswith("com"):
            body["com"][int(attr[4])] = value
        else:
            k = int(attr[8])
            inertia = list(body["inertia"])
            if len(inertia) == 3:
                inertia += [0.0, 0.0, 0.0]
            inertia[k] = value
            body["inertia"] = inertia
    else:
        joint = next(j for j in m["joints"] if j["name"] == name)
        joint["origin"]["xyz"][int(attr[4])] = value


def _check_against_rebuilt(config: dict, params: list[Parameter], evaluations: int, *, rel=1e-12,
                           poses_from=None, **kw):
    metrics = [f"{s}_{q}" for q in ("gravity_torque", "joint_torque", "shaking_force", "shaking_moment")
               for s in ("peak", "rms")]
    spec = mechanism_spec(config["mechanism"])
    names = spec.actuated if spec.loops else spec.independent_joints
    metrics += [f"rms_joint_torque.{names[-1]}", f"peak_gravity_torque.{names[0]}"]
    sweep = Sweep(spec, params, metrics, kind="monte_carlo", evaluations=evaluations, seed=11,
                  trajectory=_trajectory(len(names), config["trajectory"]), **kw)
    assert all(p.target.batched for p in sweep.parameters)
    table = sweep.run("serial", progress=False).table
    assert (table["status"] == "ok").all()
    nominal = _direct(config, sweep.poses, sweep.trajectory, sweep.q_guess)
    for i in range(evaluations):
        changed = copy.deepcopy(config)
        for p in sweep.paths:
            _set_user_value(changed, p, float(table.at[i, p]))
        direct = _direct(changed, sweep.poses, sweep.trajectory, sweep.q_guess)
        for c in metrics:
            scale = max(abs(nominal["peak_" + c.split(".")[0].split("_", 1)[1]]), 1.0)
            assert table.at[i, c] == pytest.approx(direct[c], rel=rel, abs=rel * scale), (i, c)


# ---- batched == rebuilt ------------------------------------------------------------------------------

def test_batched_equals_rebuilt_balanced_arm():
    config = read_case(ARM)
    params = [Parameter("bodies.counterweight1.mass", tolerance=0.05),
              Parameter("bodies.shoulder.mass", tolerance=0.05, distribution="normal"),
              Parameter("bodies.counterweight2.com[0]", delta=0.002),
              Parameter("bodies.elbow.com[2]", delta=0.01),
              Parameter("bodies.elbow.inertia[0]", tolerance=0.1)]
    _check_against_rebuilt(config, params, 12, pose_source="uniform", pose_count=30)


def test_batched_equals_rebuilt_tree_with_fixed_joint_and_rotated_body():
    params = [Parameter("bodies.tool.mass", tolerance=0.1),
              Parameter("bodies.tool.com[1]", delta=0.02),
              Parameter("bodies.tool.inertia[3]", delta=0.0001),
              Parameter("bodies.elbow.com[0]", delta=0.02),
              Parameter("bodies.counterweight.mass", values=[1.5, 2.0, 2.5])]
    _check_against_rebuilt(tree_case(), params, 10, pose_source="uniform", pose_count=25)


def test_batched_equals_rebuilt_closed_four_bar():
    config = read_case("four-bar")
    config["trajectory"]["samples"] = 41
    params = [Parameter("bodies.crank_counterweight.mass", tolerance=0.1),
              Parameter("bodies.coupler.com[0]", delta=0.01),
              Parameter("bodies.rocker.mass", tolerance=0.05)]
    _check_against_rebuilt(config, params, 8, rel=1e-11, pose_count=15)


def test_geometric_parameters_rebuild_the_model():
    """A joint placement changes the regressors: such sets are rebuilt, and equal a model built
    from the changed file."""
    config = read_case(ARM)
    sweep = Sweep(ARM, [Parameter("joints.elbow.placement.xyz[0]", delta=0.003),
                        Parameter("bodies.counterweight1.mass", tolerance=0.02)],
                  ["peak_gravity_torque", "rms_joint_torque", "peak_shaking_moment"],
                  kind="sensitivity", trajectory_samples=41, pose_source="uniform", pose_count=20)
    assert [p.target.batched for p in sweep.parameters] == [False, True]
    table = sweep.run("serial", progress=False).table
    assert list(table["level"]) == ["nominal", "low", "high", "low", "high"]
    traj = sweep.trajectory
    for i in range(len(table)):
        changed = copy.deepcopy(config)
        for p in sweep.paths:
            _set_user_value(changed, p, float(table.at[i, p]))
        direct = _direct(changed, sweep.poses, traj)
        for c in ("peak_gravity_torque", "rms_joint_torque", "peak_shaking_moment"):
            assert table.at[i, c] == pytest.approx(direct[c], rel=1e-12, abs=1e-12 * 20)
    # the elbow 3 mm further out unbalances the arm; the nominal is balanced
    assert table.at[0, "peak_gravity_torque"] < 1e-12
    assert table.at[2, "peak_gravity_torque"] > 1e-3


def test_balanced_arm_case_is_statically_balanced():
    mech = Mechanism.from_toml(read_case.__globals__["case_path"](ARM))
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (200, 2))
    assert np.max(np.abs(mech.gravity_torque(q))) < 1e-12
    assert np.max(np.abs(mech.gravity_torque(q))) < 1e-12 * 9.81 * mech.total_mass


# ---- backends ----------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def cluster():
    """Two worker processes on loopback, one thread each; one cluster for the whole module."""
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None, silence_logs=50) as c, \
            distributed.Client(c, set_as_default=False) as client:
        yield client


def _mixed_sweep(delay: float = 0.0, evaluations: int = 60, chunk_size: int = 8):
    """Batched sets, rebuilt sets (a list of elbow positions) and a callable metric (picklable by
    value: a closure, which cloudpickle ships to the workers)."""
    def total_mass(mech, _delay=delay):
        if _delay:
            time.sleep(_delay)
        return {"total": mech.total_mass, "com_x": float(mech.center_of_mass(np.zeros(mech.dof))[0])}

    return Sweep(ARM, [Parameter("bodies.counterweight1.mass", tolerance=0.02),
                       Parameter("bodies.shoulder.mass", tolerance=0.02, distribution="normal"),
                       Parameter("bodies.elbow.com[0]", delta=0.001),
                       Parameter("joints.elbow.placement.xyz[0]", values=[0.5, 0.5, 0.5, 0.501])],
                 {"peak_gravity_torque": "peak_gravity_torque", "rms_shaking_force": "rms_shaking_force",
                  "rms_joint_torque.elbow": "rms_joint_torque.elbow", "mass": total_mass},
                 kind="monte_carlo", evaluations=evaluations, seed=5, trajectory_samples=31,
                 pose_source="uniform", pose_count=20, chunk_size=chunk_size)


@pytest.fixture(scope="module")
def serial_table():
    return _mixed_sweep().run("serial", progress=False).table


def test_serial_table_is_complete_and_seeded(serial_table):
    t = serial_table
    assert list(t["evaluation"]) == list(range(60))
    assert list(t.columns) == ["evaluation", "bodies.counterweight1.mass", "bodies.shoulder.mass",
                               "bodies.elbow.com[0]", "joints.elbow.placement.xyz[0]", "peak_gravity_torque",
                               "rms_shaking_force", "rms_joint_torque.elbow", "mass.com_x", "mass.total",
                               "status"]
    assert (t["status"] == "ok").all() and np.isfinite(t.drop(columns="status").to_numpy(float)).all()
    assert (t["joints.elbow.placement.xyz[0]"] == 0.501).any()   # some sets are rebuilt
    again = _mixed_sweep().run("serial", progress=False).table
    pd.testing.assert_frame_equal(t, again, check_exact=True)
    other = _mixed_sweep()
    other.seed = 6
    assert not np.array_equal(other.run("serial", progress=False).table["bodies.shoulder.mass"],
                              t["bodies.shoulder.mass"])
    # chunking is part of the plan, not of the result
    pd.testing.assert_frame_equal(t, _mixed_sweep(chunk_size=7).run("serial", progress=False).table,
                                  check_exact=True)


def test_same_table_on_local_processes(serial_table):
    table = _mixed_sweep().run("processes", workers=2, progress=False).table
    pd.testing.assert_frame_equal(serial_table, table, check_exact=True)


def test_same_table_on_a_dask_cluster(serial_table, cluster):
    table = _mixed_sweep().run("dask", scheduler=cluster, progress=False).table
    pd.testing.assert_frame_equal(serial_table, table, check_exact=True)
    # by address, as `mechbal sweep --scheduler tcp://...` does
    table = _mixed_sweep().run("dask", scheduler=cluster.scheduler_info()["address"], progress=False).table
    pd.testing.assert_frame_equal(serial_table, table, check_exact=True)


def test_a_worker_killed_mid_sweep_loses_no_results(serial_table, cluster):
    pids = cluster.run(os.getpid)
    assert len(pids) == 2
    killed = {}

    def kill_one(done, total):
        if not killed and done >= 1:
            # a worker with work left: every worker has queued chunks at this point
            address, pid = sorted(pids.items())[0]
            os.kill(pid, signal.SIGKILL)
            killed.update(done=done, total=total, pid=pid)

    sweep = _mixed_sweep(delay=0.02)  # ~0.16 s per chunk: the sweep outlasts the kill
    table = sweep.run("dask", scheduler=cluster, progress=False, callback=kill_one).table
    assert killed and killed["done"] < killed["total"]
    pd.testing.assert_frame_equal(serial_table, table, check_exact=True)
    # the nanny restarts the worker; the killed process is gone
    deadline = time.time() + 30
    while time.time() < deadline:
        try:
            os.kill(killed["pid"], 0)
        except ProcessLookupError:
            break
        time.sleep(0.1)
    else:
        pytest.fail("the killed worker is still alive")


# ---- files, schema, command line ------------------------------------------------------------------------

def test_sweep_file_errors_name_the_field(tmp_path):
    from mechbal.sweep.config import from_toml

    def write(text):
        p = tmp_path / "s.toml"
        p.write_text(text)
        return p

    head = '[sweep]\nname = "s"\nkind = "monte_carlo"\nevaluations = 10\nmetrics = ["peak_gravity_torque"]\n'
    par = '[[sweep.parameters]]\npath = "bodies.counterweight1.mass"\ntolerance = 0.02\n'
    cases = [
        (head.replace("evaluations", "evaluatons") + par, "sweep.evaluatons: unknown key (did you mean 'evaluations'?)"),
        (head + par.replace("tolerance", "tolerence"), "sweep.parameters[0].tolerence: unknown key (did you mean 'tolerance'?)"),
        (head + par.replace("tolerance = 0.02", "tolerance = 0.02\ndelta = 0.1"), "sweep.parameters[0]: give exactly one range"),
        (head.replace("monte_carlo", "monte-carlo") + par, "sweep.kind: must be one of monte_carlo, sensitivity, grid"),
        (head + par.replace("counterweight1", "counterwieght1"), "sweep.parameters[0].path: no body named 'counterwieght1' (did you mean 'counterweight1'?)"),
        (head + par.replace("bodies.counterweight1.mass", "bodys.x.mass"), "sweep.parameters[0].path: not a parameter path (did you mean 'bodies'?)"),
        (head.replace("peak_gravity_torque", "peak_gravity_torqe") + par, "sweep.metrics[0]: unknown metric (did you mean 'peak_gravity_torque'?)"),
        (head.replace('"peak_gravity_torque"', '"rms_joint_torque.elbw"') + par, "no actuated joint named 'elbw' (did you mean 'elbow'?)"),
        (head.replace("evaluations = 10", "evaluations = 10.0") + par, "sweep.evaluations: must be an integer"),
        (head.replace("evaluations = 10\n", "") + par, "sweep.evaluations: is required"),
        (head + par + '[[sweep.parameters]]\npath = "design.k"\ndelta = 1.0\n', "sweep.parameters[1].nominal: a design variable needs a nominal"),
    ]
    for text, message in cases:
        with pytest.raises(ConfigError) as err:
            from_toml(write(text), ARM)
        assert message in str(err.value), (message, str(err.value))
        assert "\n" not in str(err.value)


def test_builtin_sweep_files_match_the_json_schema():
    jsonschema = pytest.importorskip("jsonschema")
    from mechbal.config import read_toml
    from mechbal.schema import json_schema
    from mechbal.sweep.config import builtin_sweeps

    files = sorted(builtin_sweeps().values())
    assert len(files) >= 2
    for p in files:
        jsonschema.validate(read_toml(p), json_schema())
        jsonschema.validate(read_toml(p), json_schema("sweep"))


def test_cli_sweep_writes_a_whole_run(tmp_path, capsys):
    from mechbal.cli import main

    out = tmp_path / "sens"
    assert main(["sweep", ARM, "--spec", "arm2link-balanced-sensitivity", "--out", str(out),
                 "--backend", "serial", "-q"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert "results.parquet" in names and "summary.json" in names
    assert "tornado_peak_gravity_torque.png" in names
    summary = json.loads((out / "summary.json").read_text())
    top = summary["metrics"]["peak_gravity_torque"]["parameters"][0]
    assert top["parameter"] == "bodies.counterweight1.mass"   # the heaviest part dominates
    assert summary["metrics"]["peak_gravity_torque"]["nominal"] < 1e-12
    table = pd.read_parquet(out / "results.parquet")
    assert len(table) == 1 + 2 * 8 and (table["status"] == "ok").all()
    # a mistake is one line and exit code 2, and leaves no output behind
    bad = tmp_path / "bad.toml"
    bad.write_text('[sweep]\nname = "x"\nkind = "grid"\nmetrics = ["peak_gravity_torque"]\n'
                   '[[sweep.parameters]]\npath = "joints.elbw.placement.xyz[0]"\ndelta = 0.01\n')
    capsys.readouterr()
    assert main(["sweep", ARM, "--spec", str(bad), "--out", str(tmp_path / "bad"), "--backend", "serial"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "sweep.parameters[0].path: no joint named 'elbw' (did you mean 'elbow'?)" in err
    assert not (tmp_path / "bad").exists()


def test_missing_extra_is_named(monkeypatch):
    import sys

    from mechbal.sweep.backends import require_extra

    monkeypatch.setitem(sys.modules, "pyarrow", None)
    with pytest.raises(ImportError, match=r"mechbal\[sweep\]"):
        require_extra("pyarrow")


def test_non_physical_sets_are_marked_not_evaluated():
    sweep = Sweep(ARM, [Parameter("bodies.counterweight2.mass", lower=-0.5, upper=0.5),
                        Parameter("bodies.elbow.inertia[0]", values=[0.002, 0.5])],
                  ["peak_gravity_torque"], kind="grid", pose_count=5, trajectory_samples=11)
    t = sweep.run("serial", progress=False).table
    bad = t["status"] != "ok"
    assert list(bad) == [True, True, False, True, False, True]   # negative mass; triangle inequality
    assert t.loc[bad, "peak_gravity_torque"].isna().all()
    assert t.loc[~bad, "peak_gravity_torque"].notna().all()


def test_design_variables_reach_callable_metrics_and_grids_take_every_combination(tmp_path):
    def cost(mech, design):
        return {"weighted_mass": design["design.price"] * mech.total_mass,
                "price": design["design.price"]}

    sweep = Sweep(ARM, [Parameter("design.price", nominal=2.0, values=[1.0, 3.0]),
                        Parameter("bodies.counterweight1.mass", lower=4.0, upper=6.0, steps=3)],
                  {"cost": cost, "peak": "peak_gravity_torque"}, kind="grid", pose_count=10,
                  trajectory_samples=11)
    result = sweep.run("serial", progress=False)
    t = result.table
    assert len(t) == 6 and list(t["design.price"]) == [1.0, 1.0, 1.0, 3.0, 3.0, 3.0]
    assert list(t["bodies.counterweight1.mass"]) == [4.0, 5.0, 6.0] * 2
    total = t["bodies.counterweight1.mass"] + 4.0 + 2.0 + 1.0
    np.testing.assert_allclose(t["cost.weighted_mass"], t["design.price"] * total, rtol=1e-15)
    assert result.nominal["cost.price"] == 2.0
    s = result.summary()
    assert s["metrics"]["peak"]["at_min"]["bodies.counterweight1.mass"] == 5.0   # the balanced design
    files = result.write(tmp_path / "grid", fmt="csv")
    back = pd.read_csv(tmp_path / "grid" / "results.csv")
    np.testing.assert_array_equal(back["cost.weighted_mass"].to_numpy(), t["cost.weighted_mass"].to_numpy())
    assert {p.name for p in files} == {"results.csv", "summary.json"}
    with pytest.raises(ValueError, match="f\\(mechanism, design\\)"):
        Sweep(ARM, [Parameter("design.price", nominal=2.0, delta=1.0)], {"m": lambda m: m.total_mass},
              kind="sensitivity", pose_count=5, trajectory_samples=11).run("serial", progress=False)


def test_urdf_robot_batched_equals_rebuilt():
    """Panda from its URDF (fixed joints folded, a mimic finger): body parameters batched against
    the model rebuilt from the changed description and evaluated by RNEA directly."""
    from test_urdf import ROBOTS, _robot_file

    from mechbal.sweep.parameters import apply_values

    path = _robot_file(*ROBOTS["panda"])
    params = [Parameter("bodies.panda_link4.mass", tolerance=0.05),
              Parameter("bodies.panda_link4.com[1]", delta=0.01),
              Parameter("bodies.panda_hand.mass", tolerance=0.1),
              Parameter("bodies.panda_link6.inertia[5]", delta=1e-5)]
    sweep = Sweep(str(path), params, ["peak_gravity_torque", "rms_joint_torque", "peak_shaking_moment"],
                  kind="monte_carlo", evaluations=6, seed=3, trajectory_samples=21, pose_source="uniform",
                  pose_count=10)
    table = sweep.run("serial", progress=False).table
    assert (table["status"] == "ok").all()
    plan = sweep.plan()
    for i in range(len(table)):
        mech = Mechanism.from_spec(apply_values(plan.spec, plan.targets, table.loc[i, sweep.paths].to_numpy(float),
                                                plan.nominal))
        qa, va, aa = sweep.trajectory
        direct = {"peak_gravity_torque": _stat(mech.gravity_torque(sweep.poses), "peak"),
                  "rms_joint_torque": _stat(mech.inverse_dynamics(qa, va, aa), "rms"),
                  "peak_shaking_moment": _stat(mech.shaking_wrench(qa, va, aa).shaking_moment, "peak")}
        for c, v in direct.items():
            assert table.at[i, c] == pytest.approx(v, rel=1e-12), (i, c)


def test_paminsa_counterweight_tolerance_brings_shaking_force_back():
    """The issue's example on PAMINSA as data (38 bodies, 9 loops, geared counter-mass): balanced
    at nominal, +-2 % counterweights bring shaking force back; batched sets equal the linkage
    rebuilt and solved directly."""
    from mechbal.sweep.config import from_toml
    from mechbal.sweep.parameters import apply_values

    full = from_toml("paminsa-tolerance", "paminsa-linkage")
    assert len(full.parameters) == 10 and full.evaluations == 10_000
    sweep = Sweep(full.base, [Parameter(p.path, tolerance=0.02) for p in full.parameters],
                  ["peak_shaking_force", "rms_joint_torque"], kind="monte_carlo", evaluations=5,
                  seed=2009, trajectory_samples=31)
    result = sweep.run("serial", progress=False)
    t = result.table
    assert result.nominal["peak_shaking_force"] < 1e-10
    assert (t["peak_shaking_force"] > 1e-3).all()
    plan = sweep.plan()
    qa, va, aa = sweep.trajectory
    for i in range(len(t)):
        mech = Mechanism.from_spec(apply_values(plan.spec, plan.targets, t.loc[i, sweep.paths].to_numpy(float),
                                                plan.nominal))
        m = mech.closed_motion(qa, va, aa, q_guess=sweep.q_guess, with_forces=True)
        w = mech.shaking_wrench(m.q, m.v, m.a)
        assert t.at[i, "peak_shaking_force"] == pytest.approx(_stat(w.shaking_force, "peak"), rel=1e-12, abs=1e-12 * 30)
        assert t.at[i, "rms_joint_torque"] == pytest.approx(_stat(m.actuated_force, "rms"), rel=1e-12)


def test_a_balancing_method_is_a_metric():
    """mechbal.balance.static sizes the counterweights of every perturbed arm2link; with the
    lightest solution at the largest radius allowed, the 2-DOF arm's closed form gives them
    (Arakelian, Le Baron & Mottu 2011, eqs 21-22): m_cw2 r2 = m2 l_s2, m_cw1 r1 = m1 l_s1 + (m2 + m_cw2) l1."""
    from mechbal.balance import CounterweightSlot, method

    slots = [CounterweightSlot("cw1", "shoulder", max_radius=0.5, direction=(-1.0, 0.0, 0.0)),
             CounterweightSlot("cw2", "elbow", max_radius=0.4, direction=(-1.0, 0.0, 0.0))]

    def counterweights(mech):
        r = method("static").balance(mech, slots, samples=30)
        return {"cw1": r.design["cw1"].mass, "cw2": r.design["cw2"].mass, "residual": r.residual}

    sweep = Sweep("arm2link", [Parameter("bodies.shoulder.mass", tolerance=0.05),
                               Parameter("bodies.elbow.mass", tolerance=0.05)],
                  {"static": counterweights}, kind="sensitivity", pose_count=5, trajectory_samples=11)
    t = sweep.run("serial", progress=False).table
    m1, m2 = t["bodies.shoulder.mass"], t["bodies.elbow.mass"]
    cw2 = m2 * 0.2 / 0.4
    np.testing.assert_allclose(t["static.cw2"], cw2, rtol=1e-9)
    np.testing.assert_allclose(t["static.cw1"], (m1 * 0.25 + (m2 + cw2) * 0.5) / 0.5, rtol=1e-9)
    assert (t["static.residual"] < 1e-9).all()


def test_auto_backend_runs_small_sweeps_serially_and_gives_the_same_table(serial_table, monkeypatch):
    from mechbal.sweep import backends

    started = []

    def pool(plan, chunks, workers, bar):   # stands in for the local processes, records the hand-over
        started.append(len(chunks))
        return [backends.evaluate_chunk(plan, start, values) for start, values in chunks]

    monkeypatch.setattr(backends, "_processes", pool)
    table = _mixed_sweep().run(progress=False).table   # the default backend is auto
    assert not started   # 60 evaluations: far below AUTO_SERIAL_SECONDS in one process
    pd.testing.assert_frame_equal(serial_table, table, check_exact=True)
    # a sweep judged long from its first chunk hands the rest to local processes
    monkeypatch.setattr(backends, "AUTO_SERIAL_SECONDS", 0.0)
    table = _mixed_sweep().run(progress=False, workers=2).table
    assert started == [7]   # 8 chunks of 8: the first here, seven to the pool
    pd.testing.assert_frame_equal(serial_table, table, check_exact=True)


def test_losing_the_cluster_names_the_finished_evaluations_and_keeps_them():
    from mechbal.sweep.backends import SweepIncomplete

    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                                       dashboard_address=None, silence_logs=50)
    client = distributed.Client(cluster, set_as_default=False)
    done = {}

    def stop_cluster(n, total):
        if not done:
            done.update(n=n, total=total)
            cluster.close()   # every worker and the scheduler gone

    try:
        with pytest.raises(SweepIncomplete) as e:
            _mixed_sweep(delay=0.02).run("dask", scheduler=client, progress=False, callback=stop_cluster)
    finally:
        client.close()
        cluster.close()
    exc = e.value
    assert exc.rows_total == 60 and 8 <= exc.rows_done < 60
    assert f"{exc.rows_done} of 60 evaluations were finished" in str(exc)
    assert sum(len(r["status"]) for _, r in exc.finished) == exc.rows_done
    assert all(isinstance(r, dict) for _, r in exc.finished)


def test_the_metric_names_before_schema_1_are_read_with_a_warning():
    from mechbal.sweep.metrics import RENAMED, resolve

    assert RENAMED["actuator_torque_rms"] == "rms_joint_torque" and RENAMED["shaking_force_peak"] == "peak_shaking_force"
    with pytest.warns(DeprecationWarning, match="now called 'peak_shaking_force'"):
        (spec,) = resolve(["shaking_force_peak"], ["elbow"])
    assert (spec.name, spec.statistic, spec.quantity) == ("peak_shaking_force", "peak", "shaking_force")
    with pytest.warns(DeprecationWarning):
        (spec,) = resolve({"mine": "actuator_torque_rms.elbow"}, ["elbow"])
    assert (spec.name, spec.quantity, spec.joint) == ("mine", "joint_torque", "elbow")
