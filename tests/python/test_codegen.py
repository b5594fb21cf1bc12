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
from mechbal.codegen.expr import Graph, directional_derivative

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
  CLOSED
  const long used = allocations - before;
  std::printf("%ld %.17g\n", used, tau.sum() + M.sum() + grav.sum() + A.sum() + c.sum() + f[0] + m[0] + R[0] + p[0]);
  return used == 0 ? 0 : 1;
}
"""


_CLOSED_CALLS = """double qa[g::num_actuated], va[g::num_actuated], aa[g::num_actuated];
  for (int i = 0; i < g::num_actuated; ++i) { qa[i] = q[g::actuated_index[i]]; va[i] = 0.1; aa[i] = 0.2; }
  double qc[g::dof];
  for (int i = 0; i < g::dof; ++i) qc[i] = q[i];
  int status = g::closed_shaking_wrench(qa, va, aa, qc, f, m);
  g::ClosedState state;
  for (int i = 0; i < g::dof; ++i) state.q[i] = q[i];
  status += 10 * g::closed_tick(state, qa, va, aa, f, m);
  std::printf("closed status %d\\n", status);"""


@needs_compiler
@pytest.mark.parametrize("which", ["random tree", "four-bar"])
def test_generated_header_compiles_strictly_and_allocates_nothing(which, tmp_path):
    mech = _random_mechanism(2) if which == "random tree" else _closed_case("four-bar")[0]
    code = codegen.generate(mech, name=which)
    header = code.write(tmp_path)
    main = tmp_path / "main.cpp"
    main.write_text(_STRICT_MAIN.replace("HEADER", header.name).replace("NAME", code.name)
                    .replace("CLOSED", _CLOSED_CALLS if code.closed else ""))
    exe = tmp_path / "main"
    eigen = next((p for p in ("/usr/include/eigen3", "/usr/local/include/eigen3") if Path(p).is_dir()), None)
    if eigen is None:
        pytest.skip("Eigen is not installed")
    cmd = [codegen.compiler(), "-std=c++17", "-O1", "-Wall", "-Wextra", "-Werror", "-fno-exceptions",
           "-fno-rtti", "-isystem", eigen, str(main), "-o", str(exe)]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    out = subprocess.run([str(exe)], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout
    assert out.stdout.strip().splitlines()[-1].split()[0] == "0"


@needs_compiler
def test_generated_computed_torque_ticks_as_the_library(tmp_path):
    """2,000 ticks of the generated ComputedTorque of a random tree (gears, springs, prismatic
    joints) against the library's ComputedTorque over the same model: the same torques (1e-12)
    and the same status on every tick, through good ticks, saturated ones, inputs out of the
    declared range, non-finite inputs (the held command returned) and recovery after them."""
    mech = _random_mechanism(3)
    module = codegen.build(codegen.generate(mech, frames=[]), cache_dir=tmp_path)
    n, ticks = mech.dof, 2000
    rng = np.random.default_rng(0)
    q, v = rng.uniform(-1.5, 1.5, (ticks, n)), rng.uniform(-2, 2, (ticks, n))
    q_des, v_des, a_des = q + rng.normal(0, 0.05, (ticks, n)), v + rng.normal(0, 0.1, (ticks, n)), rng.normal(0, 3, (ticks, n))
    q[100:110, 1] = np.nan
    v_des[300:305, 0] = np.inf
    q[700:720, 2] = 5.0  # beyond max_position
    a_des[900:905] = 1e308  # overflows the outer loop
    kp, kd = rng.uniform(50, 150, n), rng.uniform(5, 20, n)
    limit = np.full(n, np.inf)
    limit[0] = 5.0  # saturates on some ticks
    options = dict(max_position=4.0, max_speed=np.inf, max_acceleration=np.inf)
    tau, status = module.computed_torque_run(q, v, q_des, v_des, a_des, kp=kp, kd=kd, torque_limit=limit, **options)
    ct = _core.ComputedTorque(_core.MechanismDynamics(mech.model), kp, kd, limit, **options)
    ref = ct.run(q, v, q_des, v_des, a_des)
    assert np.array_equal(status, np.asarray(ref["status"], dtype=np.int64))
    assert _rel(tau, ref["joint_torque"]) < 1e-12
    kinds = set(int(x) for x in status)
    assert {0, int(_core.Status.saturated), int(_core.Status.non_finite_input), int(_core.Status.out_of_range)} <= kinds
    # a held command is the last good one, and the tick after bad input recovers
    assert np.array_equal(tau[105], tau[99]) and status[110] in (0, int(_core.Status.saturated))


# ---- closed loops --------------------------------------------------------------------------------
def _closed_case(name: str):
    from mechbal.balance.run import balance_case

    bc = balance_case(name)
    guess = np.asarray(bc.q_guess, float) if bc.q_guess is not None else np.zeros(bc.mechanism.dof)
    return bc.mechanism, [np.asarray(x, float) for x in bc.motion[:3]], guess


def _closed_graph(mech):
    tc = cg_tree.tree_constants(mech)
    g = Graph()
    n, na = tc.dof, len(tc.actuated)
    Q = [g.input(f"q{i}") for i in range(n)]
    VA, AA = ([g.input(f"{k}{i}") for i in range(na)] for k in ("va", "aa"))
    W = [g.input(f"w{i}") for i in range(n)]
    v, a = cg_tree.closed_projection(g, tc, Q, VA, AA, W)
    F, M = cg_tree.shaking_wrench(g, tc, Q, v, a)
    return g, tc, (v, a, F, M)


def _closed_inputs(tc, q, va, aa):
    return {**{f"q{i}": q[i] for i in range(tc.dof)}, **{f"va{i}": va[i] for i in range(len(va))},
            **{f"aa{i}": aa[i] for i in range(len(aa))}, **{f"w{i}": 0.0 for i in range(tc.dof)}}


def _random_loops_mechanism(seed: int, kind: str) -> mechbal.Mechanism:
    """A random tree (revolute, prismatic, fixed joints and gears) with two loop closures of
    `kind` between frames placed at random on random links (they need not close: the velocity
    products are derivatives of the closure equations wherever they are taken)."""
    rng = np.random.default_rng(seed)
    mech = random_tree(rng, 7, types="RRRPF", mimic=True).mechanism()
    d = mech.model.description
    links = [j.name for j in d.joints]
    frames, loops = [], []
    for k in range(2):
        la, lb = rng.choice(links, 2, replace=False)
        names = []
        for side, link in (("a", la), ("b", lb)):
            T = np.eye(4)
            T[:3, :3] = np.linalg.qr(rng.normal(size=(3, 3)))[0]
            if np.linalg.det(T[:3, :3]) < 0:
                T[:3, 0] *= -1.0
            T[:3, 3] = rng.uniform(-0.3, 0.3, 3)
            frames.append(_core.Frame(f"l{k}_{side}", str(link), T))
            names.append(f"l{k}_{side}")
        loops.append(_core.LoopConstraint(f"l{k}", getattr(_core.LoopType, kind), *names))
    return mechbal.Mechanism.from_description(d.joints, d.bodies, frames, mech.model.gravity, loops=loops,
                                              actuated=list(mech.model.coordinate_names[:2]))


@pytest.mark.parametrize("kind", ["point", "planar_point", "axis", "weld"])
def test_closure_velocity_products_are_the_second_derivative(kind):
    """gamma from the links' velocity-product accelerations (the generated projection's path)
    against the closure equations differentiated twice by forward mode on the graph, at random
    states of random trees with prismatic joints, gears and fixed joints."""
    for seed in range(4):
        try:
            mech = _random_loops_mechanism(100 + seed, kind)
        except ValueError as exc:  # a random closure the model cannot take (e.g. too few passive)
            pytest.skip(str(exc))
        tc = cg_tree.tree_constants(mech)
        g = Graph()
        n = tc.dof
        Q, V, W = ([g.input(f"{k}{i}") for i in range(n)] for k in "qvw")
        phi = cg_tree.loop_residual(g, tc, Q)
        seeds = {Q[k].id: W[k] for k in range(n)}
        twice = directional_derivative(g, directional_derivative(g, phi, seeds), seeds)
        fast = cg_tree.loop_velocity_product(g, tc, cg_tree.Kinematics(g, tc, Q), V)
        rng = np.random.default_rng(seed)
        for _ in range(3):
            q, v = rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)
            inputs = {**{f"q{i}": q[i] for i in range(n)}, **{f"v{i}": v[i] for i in range(n)},
                      **{f"w{i}": v[i] for i in range(n)}}
            ref, ours = (np.array(x, float) for x in g.evaluate([twice, fast], inputs))
            assert len(ours) == len(phi) and _rel(ours, ref) < 1e-12, (seed, ours, ref)
            assert np.abs(ref).max() > 1e-3  # not a vacuous comparison


@pytest.mark.parametrize("case", ["four-bar", "five-bar", "paminsa", "rpsp", "orthoglide"])
def test_closed_projection_graph_matches_the_library(case):
    """v = C v#, a = C a# + c and the shaking wrench of every built-in closed case, from the
    generator's graph (closure equations differentiated on the graph, unrolled LDL^T), against
    the library's coupling-matrix method along the case's own motion."""
    mech, (Qa, Va, Aa), q = _closed_case(case)
    g, tc, outputs = _closed_graph(mech)
    worst = 0.0
    for k in range(0, len(Qa), max(1, len(Qa) // 6)):
        cm = mech.closed_motion(Qa[k], Va[k], Aa[k], q_guess=q)
        assert cm.status == 0
        q = cm.q
        v, a, F, M = (np.array(x) for x in g.evaluate(list(outputs), _closed_inputs(tc, cm.q, Va[k], Aa[k])))
        sw = mech.shaking_wrench(cm.q, cm.v, cm.a)
        worst = max(worst, _rel(v, cm.v), _rel(a, cm.a), _rel(F, sw.shaking_force), _rel(M, sw.shaking_moment))
    # the library's own error on PAMINSA and the RPSP is a few 1e-13 (see the 40-digit test below)
    assert worst < 2e-12, worst


@needs_compiler
def test_generated_closed_tick_is_exact_to_a_40_digit_evaluation(tmp_path):
    """The generated PAMINSA tick against the same equations evaluated with 40 digits (mpmath):
    within 1e-13, where the library is within a few 1e-13 (its normal equations lose the square of
    A°'s condition); and against the library to 2e-12 along the motion, warm-started tick to tick."""
    mp = pytest.importorskip("mpmath")
    from mechbal.codegen.expr import Sym

    mech, (Qa, Va, Aa), q = _closed_case("paminsa")
    module = codegen.build(codegen.generate(mech, frames=[]), cache_dir=tmp_path)
    g, tc, outputs = _closed_graph(mech)
    flat = [x for part in outputs for x in part]
    ops = {"add": lambda a, b: a + b, "sub": lambda a, b: a - b, "mul": lambda a, b: a * b,
           "div": lambda a, b: a / b, "neg": lambda a: -a, "sin": mp.sin, "cos": mp.cos, "sqrt": mp.sqrt}
    mp.mp.dps = 40
    for k in range(0, len(Qa), len(Qa) // 3):
        cm = mech.closed_motion(Qa[k], Va[k], Aa[k], q_guess=q)
        q = cm.q
        inputs = _closed_inputs(tc, cm.q, Va[k], Aa[k])
        values = []
        for node in g.nodes:
            if node[0] == "in":
                values.append(mp.mpf(inputs[node[1]]))
            else:
                values.append(ops[node[0]](*[values[x.id] if isinstance(x, Sym) else mp.mpf(float(x)) for x in node[1:]]))
        ref = np.array([float(values[x.id]) if isinstance(x, Sym) else float(x) for x in flat])
        n = tc.dof
        gq, gv, ga, status = module.closed_motion(Qa[k], Va[k], Aa[k], cm.q)
        assert status == 0 and _rel(gq, cm.q) < 1e-13
        gF, gM = module.shaking_wrench(gq, gv, ga)
        ours = np.concatenate([gv, ga, gF, gM])
        assert _rel(ours[:n], ref[:n]) < 1e-13 and _rel(ours[n:2 * n], ref[n:2 * n]) < 1e-13
        assert _rel(ours[2 * n:2 * n + 3], ref[2 * n:2 * n + 3]) < 1e-13
        assert _rel(ours[2 * n + 3:], ref[2 * n + 3:]) < 1e-13
    # closed_tick along the motion, forward then backward (its warm start moves the last solution
    # by the time step the actuated motion implies, so a motion run backwards predicts as well)
    order = np.r_[np.arange(len(Qa)), np.arange(len(Qa) - 1, -1, -1)]
    F, M, Q, status = module.closed_ticks(Qa[order], Va[order], Aa[order], _closed_case("paminsa")[2])
    assert np.all(status == 0)
    q = np.asarray(_closed_case("paminsa")[2])
    for j in range(0, len(order), 37):
        k = order[j]
        cm = mech.closed_motion(Qa[k], Va[k], Aa[k], q_guess=Q[j])
        sw = mech.shaking_wrench(cm.q, cm.v, cm.a)
        assert _rel(Q[j], cm.q) < 1e-12 and _rel(F[j], sw.shaking_force) < 2e-12
        assert _rel(M[j], sw.shaking_moment) < 2e-12
    # tick to tick along the whole motion, each warm-started from the last
    worst = 0.0
    for k in range(len(Qa)):
        F, M, q_next, status = module.closed_shaking_wrench(Qa[k], Va[k], Aa[k], q)
        cm = mech.closed_motion(Qa[k], Va[k], Aa[k], q_guess=q)
        sw = mech.shaking_wrench(cm.q, cm.v, cm.a)
        assert status == 0
        worst = max(worst, _rel(F, sw.shaking_force), _rel(M, sw.shaking_moment), _rel(q_next, cm.q))
        q = q_next
    # the 40-digit comparison above bounds the generated error at 1e-13: what remains here is the
    # library's own (its normal equations lose the square of A°'s condition, up to 2e-12 on M)
    assert worst < 5e-12, worst


@needs_compiler
@pytest.mark.parametrize("case", ["four-bar", "five-bar", "rpsp"])
def test_generated_closed_inverse_dynamics_matches_the_library(case, tmp_path):
    """The actuated forces tau# = C^T tau of the generated closed inverse dynamics against the
    library's closed_motion(with_forces=True) along the case's motion, warm-started tick to tick."""
    mech, (Qa, Va, Aa), q = _closed_case(case)
    module = codegen.build(codegen.generate(mech, frames=[]), cache_dir=tmp_path)
    worst, scale = 0.0, 0.0
    for k in range(0, len(Qa), max(1, len(Qa) // 25)):
        tau, q_next, status = module.closed_inverse_dynamics(Qa[k], Va[k], Aa[k], q)
        cm = mech.closed_motion(Qa[k], Va[k], Aa[k], q_guess=q, with_forces=True)
        assert status == 0 and cm.status == 0
        worst = max(worst, _rel(tau, cm.actuated_force), _rel(q_next, cm.q))
        scale = max(scale, float(np.abs(cm.actuated_force).max()))
        q = q_next
    assert worst < 1e-11 and scale > 1e-3, (worst, scale)


@needs_compiler
def test_generated_closed_tick_reports_what_it_could_not_do(tmp_path):
    mech, (Qa, Va, Aa), q = _closed_case("four-bar")
    module = codegen.build(codegen.generate(mech, frames=[]), cache_dir=tmp_path)
    cm = mech.closed_motion(Qa[10], Va[10], Aa[10], q_guess=q)
    far = cm.q.copy()
    far[module.code.passive] += 0.3
    # no Newton step allowed from a pose that does not close: refused, nothing written
    q_out, v, a, status = module.closed_motion(Qa[10], Va[10], Aa[10], far, max_iterations=0)
    assert status == 1 and np.array_equal(q_out, far) and not v.any()
    # the same pose with the default bound closes to the library's solution
    q_out, v, a, status = module.closed_motion(Qa[10], Va[10], Aa[10], far)
    assert status == 0 and _rel(q_out, cm.q) < 1e-12 and _rel(v, cm.v) < 1e-12
    # a non-finite input is a status, not a NaN result
    bad = np.array(Qa[10])
    bad[0] = np.nan
    q_out, v, a, status = module.closed_motion(bad, Va[10], Aa[10], cm.q)
    assert status == 2 and np.array_equal(q_out, cm.q)
