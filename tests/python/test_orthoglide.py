"""Orthoglide 5-axis (Martini, Troncossi, Carricato & Rivola 2015) on the general model: the loop
solve against eq 1, the spring rates against eqs 18-19, static balance and potential-energy
invariance over the workspace, the closed-loop inverse dynamics against the virtual-power balance
and the platform's Newton equations, the catalogue selection against Tables 1-2."""
import copy
import json
import math

import numpy as np
import pytest

from mechbal.balance.springs import load_catalogue, select_springs
from mechbal.papers.orthoglide import runner as og
from mechbal.config import ConfigError, read_case
from mechbal.papers import orthoglide as paper
from mechbal.schema import validate_case


@pytest.fixture(scope="module")
def raw():
    return read_case("orthoglide")


@pytest.fixture(scope="module")
def case(raw):
    return validate_case(raw)


@pytest.fixture(scope="module")
def machine(case):
    return og.Orthoglide(case)


@pytest.fixture(scope="module")
def grid(case):
    return og.workspace_grid(case.workspace.center, case.workspace.edge, 5)


@pytest.fixture(scope="module")
def rates(machine, grid):
    return machine.size_rates(grid)[0]


@pytest.fixture(scope="module")
def lumped(machine, case):
    return machine.lumped(case.workspace.center)


def test_loop_solve_reproduces_linear_delta_ik(machine, case):
    rng = np.random.default_rng(3)
    c, h = np.asarray(case.workspace.center), case.workspace.edge / 2
    p = c + rng.uniform(-h, h, (40, 3))
    v, a = rng.normal(size=(40, 3)), rng.normal(size=(40, 3))
    m, C, rho, rho_d, rho_dd = machine.solve(p, v, a)   # raises when P misses the path by 1e-9 m
    P = machine.mech.frame_placement(m.q, "P")[:, :3, 3]
    assert np.max(np.abs(P - p)) < 1e-12
    bm = machine.mech.body_motion(m.q, m.v, m.a)
    k = machine.mech.body_names.index(case.roles.platform_body)
    assert np.max(np.abs(bm.com_velocity[:, k] - v)) < 1e-9
    assert np.max(np.abs(bm.com_acceleration[:, k] - a)) < 1e-8
    # eq 1: each leg keeps its length L between O_j (on the axis, at rho_j) and D_j
    for j in (1, 2, 3):
        O = machine.mech.frame_placement(m.q, f"O{j}")[:, :3, 3]
        D = machine.mech.frame_placement(m.q, f"D{j}")[:, :3, 3]
        assert np.allclose(O[:, j - 1], rho[:, j - 1], atol=1e-12)
        assert np.allclose(np.linalg.norm(D - O, axis=1), machine.L, atol=1e-12)
    # the coupling matrix: v = C v#
    assert np.max(np.abs(np.einsum("nda,na->nd", C, rho_d) - m.v)) < 1e-9


def test_rates_by_least_squares_are_eqs_18_19(machine, grid, rates, lumped, case):
    K_D = paper.distal_rate(lumped.m_p, lumped.g, lumped.delta_y)
    K_P = paper.proximal_rate(lumped.m_p, lumped.m_s2, lumped.m_w, lumped.m_t, lumped.g, lumped.eps_y)
    assert rates[case.roles.distal_spring] == pytest.approx(K_D, rel=1e-12)
    assert rates[case.roles.proximal_spring] == pytest.approx(K_P, rel=1e-12)
    # the case's parameters are consistent with Table 1 (theoretical row, printed to 3 decimals)
    t1 = paper.PAPER_TABLE1["theoretical"]
    assert round(K_D / 1e3, 3) == t1["K_D_N_per_mm"] and round(K_P / 1e3, 3) == t1["K_P_N_per_mm"]
    assert lumped.delta_y * 1e3 == pytest.approx(t1["delta_y_mm"]) and lumped.eps_y * 1e3 == pytest.approx(t1["eps_y_mm"])


