"""The Orthoglide 5-axis of Martini, Troncossi, Carricato & Rivola 2015 ("Static balancing of a
parallel kinematics machine with Linear-Delta architecture", Mech. Mach. Theory 90:128-141): the
paper's closed forms, kept as **checks** of the general path (the mechanism itself is data:
``python/mechbal/papers/orthoglide/cases/orthoglide.toml``; the runner is `mechbal.papers.orthoglide.runner`).

Frame of the paper: y vertical, gravity (0, -g, 0). Here:

* `linear_delta_ik` - eq 1 (with its typo corrected: the right-hand sides are the platform
  point's coordinates p, not the slider positions rho), with its time derivatives;
* `distal_rate`, `proximal_rate` - eqs 18-19;
* `LumpedModel` and `lumped_model` - **the paper's model**, a deliberate
  approximation of Section 3 (massless legs and links, lumped masses on the platform, the sliders
  and the spring support), its parameters *measured* on the general model (lengths between its
  named frames, masses of its bodies), so that the closed forms check the model the case file
  describes;
* `potential_energy` - eqs 5, 6, 9, 10 on the lumped model (total, for any rates): checks
  the general model's potential energy with its springs (``Mechanism.potential_energy``);
* `inverse_dynamics` - motor forces of the lumped model from the platform's Newton equation
  with the leg forces along the parallelogram directions, the sliders' and the spring support's
  Newton equations (an independent computation of what the general closed-loop inverse dynamics,
  springs on the model, gives);
* `rest_to_rest`, `helix_path`, `cube_path`, `machining_path` - the
  simulated trajectories of Section 5.1 (Paths A-F) and the cutting-force model;
* ``PAPER_*`` - the paper's published numbers (Tables 1, 2, 4, 5, 6), for comparison only.

The springs themselves are elements of the general model and are sized by the general method
(`mechbal.balance.springs`: ``balance``, ``select_springs`` for Tables 1-2); the runner
`mechbal.papers.orthoglide.runner` uses them, and these closed forms are its fast-path checks.

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

__all__ = ["linear_delta_ik", "distal_rate", "proximal_rate", "LumpedModel", "lumped_model",
           "potential_energy", "inverse_dynamics", "rest_to_rest", "PlatformPath", "helix_path", "cube_path", "machining_path",
           "PAPER_TABLE1", "PAPER_TABLE2", "PAPER_TABLE4", "PAPER_TABLE5", "PAPER_TABLE6"]

# ---- the paper's published numbers (for comparison only) ----------------------------------------
#: Table 1: theoretical and off-the-shelf balancing parameters (mm, N/mm, N)
PAPER_TABLE1 = {
    "theoretical": {"delta_y_mm": 150.00, "K_D_N_per_mm": 2.510, "f_D_max": 2321,
                    "eps_y_mm": 130.00, "K_P_N_per_mm": 11.131, "f_P_max": 4470},
    "off_the_shelf": {"delta_y_mm": 150.30, "K_D_N_per_mm": 2.505, "f_D_max": 2318,
                      "eps_y_mm": 131.52, "K_P_N_per_mm": 11.002, "f_P_max": 4424},
}
#: Table 2: the clusters
PAPER_TABLE2 = {
    "distal": {"spring_rate_N_per_mm": 5.009, "spring_max_force": 1159, "count": 8, "moving_pulleys": 2,
               "total_spring_mass": 8.087},
    "proximal": {"spring_rate_N_per_mm": 5.501, "spring_max_force": 1105, "count": 8, "moving_pulleys": 1,
                 "total_spring_mass": 8.450},
}


def _axes(rows):
    return {ax: dict(zip(("rms_un", "rms_sb", "delta_rms_pct", "max_un", "max_sb", "delta_max_pct"), r))
            for ax, r in zip("xyz", rows)}


#: Table 4 (Paths A, B; profiles #1, #2): rms and max motor force [N] per axis, % change; overall rms
PAPER_TABLE4 = {
    "A1": {**_axes([(56, 96, 72, 150, 190, 26), (743, 87, -88, 1887, 1070, -43), (83, 99, 19, 264, 405, 53)]),
           "total_rms": {"un": 882, "sb": 283, "delta_pct": -68}},
    "A2": {**_axes([(148, 214, 45, 341, 427, 25), (743, 114, -85, 1834, 1016, -45),
                    (163, 222, 36, 436, 578, 33)]),
           "total_rms": {"un": 1054, "sb": 550, "delta_pct": -48}},
    "B1": {**_axes([(267, 296, 11, 1189, 1368, 15), (843, 342, -59, 2188, 1565, -28),
                    (266, 297, 12, 1189, 1368, 15)]),
           "total_rms": {"un": 1375, "sb": 935, "delta_pct": -32}},
    "B2": {**_axes([(309, 347, 12, 1172, 1347, 15), (861, 401, -53, 2165, 1537, -29),
                    (308, 348, 13, 1172, 1347, 15)]),
           "total_rms": {"un": 1477, "sb": 1095, "delta_pct": -26}},
}
#: Table 5 (Paths C-F)
PAPER_TABLE5 = {
    "C": {**_axes([(569, 574, 1, 1014, 1142, 13), (813, 326, -60, 1719, 997, -42), (765, 758, -1, 1381, 1216, -12)]),
          "total_rms": {"un": 2148, "sb": 1659, "delta_pct": -23}},
    "D": {**_axes([(134, 131, -2, 863, 858, -1), (777, 159, -80, 1719, 946, -45), (197, 157, -21, 867, 861, -1)]),
          "total_rms": {"un": 1108, "sb": 447, "delta_pct": -60}},
    "E": {**_axes([(159, 154, -3, 863, 857, -1), (771, 220, -71, 1744, 973, -44), (193, 181, -6, 869, 880, 1)]),
          "total_rms": {"un": 1123, "sb": 555, "delta_pct": -51}},
    "F": {**_axes([(206, 208, 1, 1021, 947, -7), (627, 355, -43, 1768, 1029, -42), (136, 139, 2, 977, 940, -4)]),
          "total_rms": {"un": 970, "sb": 702, "delta_pct": -28}},
}
#: Table 6: static motor loads [N] over the workspace, unbalanced and balanced with one parameter
#: changed (+10 % or +5 mm; the paper finds the same magnitudes for -)
PAPER_TABLE6 = {
    "unbalanced": {"x": {"rms": 88, "max": 243}, "y": {"rms": 728, "max": 907}, "z": {"rms": 88, "max": 243}},
    "m_p": {"x": {"rms": 9, "max": 24}, "y": {"rms": 3, "max": 19}, "z": {"rms": 9, "max": 24}},
    "m_s2": {"x": {"rms": 0, "max": 0}, "y": {"rms": 72, "max": 72}, "z": {"rms": 0, "max": 0}},
    "K_D": {"x": {"rms": 3, "max": 8}, "y": {"rms": 13, "max": 19}, "z": {"rms": 3, "max": 8}},
    "K_P": {"x": {"rms": 0, "max": 0}, "y": {"rms": 27, "max": 27}, "z": {"rms": 0, "max": 0}},
    "r_B": {"x": {"rms": 16, "max": 31}, "y": {"rms": 7, "max": 19}, "z": {"rms": 16, "max": 31}},
}


# ---- eq 1 -------------------------------------------------------------------------------------------
def linear_delta_ik(p, L: float, delta, v=None, a=None):
    """Slider positions rho = (rho_x, rho_y, rho_z) of the Linear-Delta for the platform point P =
    p (eq 1): rho_x = p_x + Delta_x + sqrt(L^2 - p_y^2 - p_z^2), and cyclically. The printed eq 1
    writes rho on both sides; the right-hand side is P's coordinates. ``delta``: (Delta_x,
    Delta_y, Delta_z), the offsets of D_j from P along each axis. With ``v`` and ``a`` (P's
    velocity and acceleration) also returns rho' and rho''. Arrays (..., 3)."""
    p = np.asarray(p, float)
    delta = np.broadcast_to(np.asarray(delta, float), p.shape)
    rho = np.empty_like(p)
    rho_d = np.empty_like(p) if v is not None else None
    rho_dd = np.empty_like(p) if a is not None else None
    for j in range(3):
        k, m = [i for i in range(3) if i != j]
        s = np.sqrt(L * L - p[..., k] ** 2 - p[..., m] ** 2)
        rho[..., j] = p[..., j] + delta[..., j] + s
        if v is not None:
            v = np.asarray(v, float)
            n = p[..., k] * v[..., k] + p[..., m] * v[..., m]
            rho_d[..., j] = v[..., j] - n / s
            if a is not None:
                a = np.asarray(a, float)
                n_d = v[..., k] ** 2 + v[..., m] ** 2 + p[..., k] * a[..., k] + p[..., m] * a[..., m]
                rho_dd[..., j] = a[..., j] - n_d / s - n * n / s ** 3
    if v is None:
        return rho
    return (rho, rho_d) if a is None else (rho, rho_d, rho_dd)


