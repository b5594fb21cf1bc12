"""mechbal.codegen: the generated C++ of one mechanism against the general library.

The generator re-derives every algorithm over an expression graph with the model's constants
folded in; these tests check the graph (evaluated in Python, no compiler) and the compiled header
against the library's own algorithms, which are themselves checked against Pinocchio
(test_urdf.py), on real robots and on random trees with gears, springs, prismatic and fixed
joints."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechbal
from mechbal import _core, codegen
from mechbal.codegen import tree as cg_tree
from mechbal.codegen.expr import Graph

sys.path.insert(0, str(Path(__file__).parent))
from random_trees import random_tree  # noqa: E402
from test_model_springs import random_springs  # noqa: E402
from test_urdf import ROBOTS, _robot_file  # noqa: E402

RTOL = 1e-12
needs_compiler = pytest.mark.skipif(codegen.compiler() is None, reason="no C++ compiler installed")


def _rel(x, y) -> float:
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return float(np.abs(x - y).max() / max(1.0, np.abs(y).max()))


def _random_mechanism(seed: int) -> mechbal.Mechanism:
    rng = np.random.default_rng(seed)
    tree = random_tree(rng, 7, types="RRRPF", mimic=True)
    mech = tree.mechanism()
    return mech.with_springs(random_springs(rng, mech.link_names, 3))


def _library(mech, q, v, a) -> dict[str, np.ndarray]:
    sw = mech.shaking_wrench(q, v, a)
    br = mech.base_reaction(q, v, a)
    return {"inverse_dynamics": mech.inverse_dynamics(q, v, a), "gravity_torque": mech.gravity_torque(q),
            "mass_matrix": mech.mass_matrix(q), "shaking_force": sw.shaking_force,
            "shaking_moment": sw.shaking_moment, "base_force": br.base_reaction_force,
            "base_moment": br.base_reaction_moment, "center_of_mass": mech.center_of_mass(q),
            "momentum_matrix": mech.momentum_matrix(q)}


def _graph_values(mech, q, v, a) -> dict[str, np.ndarray]:
    """Every algorithm of the generator evaluated on its graph (no C++ involved)."""
    tc = cg_tree.tree_constants(mech)
    g = Graph()
    n = tc.dof
    Q, V, A = ([g.input(f"{k}{i}") for i in range(n)] for k in "qva")
    zero = [0.0] * n
    outputs = {
        "inverse_dynamics": cg_tree.newton_euler(g, tc, Q, V, A, gravity=True, springs=True)[0],
        "gravity_torque": cg_tree.newton_euler(g, tc, Q, zero, zero, gravity=True, springs=False)[0],
        "mass_matrix": cg_tree.mass_matrix(g, tc, Q),
        "center_of_mass": cg_tree.center_of_mass(g, tc, Q),
        "momentum_matrix": cg_tree.momentum_matrix(g, tc, Q),
    }
    F, M = cg_tree.shaking_wrench(g, tc, Q, V, A)
    BF, BM = cg_tree.base_reaction(g, tc, Q, V, A)
    outputs.update(shaking_force=F, shaking_moment=M, base_force=BF, base_moment=BM)
    inputs = {f"{k}{i}": float(x[i]) for k, x in zip("qva", (q, v, a)) for i in range(n)}
    keys = list(outputs)
    values = g.evaluate([outputs[k] for k in keys], inputs)
    return {k: np.array(val, dtype=float) for k, val in zip(keys, values)}


@pytest.mark.parametrize("seed", range(12))
def test_generator_graph_matches_the_library_on_random_trees(seed):
    mech = _random_mechanism(seed)
    assert mech.springs
    rng = np.random.default_rng(100 + seed)
    for _ in range(3):
        q, v, a = rng.uniform(-2, 2, size=(3, mech.dof))
        ours, lib = _graph_values(mech, q, v, a), _library(mech, q, v, a)
        worst = {k: _rel(ours[k], lib[k]) for k in lib}
        assert max(worst.values()) < RTOL, worst


def test_the_random_trees_cover_gears_and_prismatic_joints():
    """(Their fixed joints are folded into the moving links by the model, bodies moved along.)"""
    joints = [j for seed in range(12) for j in _random_mechanism(seed).model.description.joints]
    assert sum(bool(j.mimic_joint) for j in joints) >= 3
    assert {j.type.name for j in joints} == {"revolute", "prismatic"}


def test_generator_graph_catches_a_wrong_constant():
    """The comparison above can fail: one body's mass changed by 1e-6 is seen."""
    mech = _random_mechanism(3)
    bodies = list(mech.bodies)
    b = bodies[1]
    bodies[1] = _core.Body(b.name, b.link, b.mass * (1 + 1e-6), b.com, b.inertia)
    wrong = mech.with_bodies(bodies, replace=True)
    q, v, a = np.random.default_rng(0).uniform(-2, 2, size=(3, mech.dof))
    ours, lib = _graph_values(wrong, q, v, a), _library(mech, q, v, a)
    assert _rel(ours["inverse_dynamics"], lib["inverse_dynamics"]) > 1e-9


def test_regeneration_is_byte_identical_and_the_hash_follows_the_input():
    mech = _random_mechanism(5)
    first, second = codegen.generate(mech), codegen.generate(_random_mechanism(5))
    assert first.header == second.header
    assert first.input_hash in first.header and "generator 1" in first.header
    bodies = list(mech.bodies)
    b = bodies[0]
    bodies[0] = _core.Body(b.name, b.link, b.mass + 0.5, b.com, b.inertia)
    other = codegen.generate(mech.with_bodies(bodies, replace=True))
    assert other.input_hash != first.input_hash and other.header != first.header