def test_static_balance_and_constant_potential_energy(machine, grid, rates, lumped, case):
    springs = machine.springs(rates)
    assert np.max(np.abs(machine.static_forces(grid, springs))) < 1e-9
    V = machine.potential_energy(grid, springs)
    assert np.ptp(V) < 1e-9
    # eqs 5, 6, 9, 10 give the same energy up to a constant, balanced or not
    for K in (rates, {n: 0.0 for n in rates}, {n: 0.7 * k for n, k in rates.items()}):
        V_gen = machine.potential_energy(grid, machine.springs(K))
        V_cf = paper.potential_energy(lumped, grid, K[case.roles.distal_spring], K[case.roles.proximal_spring])
        assert np.ptp(V_gen - V_cf) < 1e-9
    # unbalanced: the vertical motor carries the weights (mean near (m_p + m_s2 + m_w + m_t/2) g)
    F = machine.static_forces(grid, machine.springs({n: 0.0 for n in rates}))
    w = (lumped.m_p + lumped.m_s2 + lumped.m_w + lumped.m_t / 2) * lumped.g
    assert abs(np.mean(F[:, 1]) - w) < 0.05 * w


def test_static_forces_are_the_potential_gradient(machine, case, rates):
    """C^T (G + K) = dV/drho by central differences along each slider, V the model's potential
    energy with its springs (at 0.6 of their balancing rates, so nothing cancels)."""
    K = {n: 0.6 * k for n, k in rates.items()}
    springs = machine.springs(K)
    sprung = machine.with_springs(springs)
    assert sorted(sprung.spring_names) == sorted(rates)
    p0 = np.asarray(case.workspace.center) + np.array([0.05, -0.1, 0.08])
    F = machine.static_forces(p0[None], springs)[0]
    m, *_ = machine.solve(p0[None], with_coupling=False)
    rho0 = machine.rho(p0[None])[0]
    h = 1e-5
    for j in range(3):
        V = []
        for s in (+1, -1):
            rho = rho0.copy()
            rho[j] += s * h
            mm = sprung.closed_motion(rho, q_guess=m.q[0], tolerance=og.CLOSURE_TOLERANCE)
            V.append(sprung.potential_energy(mm.q))
        assert F[j] == pytest.approx((V[0] - V[1]) / (2 * h), rel=1e-6, abs=1e-5)


def test_model_springs_are_the_papers_springs(machine, case, rates, lumped, grid):
    """The springs on the model (lengths, tensions, energies) against the paper's zero-free-length
    springs on the lumped model's points (eqs 6, 10: A = O_2 + a, B = P + b, N_1 = O_2 + n_1,
    N_2 = S + n_2, V = K |r|^2 / 2), and the spring torque against finite differences of the
    spring energy in the full coordinates."""
    springs = machine.springs(rates)
    sprung = machine.with_springs(springs)
    m, *_ = machine.solve(grid, with_coupling=False)
    rho = machine.rho(grid)
    O2 = np.stack([np.zeros(len(grid)), rho[:, 1], np.zeros(len(grid))], 1)
    S = lumped.support_kinematics(rho[:, 1])
    d_paper = {case.roles.distal_spring: np.linalg.norm(grid + lumped.b - (O2 + lumped.a), axis=1),
               case.roles.proximal_spring: np.linalg.norm(O2 + lumped.n1 - (S + lumped.n2), axis=1)}
    d = sprung.spring_lengths(m.q)
    T = sprung.spring_tension(m.q)
    for k, name in enumerate(sprung.spring_names):
        assert np.max(np.abs(d[:, k] - d_paper[name])) < 1e-12
        assert np.max(np.abs(T[:, k] - rates[name] * d_paper[name])) < 1e-8
    E = sprung.spring_energy(m.q)
    E_paper = sum(0.5 * rates[n] * d_paper[n] ** 2 for n in d_paper)
    assert np.max(np.abs(E - E_paper)) < 1e-8
    # the springs' joint forces are the gradient of their energy (full tree coordinates)
    q0, h = m.q[7], 1e-6
    K0 = sprung.spring_torque(q0)
    for i in range(sprung.dof):
        dq = np.zeros(sprung.dof)
        dq[i] = h
        fd = (sprung.spring_energy(q0 + dq) - sprung.spring_energy(q0 - dq)) / (2 * h)
        assert K0[i] == pytest.approx(fd, rel=1e-6, abs=1e-4)