# ---- eqs 18-19 --------------------------------------------------------------------------------------
def distal_rate(m_p: float, g: float, delta_y: float) -> float:
    """K_D = m_p g / delta_y [N/m] (eq 18; eq 15 writes m_p g_y, the magnitude g is meant)."""
    return m_p * g / delta_y


def proximal_rate(m_p: float, m_s2: float, m_w: float, m_t: float, g: float, eps_y: float) -> float:
    """K_P = 2 (m_p + m_s2 + m_w + m_t / 2) g / eps_y [N/m] (eq 19)."""
    return 2.0 * (m_p + m_s2 + m_w + m_t / 2.0) * g / eps_y


# ---- the paper's lumped model of Section 3 (an approximation: massless legs, lumped masses),
# measured on the general model; checks of the general path, not a second model of the machine ----
@dataclass(frozen=True)
class LumpedModel:
    """Section 3's parameters in SI units and O's axes (y up). ``L`` leg length; ``delta`` (3, 3):
    row j = D_j - P; ``m_p``; ``m_slider`` (3,): all mass on slider j (m_sj, plus m_w on the
    vertical one); ``m_s2``, ``m_w`` separately; ``m_t`` on the spring support; ``g`` (>0);
    proximal device: base pivot ``V`` (3,), ``e`` (G_w - O_2 along y), ``Gw_offset`` (3,) =
    G_w - O_2, ``H``, ``q_t`` (3,) G_t - S; springs: ``a`` = A - O_2, ``b`` = B - P, ``n1`` = N_1 -
    O_2, ``n2`` = N_2 - S (each (3,)); delta_y = a_y - (b_y - Delta_y), eps_y = n2_y - (n1_y - e)."""

    L: float
    delta: np.ndarray
    m_p: float
    m_slider: np.ndarray
    m_s2: float
    m_w: float
    m_t: float
    g: float
    V: np.ndarray
    Gw_offset: np.ndarray
    H: float
    q_t: np.ndarray
    a: np.ndarray
    b: np.ndarray
    n1: np.ndarray
    n2: np.ndarray

    @property
    def e(self) -> float:
        return float(self.Gw_offset[1])

    @property
    def delta_y(self) -> float:
        """a_y - b_y with b measured from D_2 (eq 17)."""
        return float(self.a[1] - (self.b[1] - self.delta[1, 1]))

    @property
    def eps_y(self) -> float:
        """n_2y - n_1y with n_1 measured from G_w (eq 17)."""
        return float(self.n2[1] - (self.n1[1] - self.e))

    def support_kinematics(self, rho_y, rho_y_d=None, rho_y_dd=None):
        """Support pivot S and its velocity and acceleration from eq 8, H s_gamma = (rho_y + e -
        v_y) / 2 (the branch cos(gamma) > 0)."""
        rho_y = np.asarray(rho_y, float)
        s = (rho_y + self.e - self.V[1]) / (2 * self.H)
        c = np.sqrt(1 - s * s)
        zero = np.zeros_like(rho_y)
        S = np.stack([self.V[0] + self.H * c, self.V[1] + self.H * s, self.V[2] + zero], -1)
        if rho_y_d is None:
            return S
        sd = np.asarray(rho_y_d, float) / (2 * self.H)
        sdd = (zero if rho_y_dd is None else np.asarray(rho_y_dd, float)) / (2 * self.H)
        cd = -s * sd / c
        cdd = -(sd * sd + s * sdd) / c - s * s * sd * sd / c ** 3
        Sd = np.stack([self.H * cd, self.H * sd, zero], -1)
        Sdd = np.stack([self.H * cdd, self.H * sdd, zero], -1)
        return S, Sd, Sdd