def test_structural_zeros_are_pruned():
    """A planar chain about z needs far fewer operations than the same chain about tilted axes."""
    def chain(axis):
        joints, bodies, parent = [], [], "base"
        for i in range(4):
            T = np.eye(4)
            T[0, 3] = 0.3
            joints.append(_core.Joint(f"j{i}", _core.JointType.revolute, parent, T, axis))
            bodies.append(_core.Body(f"b{i}", f"j{i}", 1.0, [0.15, 0.0, 0.0], np.diag([0.01, 0.02, 0.02])))
            parent = f"j{i}"
        return mechbal.Mechanism.from_description(joints, bodies)
    planar = codegen.generate(chain([0.0, 0.0, 1.0])).operations["inverse_dynamics"]
    tilted = codegen.generate(chain([0.3, 0.5, 0.81])).operations["inverse_dynamics"]
    assert planar < 0.5 * tilted, (planar, tilted)


def test_refusals_name_the_limit():
    four_bar = mechbal.Mechanism.from_toml(Path(mechbal.__file__).parent / "cases" / "four-bar.toml")
    with pytest.raises(codegen.CodegenError, match="closed loops are not generated yet"):
        codegen.generate(four_bar)
    with pytest.raises(codegen.CodegenError, match="max_joints = 3"):
        codegen.generate(_random_mechanism(1), max_joints=3)
    with pytest.raises(codegen.CodegenError, match="frames: 'nope'"):
        codegen.generate(_random_mechanism(1), frames=["nope"])


@needs_compiler
@pytest.mark.parametrize("robot", ["ur5", "panda", "random"])
def test_compiled_code_matches_the_library(robot, tmp_path):
    mech = _random_mechanism(7) if robot == "random" else mechbal.Mechanism.from_urdf(_robot_file(*ROBOTS[robot]))
    module = codegen.build(mech, cache_dir=tmp_path)
    rng = np.random.default_rng(11)
    for _ in range(20):
        q, v, a = rng.uniform(-3, 3, size=(3, mech.dof))
        lib = _library(mech, q, v, a)
        F, M = module.shaking_wrench(q, v, a)
        BF, BM = module.base_reaction(q, v, a)
        ours = {"inverse_dynamics": module.inverse_dynamics(q, v, a), "gravity_torque": module.gravity_torque(q),
                "mass_matrix": module.mass_matrix(q), "shaking_force": F, "shaking_moment": M,
                "base_force": BF, "base_moment": BM, "center_of_mass": module.center_of_mass(q),
                "momentum_matrix": module.momentum_matrix(q)}
        worst = {k: _rel(ours[k], lib[k]) for k in lib}
        assert max(worst.values()) < RTOL, worst
        for frame in module.frame_names[:: max(1, len(module.frame_names) // 5)]:
            assert _rel(module.frame_placement(q, frame), mech.frame_placement(q, frame)) < RTOL
    # a second build loads the cached library
    again = codegen.build(mech, cache_dir=tmp_path)
    assert again.path == module.path


_STRICT_MAIN = r"""
#include <cstdio>
#include <cstdlib>
#include <new>
#include "HEADER"
static long allocations = 0;
void* operator new(std::size_t n) { ++allocations; void* p = std::malloc(n ? n : 1); if (!p) std::abort(); return p; }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
namespace g = mechbal_generated::NAME;
int main() {
  g::Vector q = g::Vector::LinSpaced(0.1, 0.9), v = g::Vector::Constant(0.3), a = g::Vector::Constant(-0.2);
  double R[9 * (g::num_frames > 0 ? g::num_frames : 1)], p[3 * (g::num_frames > 0 ? g::num_frames : 1)];
  double f[3] = {0, 0, 0}, m[3] = {0, 0, 0};
  for (double& x : R) x = 0.0;
  for (double& x : p) x = 0.0;
  const long before = allocations;
  g::Vector tau = g::inverse_dynamics(q, v, a);
  g::Matrix M = g::mass_matrix(q);
  g::Vector grav = g::gravity_torque(q);
  auto A = g::momentum_matrix(q);
  auto c = g::center_of_mass(q);
  g::shaking_wrench(q.data(), v.data(), a.data(), f, m);
  g::base_reaction(q.data(), v.data(), a.data(), f, m);
  g::frame_placements(q.data(), R, p);
  const long used = allocations - before;
  std::printf("%ld %.17g\n", used, tau.sum() + M.sum() + grav.sum() + A.sum() + c.sum() + f[0] + m[0] + R[0] + p[0]);
  return used == 0 ? 0 : 1;
}
"""


@needs_compiler
def test_generated_header_compiles_strictly_and_allocates_nothing(tmp_path):
    mech = _random_mechanism(2)
    code = codegen.generate(mech, name="random tree")
    header = code.write(tmp_path)
    main = tmp_path / "main.cpp"
    main.write_text(_STRICT_MAIN.replace("HEADER", header.name).replace("NAME", code.name))
    exe = tmp_path / "main"
    eigen = next((p for p in ("/usr/include/eigen3", "/usr/local/include/eigen3") if Path(p).is_dir()), None)
    if eigen is None:
        pytest.skip("Eigen is not installed")
    cmd = [codegen.compiler(), "-std=c++17", "-O1", "-Wall", "-Wextra", "-Werror", "-fno-exceptions",
           "-fno-rtti", "-isystem", eigen, str(main), "-o", str(exe)]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    out = subprocess.run([str(exe)], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout
    assert out.stdout.split()[0] == "0"