def test_published_spring_numbers_through_the_model(machine, case, grid):
    """The runner's published Table 1 (theoretical row) from the general spring method with the
    springs on the model: rates 2.510052 / 11.130577 N/mm (eqs 18-19) and the peak cable forces
    2321.80 / 4471.77 N (the model's tension at the largest anchor distance over the cube)."""
    result = machine.size(grid)
    assert result.exact and result.rank == 2 and result.residual < 1e-9
    assert result.balanced.spring_names == [s.name for s in case.springs]
    published = {case.roles.distal_spring: (2.510052, 2321.798099958), case.roles.proximal_spring: (11.130576923, 4471.771447237)}
    for name, (rate, peak) in published.items():
        assert result.design[name].rate / 1e3 == pytest.approx(rate, rel=1e-9)
        d, where = og.peak_distance(machine, name, grid, case.workspace.center, case.workspace.edge)
        sprung = machine.with_springs(machine.springs({n: v.rate for n, v in result.design.items()}))
        m, *_ = machine.solve(np.asarray(where)[None], with_coupling=False)
        tension = sprung.spring_tension(m.q)[0, sprung.spring_names.index(name)]
        assert tension == pytest.approx(peak, rel=1e-6)
    # the potential energy of the balanced model is constant (the method's own metric)
    assert result.metrics["potential_energy_variation_after"] < 1e-9


def _short_paths(case, dt=0.01):
    ws, pp, mc = case.workspace, case.paths, case.machining
    pockets = [{"corner": pk.corner, "size": pk.size} for pk in mc.pockets]
    yield paper.helix_path(ws.center, ws.edge, pp.helix_radius, pp.helix_speeds[-1], pp.helix_vertical_ratio,
                           pp.helix_acceleration, dt)
    yield paper.cube_path(ws.center, ws.edge, pp.cube_speeds[-1], pp.max_acceleration, dt)
    for task in mc.tasks:
        yield paper.machining_path(ws.center, task.operation, task.feed, task.force, pockets[:1], mc.holes[:1],
                                   mc.drill_depth, mc.approach_height, pp.rapid_speed, pp.max_acceleration, 2 * dt,
                                   task.name)


def test_inverse_dynamics_virtual_power_and_newton(machine, case, rates, lumped):
    K_D, K_P = rates[case.roles.distal_spring], rates[case.roles.proximal_spring]
    for path in _short_paths(case):
        for K in ({n: 0.0 for n in rates}, rates):
            r = machine.dynamics(path, machine.springs(K))
            assert r["power_balance_error"] < 1e-9, path.name
            kd, kp = K[case.roles.distal_spring], K[case.roles.proximal_spring]
            cf = paper.inverse_dynamics(lumped, path.p, path.v, path.a, path.f_cut, kd, kp)["motor_force"]
            scale = np.max(np.abs(r["motor_force"]))
            assert np.max(np.abs(cf - r["motor_force"])) < 1e-9 * scale, path.name
        if path.cutting.any():
            # cutting forces follow the feed: the cutting power is never positive
            assert np.all(np.einsum("nk,nk->n", path.f_cut, path.v) <= 1e-12)
    assert K_D > 0 and K_P > 0


