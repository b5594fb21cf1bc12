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
    joints = [mechbal.JointSpec(s["name"],
                                mechbal.JointType.prismatic if s["prismatic"] else mechbal.JointType.revolute,
                                s["origin"], s["axis"], s["mass"], s["com"], s["inertia"])
              for s in specs]
    return mechbal.ChainModel(joints, np.array(gravity), np.eye(4) if base is None else base)


@pytest.fixture(scope="session")
def demo_run(tmp_path_factory):
    """The default serial-chain case run once into a temporary folder."""
    from mechbal.cases import run_case

    out = tmp_path_factory.mktemp("arm2link")
    summary = run_case("arm2link", out)
    return out, summary