def lumped_model(mechanism, q, *, frames: dict[str, str], bodies: dict[str, str], anchors: dict[str, tuple]) -> LumpedModel:
    """Measure Section 3's parameters on a general model at one assembled configuration ``q``.
    ``frames`` maps the paper's points to frame names: O1, O2, O3 (slider points), D1, D2, D3,
    P (platform), V (proximal base pivot), S (support pivot), G_w (link_3 pivot on the slider);
    ``bodies`` maps m_p, m_s2, m_w, m_t to body names (sliders' masses are all the bodies on the
    slider links); ``anchors`` maps A, B, N1, N2 to frame names at the spring anchors.
    Raises ValueError when a moving body is not on a slider, the platform or the support (the
    lumped model has massless legs and links)."""
    X = {k: mechanism.frame_placement(q, f)[:3, 3] for k, f in {**frames, **anchors}.items()}
    model = mechanism.model
    desc = model.description
    mass = {b.name: b.mass for b in model.bodies}
    link_of = {b.name: b.link for b in desc.bodies}
    act = mechanism.actuated_names
    frame_link = {f.name: f.link for f in desc.frames}
    platform_link, support_link = frame_link[frames["P"]], frame_link[frames["S"]]
    allowed = {*act, platform_link, support_link, "base"}
    for name, link in link_of.items():
        if mass[name] > 0 and link not in allowed:
            raise ValueError(f"body {name!r} on link {link!r}: the lumped model has masses only on the "
                             "sliders, the platform and the spring support")
    m_slider = np.array([sum(mass[n] for n, l in link_of.items() if l == s) for s in act])
    legs = [np.linalg.norm(X[f"D{j}"] - X[f"O{j}"]) for j in (1, 2, 3)]
    if max(legs) - min(legs) > 1e-9:
        raise ValueError(f"legs of different lengths: {legs}")
    g = -float(mechanism.gravity[1])
    if g <= 0 or abs(mechanism.gravity[0]) + abs(mechanism.gravity[2]) > 0:
        raise ValueError("the paper's frame has gravity along -y")
    on_support = [b for b in model.bodies if link_of[b.name] == support_link]
    m_t = sum(b.mass for b in on_support)
    q_t = sum(b.mass * np.asarray(b.com, float) for b in on_support) / m_t if m_t > 0 else np.zeros(3)
    return LumpedModel(
        L=float(legs[0]), delta=np.array([X[f"D{j}"] - X["P"] for j in (1, 2, 3)]),
        m_p=mass[bodies["m_p"]], m_slider=m_slider, m_s2=mass[bodies["m_s2"]], m_w=mass[bodies["m_w"]],
        m_t=m_t, g=g, V=X["V"],
        Gw_offset=X["G_w"] - X["O2"], H=float(np.linalg.norm(X["S"] - X["V"])), q_t=np.asarray(q_t, float),
        a=X["A"] - X["O2"], b=X["B"] - X["P"], n1=X["N1"] - X["O2"], n2=X["N2"] - X["S"])