def test_paths_are_smooth_and_within_limits(case):
    ws, pp = case.workspace, case.paths
    lo, hi = np.asarray(ws.center) - ws.edge / 2 - 1e-12, np.asarray(ws.center) + ws.edge / 2 + 1e-12
    for path in _short_paths(case, dt=5e-4):
        assert np.all(path.p >= lo) and np.all(path.p <= hi), path.name
        assert np.allclose(path.v[[0, -1]], 0) and np.allclose(path.a[[0, -1]], 0, atol=1e-9)
        dt = np.diff(path.t)[:, None]
        # velocities and accelerations integrate to positions and velocities (trapezoid rule, step by step)
        assert np.max(np.abs((path.v[1:] + path.v[:-1]) / 2 * dt - np.diff(path.p, axis=0))) < 1e-6, path.name
        assert np.max(np.abs((path.a[1:] + path.a[:-1]) / 2 * dt - np.diff(path.v, axis=0))) < 1e-3, path.name
    helix = paper.helix_path(ws.center, ws.edge, pp.helix_radius, 0.8, pp.helix_vertical_ratio, pp.helix_acceleration,
                             0.005)
    speed_h = np.linalg.norm(helix.v[:, [0, 2]], axis=1)
    assert np.max(speed_h) == pytest.approx(0.8, rel=1e-9)
    assert np.max(helix.v[:, 1]) == pytest.approx(0.8 * pp.helix_vertical_ratio, rel=1e-9)


def test_catalogue_selection_reproduces_tables_1_2(machine, grid, rates, lumped, case):
    t1, t2 = paper.PAPER_TABLE1, paper.PAPER_TABLE2
    for name, offset, key in ((case.roles.distal_spring, lumped.delta_y, "distal"),
                              (case.roles.proximal_spring, lumped.eps_y, "proximal")):
        d, _ = og.peak_distance(machine, name, grid, case.workspace.center, case.workspace.edge)
        best = select_springs(rates[name], rates[name] * d, anchor_offset=offset)[0]
        assert best.count == t2[key]["count"] and best.moving_pulleys == t2[key]["moving_pulleys"]
        assert best.spring.rate / 1e3 == pytest.approx(t2[key]["spring_rate_N_per_mm"])
        assert best.equivalent_rate * best.anchor_offset == pytest.approx(rates[name] * offset, rel=1e-12)
        letter = "D" if key == "distal" else "P"
        assert best.equivalent_rate / 1e3 == pytest.approx(t1["off_the_shelf"][f"K_{letter}_N_per_mm"], abs=5e-4)
        # the peak cable force of the chosen geometry is Table 1's to 0.1 %
        assert rates[name] * d == pytest.approx(t1["theoretical"][f"f_{letter}_max"], rel=1e-3)
    with pytest.raises(ValueError, match="rate_N_per_mm"):
        load_catalogue(__file__)


def test_sensitivity_of_the_vertical_loads(machine, grid, rates, lumped, case):
    """10 % on m_s2 or on K_P leaves a constant load on the vertical motor only: 0.1 m_s2 g and
    0.1 K_P eps_y / 2 (Table 6's 27 N and 72 N, under swapped column labels in the paper)."""
    name = case.roles.vertical_slider_body
    o = og.Orthoglide(case, masses={name: lumped.m_s2 * 1.1})
    F = o.static_forces(grid, o.springs(rates))
    assert np.allclose(F[:, 1], -0.1 * lumped.m_s2 * lumped.g, atol=1e-8) or \
        np.allclose(F[:, 1], 0.1 * lumped.m_s2 * lumped.g, atol=1e-8)
    assert np.max(np.abs(F[:, [0, 2]])) < 1e-9
    K = dict(rates)
    K[case.roles.proximal_spring] *= 1.1
    F = machine.static_forces(grid, machine.springs(K))
    assert np.allclose(np.abs(F[:, 1]), 0.1 * rates[case.roles.proximal_spring] * lumped.eps_y / 2, atol=1e-8)


