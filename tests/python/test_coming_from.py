"""docs/coming_from.md's notes on Pinocchio, checked against Pinocchio on the same URDF.

The centre of mass: `Mechanism.center_of_mass` is the centre of mass of every body, those on the
root link included (the Panda's panda_link0, 0.63 kg, is fixed to the base); Pinocchio's
`centerOfMass` (data.mass[0], data.com[0]) sums the joints' subtrees only and leaves out the
universe's own inertia (`model.inertias[0]`, where the URDF reader puts the root link's body)."""
from __future__ import annotations

import numpy as np
import pytest

import mechbal
from mechbal.cases.panda import urdf_path

pin = pytest.importorskip("pinocchio")


def _both():
    path = str(urdf_path())
    model = pin.buildModelFromUrdf(path)
    return mechbal.Mechanism.from_urdf(path), model, model.createData()


def test_center_of_mass_includes_the_root_link_where_pinocchio_does_not():
    mech, model, data = _both()
    root = model.inertias[0]
    assert root.mass > 0.5   # panda_link0 sits on the root link
    rng = np.random.default_rng(3)
    for q in rng.uniform(-1.5, 1.5, (5, model.nq)):
        c_pin = np.array(pin.centerOfMass(model, data, q))
        c = np.asarray(mech.center_of_mass(q), float)
        # Pinocchio's total leaves the root link out ...
        assert data.mass[0] == pytest.approx(mech.total_mass - root.mass, rel=1e-12)
        assert np.linalg.norm(c - c_pin) > 1e-3
        # ... and mechbal's is Pinocchio's with the root link's body added back
        with_root = (data.mass[0] * c_pin + root.mass * np.asarray(root.lever)) / (data.mass[0] + root.mass)
        np.testing.assert_allclose(c, with_root, atol=1e-12)


def test_the_docs_say_so():
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "coming_from.md").read_text()
    row = next(line for line in text.splitlines() if line.startswith("| centre of mass"))
    assert "root link" in row and "centerOfMass" in row