def _slider_points(lm: LumpedModel, rho):
    rho = np.asarray(rho, float)
    O = np.zeros(rho.shape[:-1] + (3, 3))
    for j in range(3):
        O[..., j, j] = rho[..., j]
    return O


def potential_energy(lm: LumpedModel, p, K_D: float = 0.0, K_P: float = 0.0) -> np.ndarray:
    """The paper's lumped model (a check of the general path): total potential energy [J] at platform points p (..., 3): gravity of m_p, m_s2 + m_w (the
    vertical slider) and m_t plus the two zero-free-length springs (eqs 5, 6, 9, 10, written in
    positions rather than the angles phi_1, phi_2, gamma; the horizontal sliders' V_gH is
    constant and left out). Its zero differs from the general model's -sum m g . c by a constant."""
    p = np.asarray(p, float)
    rho = linear_delta_ik(p, lm.L, np.diagonal(lm.delta))
    O2 = np.stack([np.zeros_like(rho[..., 1]), rho[..., 1], np.zeros_like(rho[..., 1])], -1)
    S = lm.support_kinematics(rho[..., 1])
    g = lm.g
    V = g * (lm.m_p * p[..., 1] + lm.m_s2 * rho[..., 1] + lm.m_w * (rho[..., 1] + lm.e)
             + lm.m_t * (S[..., 1] + lm.q_t[1]))
    r_AB = (p + lm.b) - (O2 + lm.a)
    r_N = (O2 + lm.n1) - (S + lm.n2)
    return V + 0.5 * K_D * np.sum(r_AB ** 2, -1) + 0.5 * K_P * np.sum(r_N ** 2, -1)