def test_schema_is_strict(raw):
    bad = copy.deepcopy(raw)
    bad["roles"]["platfrom_body"] = bad["roles"].pop("platform_body")
    with pytest.raises(ConfigError, match="platfrom_body"):
        validate_case(bad)
    bad = copy.deepcopy(raw)
    bad["roles"]["distal_spring"] = "distle"
    with pytest.raises(ConfigError, match="did you mean 'distal'"):
        validate_case(bad)
    bad = copy.deepcopy(raw)
    bad["springs"][0]["link_b"] = "platfrom"
    with pytest.raises(ConfigError, match=r"springs\[0\]\.link_b"):
        validate_case(bad)


def test_run_writes_tables_and_files(raw, tmp_path):
    small = copy.deepcopy(raw)
    small["workspace"]["grid"] = 3
    small["paths"].update(sample_period=0.05, helix_speeds=[0.8], cube_speeds=[1.0])
    small["machining"]["tasks"] = small["machining"]["tasks"][-1:]
    small["machining"]["holes"] = small["machining"]["holes"][:1]
    (tmp_path / "out").mkdir()
    summary = og.run(small, tmp_path / "out")
    data = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert set(data["spring_rates_N_per_mm"]) == {"K_D", "K_P"}
    assert data["acceptance"]["static_motor_force_balanced_max"] < 1e-9
    assert data["acceptance"]["potential_energy_variation"] < 1e-9
    assert data["acceptance"]["power_balance_relative_error_max"] < 1e-9
    assert {"A1", "B1"} <= set(data["table4"]) and set(data["table5"]) == {"F"}
    assert data["table4"]["A1"]["y"]["delta_rms_pct"] < 0            # the vertical motor is relieved
    assert {"unbalanced", "m_p", "m_s2", "K_D", "K_P", "r_B"} <= set(data["table6"])
    assert data["clusters"]["distal"]["chosen"]["count"] >= 1
    for f in data["files"]:
        assert (tmp_path / "out" / f).is_file()
    assert summary["discrepancies"]
    assert math.isfinite(data["table1"]["off_the_shelf"]["K_D_N_per_mm"])


def test_table6_runs_through_the_sweep_api():
    """Issue 16's built-in Orthoglide example: Table 6 as a mechbal.sweep sensitivity sweep equals
    the static loads computed directly with the changed mass, rate or anchor."""
    import numpy as np

    from mechbal.papers.orthoglide import runner as og
    from mechbal.config import case_path, read_toml
    from mechbal.schema import validate_case

    case = validate_case(read_toml(case_path("orthoglide")), warn=False)
    grid = og.workspace_grid(case.workspace.center, case.workspace.edge, 3)
    nominal = og.Orthoglide(case)
    rates, *_ = nominal.size_rates(grid)
    table = og.table6_sweep(case, rates=rates, grid=grid).run("serial").table
    rel, roles = case.sensitivity.relative, case.roles

    def row(parameter, level, column):
        t = table[(table["parameter"] == parameter) & (table["level"] == level)]
        return float(t[column].iloc[0])

    # K_P +rel: the nominal machine with the proximal rate changed
    sprs = nominal.springs({**rates, roles.proximal_spring: rates[roles.proximal_spring] * (1 + rel)})
    direct = og.static_stats(nominal.static_forces(grid, sprs))
    assert row("design.K_P", "high", "static_loads.y_rms") == pytest.approx(direct["y"]["rms"], rel=1e-9)
    # m_p +rel: the machine rebuilt with a heavier platform
    m_p = next(b.mass for b in nominal.mech.bodies if b.name == roles.platform_body)
    heavy = og.Orthoglide(case, masses={roles.platform_body: m_p * (1 + rel)})
    direct = og.static_stats(heavy.static_forces(grid, heavy.springs(rates)))
    for ax in "xyz":
        assert row(f"bodies.{roles.platform_body}.mass", "high", f"static_loads.{ax}_max") == \
            pytest.approx(direct[ax]["max"], rel=1e-9, abs=1e-9)
    # the balanced nominal machine carries no static load
    assert max(row("nominal", "nominal", f"static_loads.{ax}_max") for ax in "xyz") < 1e-9
    assert (table["status"] == "ok").all()
