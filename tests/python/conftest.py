import numpy as np
import pytest

import mechbal


def random_chain_specs(rng: np.random.Generator, types: str):
    """Random joints as plain arrays (so that the same chain can be built in other engines)."""
    specs = []
    for i, t in enumerate(types):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        if np.linalg.det(q) < 0:
            q[:, 0] *= -1
        origin = np.eye(4)
        origin[:3, :3] = q
        origin[:3, 3] = rng.uniform(-0.4, 0.4, 3)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        a, c = rng.uniform(0.1, 2.0, 2)
        p = np.array([a, c, abs(a - c) + 0.5 * (a + c - abs(a - c))]) * 0.05
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        inertia = Q @ np.diag(p) @ Q.T
        specs.append(dict(name=f"j{i + 1}", prismatic=(t == "P"), origin=origin, axis=axis,
                          mass=rng.uniform(0.1, 2.0), com=rng.uniform(-0.3, 0.3, 3),
                          inertia=0.5 * (inertia + inertia.T)))
    return specs


def chain_from_specs(specs, gravity=(0.0, 0.0, -9.81), base=None):
    """The serial chain of ``specs`` as a general `mechbal.MechanismModel`: joint i's parent
    is joint i - 1, one body per link (named after its joint), ``base`` (4x4) folded into the
    first joint's placement."""
    joints, bodies, parent = [], [], "base"
    for k, s in enumerate(specs):
        placement = np.asarray(s["origin"], float)
        if k == 0 and base is not None:
            placement = np.asarray(base, float) @ placement
        kind = mechbal.JointType.prismatic if s["prismatic"] else mechbal.JointType.revolute
        joints.append(mechbal.Joint(s["name"], kind, parent, placement, np.asarray(s["axis"], float)))
        bodies.append(mechbal.Body(s["name"], s["name"], float(s["mass"]), np.asarray(s["com"], float),
                                   np.asarray(s["inertia"], float)))
        parent = s["name"]
    return mechbal.MechanismModel(mechbal.MechanismDescription(joints, bodies, [], np.asarray(gravity, float)))


@pytest.fixture(scope="session")
def demo_run(tmp_path_factory):
    """The default serial-chain case run once into a temporary folder."""
    from mechbal.cases import run_case

    out = tmp_path_factory.mktemp("arm2link")
    summary = run_case("arm2link", out)
    return out, summary


@pytest.fixture(scope="session", autouse=True)
def every_summary_follows_the_schema(tmp_path_factory):
    """At the end of the session, every summary.json that the tests wrote under the session's
    temporary folder (run, balance, verify, sweep, through the API or the command line) is
    validated against the shipped JSON Schema (mechbal/cases/summary.schema.json): an error here
    names each file and what is wrong with it."""
    yield
    try:
        import jsonschema
    except ImportError:  # the test extra is not installed: test_summary_schema.py is skipped too
        return
    import json
    from pathlib import Path

    schema = json.loads((Path(mechbal.__file__).resolve().parent / "cases" / "summary.schema.json").read_text())
    check = jsonschema.Draft202012Validator(schema)
    bad = []
    for path in sorted(Path(tmp_path_factory.getbasetemp()).rglob("summary.json")):
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError):
            continue  # a test's own broken file (the CLI's refusal of a damaged run folder)
        if not isinstance(data, dict) or not {"schema_version", "command", "case", "sweep"} & set(data):
            continue  # not a mechbal summary (a test's planted marker file)
        problems = [f"{'.'.join(map(str, e.absolute_path)) or '<top>'}: {e.message[:200]}"
                    for e in check.iter_errors(data)]
        if problems:
            bad.append(f"{path}:\n    " + "\n    ".join(problems[:5]))
    assert not bad, "summary.json files that do not follow the schema:\n" + "\n".join(bad[:20])