def inverse_dynamics(lm: LumpedModel, p, v, a, f_cut=None, K_D: float = 0.0, K_P: float = 0.0,
                     m_slider_extra=None) -> dict[str, np.ndarray]:
    """The paper's lumped model (a check of the general path): motor forces (..., 3) [N] along x, y, z of the lumped machine for the platform motion (p,
    v, a) (..., 3) with the cutting force ``f_cut`` (..., 3) on the tool, by Newton's equations:

    * platform: m_p (a_P - g) = sum_j t_j w_j + f_cut + K_D (A - B): solves the leg forces t_j
      along the parallelogram directions w_j = (D_j - O_j)/L (a massless leg with revolute ends
      and a parallelogram transmits a force along its line and couples, which a translating
      platform's force balance does not see);
    * spring support (translating, links 1-2 along (c_gamma, s_gamma), link_3 along S - G_w,
      both two-force members): m_t (a_S - g) = f_12 u_12 + f_3 u_3 + K_P (N_1 - N_2);
    * slider j along e_j: F_j = M_j (rho_j'' - g . e_j) + t_j w_j . e_j - (spring and link_3
      forces on the slider) . e_j.

    Returns ``motor_force``, ``leg_force`` (t, compression > 0), ``rho``, ``rho_d``, ``rho_dd``."""
    p, v, a = (np.asarray(x, float) for x in (p, v, a))
    f_cut = np.zeros_like(p) if f_cut is None else np.asarray(f_cut, float)
    rho, rho_d, rho_dd = linear_delta_ik(p, lm.L, np.diagonal(lm.delta), v, a)
    O = _slider_points(lm, rho)
    D = p[..., None, :] + lm.delta
    W = np.swapaxes((D - O) / lm.L, -1, -2)            # columns w_j
    gv = np.array([0.0, -lm.g, 0.0])
    O2 = O[..., 1, :]
    A, B = O2 + lm.a, p + lm.b
    S, Sd, Sdd = lm.support_kinematics(rho[..., 1], rho_d[..., 1], rho_dd[..., 1])
    N1, N2 = O2 + lm.n1, S + lm.n2
    rhs = lm.m_p * (a - gv) - f_cut - K_D * (A - B)
    t = np.linalg.solve(W, rhs[..., None])[..., 0]
    Gw = O2 + lm.Gw_offset
    u12 = (S - lm.V) / lm.H
    u3 = (S - Gw) / lm.H
    M2 = np.stack([u12[..., :2], u3[..., :2]], -1)     # planar (x, y) 2x2
    rhs_t = (lm.m_t * (Sdd - gv) - K_P * (N1 - N2))[..., :2]
    f = np.linalg.solve(M2, rhs_t[..., None])[..., 0]
    on_slider2 = K_D * (B - A) + K_P * (N2 - N1) - f[..., 1:2] * u3
    M = lm.m_slider if m_slider_extra is None else lm.m_slider + m_slider_extra
    F = np.empty_like(p)
    for j in range(3):
        F[..., j] = M[j] * (rho_dd[..., j] - gv[j]) + t[..., j] * W[..., j, j]
    F[..., 1] -= on_slider2[..., 1]
    return {"motor_force": F, "leg_force": t, "rho": rho, "rho_d": rho_d, "rho_dd": rho_dd}


def rest_to_rest(distance: float, v_max: float, a_max: float):
    """A smooth rest-to-rest law s(t) over ``distance`` with speed <= v_max and acceleration <= a_max:
    sine-squared acceleration ramps a(t) = a_max sin^2(pi t / T_a), T_a = 2 v / a_max, and a cruise
    at v (v = v_max, or lower on short moves). Returns (duration, law) with law(t) -> (s, s', s'')."""
    if distance <= 0:
        return 0.0, lambda t: (np.zeros_like(t), np.zeros_like(t), np.zeros_like(t))
    v = min(v_max, math.sqrt(distance * a_max / 2.0))
    Ta = 2.0 * v / a_max
    Tc = (distance - v * Ta) / v
    T = 2 * Ta + max(Tc, 0.0)

    def ramp(t):
        w = 2 * math.pi / Ta
        acc = a_max / 2 * (1 - np.cos(w * t))
        vel = a_max / 2 * (t - np.sin(w * t) / w)
        pos = a_max / 2 * (t * t / 2 + (np.cos(w * t) - 1) / w ** 2)
        return pos, vel, acc

    def law(t):
        t = np.clip(np.asarray(t, float), 0.0, T)
        s, sd, sdd = (np.zeros_like(t) for _ in range(3))
        m1, m3 = t <= Ta, t >= T - Ta
        m2 = ~(m1 | m3)
        s[m1], sd[m1], sdd[m1] = ramp(t[m1])
        s[m2], sd[m2], sdd[m2] = v * Ta / 2 + v * (t[m2] - Ta), v, 0.0
        p, pd, pdd = ramp(T - t[m3])
        s[m3], sd[m3], sdd[m3] = distance - p, pd, -pdd
        return s, sd, sdd

    return T, law


@dataclass
class PlatformPath:
    """A sampled trajectory of the platform point P: ``t`` (N,), ``p``, ``v``, ``a`` (N, 3) and
    the cutting force on the tool ``f_cut`` (N, 3) [N]; ``cutting`` (N,) bool."""

    name: str
    t: np.ndarray
    p: np.ndarray
    v: np.ndarray
    a: np.ndarray
    f_cut: np.ndarray
    cutting: np.ndarray
    info: dict = field(default_factory=dict)


def _sample(segments, dt: float, name: str, info=None) -> PlatformPath:
    """Concatenate segments (duration, fn(t_local) -> p, v, a, f, cutting) on one time grid."""
    durations = np.array([d for d, _ in segments])
    starts = np.concatenate([[0.0], np.cumsum(durations)])
    T = starts[-1]
    n = int(math.ceil(T / dt - 1e-9)) + 1
    t = np.linspace(0.0, T, n)
    idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(segments) - 1)
    p, v, a, f = (np.zeros((n, 3)) for _ in range(4))
    cutting = np.zeros(n, bool)
    for i, (d, fn) in enumerate(segments):
        m = idx == i
        if np.any(m):
            p[m], v[m], a[m], f[m], cutting[m] = fn(t[m] - starts[i])
    return PlatformPath(name, t, p, v, a, f, cutting, dict(info or {}))


def _line(p0, p1, v_max, a_axis, force: Callable | None = None):
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = np.linalg.norm(p1 - p0)
    u = (p1 - p0) / d if d > 0 else np.zeros(3)
    a_path = a_axis / max(np.max(np.abs(u)), 1e-12)   # at most a_axis on each axis
    T, law = rest_to_rest(d, v_max, a_path)

    def fn(tl):
        s, sd, sdd = law(tl)
        p, v, a = p0 + s[:, None] * u, sd[:, None] * u, sdd[:, None] * u
        f = np.zeros_like(p) if force is None else force(v)
        return p, v, a, f, np.full(len(tl), force is not None)

    return T, fn


def helix_path(center, edge: float, radius: float, speed: float, vertical_ratio: float, acceleration: float,
               dt: float, name: str = "A") -> PlatformPath:
    """Path A: P on a helix of ``radius`` about the vertical through ``center``, from the bottom to
    the top face of the workspace cube, tangential (horizontal) speed ``speed`` and vertical speed
    ``vertical_ratio * speed``, constant between smooth start and stop ramps of ``acceleration``
    along the path."""
    c = np.asarray(center, float)
    k = math.sqrt(1 + vertical_ratio ** 2)
    length = edge * k / vertical_ratio
    T, law = rest_to_rest(length, speed * k, acceleration)
    y0 = c[1] - edge / 2

    def fn(tl):
        s, sd, sdd = law(tl)
        th, thd, thdd = s / (radius * k), sd / (radius * k), sdd / (radius * k)
        yd_s = vertical_ratio / k
        p = np.stack([c[0] + radius * np.cos(th), y0 + s * yd_s, c[2] + radius * np.sin(th)], -1)
        v = np.stack([-radius * np.sin(th) * thd, sd * yd_s, radius * np.cos(th) * thd], -1)
        a = np.stack([-radius * (np.cos(th) * thd ** 2 + np.sin(th) * thdd), sdd * yd_s,
                      radius * (-np.sin(th) * thd ** 2 + np.cos(th) * thdd)], -1)
        return p, v, a, np.zeros_like(p), np.zeros(len(tl), bool)

    return _sample([(T, fn)], dt, name, {"turns": length / k / (2 * math.pi * radius)})


#: Path B: corners of the cube (index bits x, y, z), along its 12 edges and 4 diagonals
CUBE_TOUR = ["000", "100", "101", "001", "000", "010", "110", "111", "011", "010", "101", "111", "000", "100",
             "011", "001", "110", "100"]


def cube_path(center, edge: float, speed: float, a_axis: float, dt: float, name: str = "B") -> PlatformPath:
    """Path B: rest-to-rest moves along the edges and the space diagonals of the workspace cube
    (`CUBE_TOUR`), speed <= ``speed``, acceleration <= ``a_axis`` on each axis."""
    c = np.asarray(center, float)
    pts = [c + edge * (np.array([int(ch) for ch in v], float) - 0.5) for v in CUBE_TOUR]
    return _sample([_line(pts[i], pts[i + 1], speed, a_axis) for i in range(len(pts) - 1)], dt, name)


def cutting_force(operation: str, feed: float, force: float) -> Callable:
    """Cutting force on the tool as a function of the platform velocity (Section 5.1): proportional
    to the feed velocity, |f| = F_c at v = v_f. Milling (roughing, finishing): a radial component
    against the feed and a tangential one normal to the feed and to the vertical, equal in size;
    deburring: also a vertical one (upwards, the part is below the tool), the three equal;
    drilling: a thrust against the (vertical) feed."""
    y = np.array([0.0, 1.0, 0.0])
    if operation == "drilling":
        return lambda v: -(force / feed) * v
    n = 3 if operation == "deburring" else 2
    c = force / (math.sqrt(n) * feed)

    def f(v):
        out = -c * v + c * np.cross(y, v)
        if n == 3:
            out = out + c * np.linalg.norm(v, axis=-1, keepdims=True) * y
        return out

    return f


def machining_path(center, operation: str, feed: float, force: float, pockets, holes, drill_depth: float,
                   approach_height: float, rapid_speed: float, a_axis: float, dt: float, name: str) -> PlatformPath:
    """Paths C-F: from C, rapid moves (``rapid_speed``, ``a_axis``) to each pocket (or hole), the
    machining at the feed ``feed`` with the cutting force of `cutting_force`, rapid moves
    back to C. A pocket is a contour pass of its rectangle (corner (x, y, z) relative to C, size
    along x and z); a hole is a vertical feed of ``drill_depth`` down from its point and a rapid
    retract."""
    c = np.asarray(center, float)
    up = np.array([0.0, approach_height, 0.0])
    f = cutting_force(operation, feed, force)
    segs, here = [], c.copy()

    def rapid(to):
        nonlocal here
        segs.append(_line(here, to, rapid_speed, a_axis))
        here = np.asarray(to, float)

    def cut(to):
        nonlocal here
        segs.append(_line(here, to, feed, a_axis, f))
        here = np.asarray(to, float)

    if operation == "drilling":
        for h in holes:
            top = c + np.asarray(h, float)
            rapid(top + up)
            rapid(top)
            cut(top - np.array([0.0, drill_depth, 0.0]))
            rapid(top + up)
    else:
        for pk in pockets:
            corner = c + np.asarray(pk["corner"], float)
            sx, sz = pk["size"]
            loop = [corner + np.array([sx, 0, 0]), corner + np.array([sx, 0, sz]), corner + np.array([0, 0, sz]),
                    corner]
            rapid(corner + up)
            rapid(corner)
            for pnt in loop:
                cut(pnt)
            rapid(corner + up)
    rapid(c)
    return _sample(segs, dt, name, {"operation": operation, "feed_m_per_s": feed, "force_N": force})

# importing the schema registers this paper's case kind (mechbal.registry imports this package)
from mechbal.papers.orthoglide import schema as _schema  # noqa: E402,F401
