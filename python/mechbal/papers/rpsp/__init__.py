"""The 3(RPSP)-S spherical parallel robot of Heydari & Enferadi ("Complete dynamic shaking force
balancing of a 3(RPSP)-S spherical parallel robot using extra linkage", Persian, research note):
the paper's closed forms, kept as *checks* of the general model (the mechanism itself is data,
``python/mechbal/papers/rpsp/cases/rpsp.toml``, solved by `mechbal.Mechanism.closed_motion`).

* `inverse_kinematics`: eqs 1-13 (platform orientation -> b_i, l_i, e_i, theta_i) with
  their first and second time derivatives in closed form, and the degenerate configurations
  (eq 8's denominator u_i . R v_i -> 0, eq 10's leg length l_i -> 0) reported instead of
  returning garbage.
* `counterweights_eqs_29_31`: the printed sizing equations; `balance_coefficients`:
  the three vector coefficients of eq 28 (first principles: the leg's mass-weighted position must
  not depend on D_i, C_i - D_i, E_i - A_i), which the masses must make zero.
* `PAPER_TABLES` and `table_consistency`: Tables 1-3 as printed and which cells do not
  follow from the printed forces.

Conventions (the paper's): base frame {B} at the centre of the fixed base, z up; the central
column ends at h = (0, 0, h) in the spherical joint S, the platform's centre; u_i = (cos lambda_i,
sin lambda_i, 0) is the axis of the actuated revolute joint at A_i = a_i u_i; v_i = R (cos alpha_i,
sin alpha_i, 0) the direction of the platform's slider i; R = Rz(phi_z) Ry(phi_y) Rx(phi_x)
(eq 1); the leg's spherical joint is at h + b_i v_i = A_i + l_i e_i (eq 2), with
e_i = cos(theta_i) k + sin(theta_i) (u_i x k) (eq 12).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["RpspGeometry", "paper_motion", "platform_rotation", "inverse_kinematics",
           "counterweights_eqs_29_31", "balance_coefficients", "PAPER_COUNTERWEIGHTS_KG",
           "PAPER_TABLES", "PAPER_MEAN_REDUCTION_PCT", "table_consistency"]

#: the paper's sizing result (section "c"): m_P, m_N, m_F per leg [kg]
PAPER_COUNTERWEIGHTS_KG = {"m_P": 17.61, "m_N": 2.76, "m_F": 4.5}
#: the paper's mean reductions per axis (abstract, conclusion) [%]
PAPER_MEAN_REDUCTION_PCT = [98.0, 79.0, 99.4]

#: Tables 1-3 as printed (x, y, z): rows (time [s], force before [N], force after [N], reduction
#: [%]). Transcribed from the Persian digits; the decimal separators lost in the conversion are
#: restored only where the column's other rows and the printed percentage leave no doubt:
#: Table 1's last "before" cell prints "18956" (1.8956: 1 - 0.032/1.8956 = 98.31 %, as printed).
#: The fourth instant prints 0.102 in all three tables (0.152 follows the 0.05 s spacing).
PAPER_TABLES = {
    "x": [(0.0, 60.6597, -0.6359, 98.9517), (0.052, 88.7681, -1.2867, 98.5505),
          (0.1, -163.053, 2.4515, 98.4965), (0.102, 89.1446, -1.3241, 98.0147),
          (0.2, 1.8956, -0.032, 98.3119)],
    "y": [(0.0, 27.1848, 0.0244, 81.5176), (0.052, 28.2497, 6.564, 76.7644),
          (0.1, -56.05087, -10.7603, 80.9582), (0.102, 28.2404, 6.6492, 76.405),
          (0.2, 0.9875, 0.1679, 82.9975)],
    "z": [(0.0, 121.8986, -0.9443, 99.2256), (0.052, 155.2322, -0.473, 99.7953),
          (0.1, -225.936, -1.6137, 99.316), (0.102, 156.2115, -0.394, 99.7478),
          (0.2, 3.4499, 0.0197, 99.429)],
}


@dataclass(frozen=True)
class RpspGeometry:
    """a_i [m] (|O A_i|), h [m] (column height), lambda_i and alpha_i [rad] (eqs 4-5)."""
    a: tuple[float, float, float]
    h: float
    lam: tuple[float, float, float]
    alpha: tuple[float, float, float]

    @classmethod
    def paper(cls) -> "RpspGeometry":
        ang = tuple(2.0 * i * np.pi / 3.0 for i in range(3))
        return cls(a=(0.303,) * 3, h=0.215, lam=ang, alpha=ang)


def paper_motion(t, roll_amplitude=1.0, yaw_amplitude=np.pi / 6, period=2.0 * np.pi,
                 yaw_factor=0.125):
    """The paper's motion (section "d"): phi_x = A sin(2 pi t / T), phi_y = 0,
    phi_z = B sin(f pi t / T) with A = 1, B = pi/6, f = 0.125, T = 2 pi. Returns (phi, phi', phi'')
    as (N, 3) arrays ordered (phi_z, phi_y, phi_x), the order of R = Rz Ry Rx (eq 1) and of
    mechbal's spherical joint coordinates."""
    t = np.atleast_1d(np.asarray(t, float))
    wx, wz = 2.0 * np.pi / period, yaw_factor * np.pi / period
    z = np.zeros_like(t)
    phi = np.stack([yaw_amplitude * np.sin(wz * t), z, roll_amplitude * np.sin(wx * t)], axis=1)
    dphi = np.stack([yaw_amplitude * wz * np.cos(wz * t), z, roll_amplitude * wx * np.cos(wx * t)], axis=1)
    ddphi = np.stack([-yaw_amplitude * wz ** 2 * np.sin(wz * t), z, -roll_amplitude * wx ** 2 * np.sin(wx * t)],
                     axis=1)
    return phi, dphi, ddphi


def _rz(x):
    c, s = np.cos(x), np.sin(x)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(x):
    c, s = np.cos(x), np.sin(x)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rx(x):
    c, s = np.cos(x), np.sin(x)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def platform_rotation(phi, dphi=None, ddphi=None):
    """R = Rz(phi_z) Ry(phi_y) Rx(phi_x) (eq 1; ``phi`` ordered z, y, x), and, with the rates,
    the platform's angular velocity w and acceleration w' in {B}."""
    pz, py, px = phi
    Rz, Ry, Rx = _rz(pz), _ry(py), _rx(px)
    R = Rz @ Ry @ Rx
    if dphi is None:
        return R
    dz, dy, dx = dphi
    ddz, ddy, ddx = (0.0, 0.0, 0.0) if ddphi is None else ddphi
    k, j1, i2 = np.array([0.0, 0.0, 1.0]), Rz[:, 1], (Rz @ Ry)[:, 0]
    w_zy = dz * k + dy * j1
    w = w_zy + dx * i2
    dw = ddz * k + ddy * j1 + dy * np.cross(dz * k, j1) + ddx * i2 + dx * np.cross(w_zy, i2)
    return R, w, dw


def inverse_kinematics(geometry: RpspGeometry, phi, dphi=None, ddphi=None, *, tolerance=1e-9):
    """Eqs 1-13 with exact time derivatives, for one orientation or a batch ((N, 3), z, y, x).

    Returns a dict of arrays ((N, 3) per leg unless noted): ``denominator`` u_i . R v_i (eq 8),
    ``b`` (eq 8), ``l`` (eq 9), ``e`` (N, 3, 3: leg, xyz; eq 10), ``theta`` (eq 13, written as
    atan2((u_i x k) . e_i, e_iz), which is eq 13's atan2(-e_iy / u_ix, e_iz) without the division
    by u_ix), ``b_dot``, ``l_dot``, ``theta_dot``, ``b_ddot``, ``l_ddot``, ``theta_ddot``,
    ``tip`` (N, 3, 3): the leg's spherical joint h + b_i v_i, and ``degenerate`` (N, 3) bool:
    |denominator| < tolerance (the platform slider is parallel to the leg plane: b_i unbounded)
    or l_i < tolerance (e_i and theta_i undefined). Degenerate entries are zeros, never NaN."""
    phi = np.atleast_2d(np.asarray(phi, float))
    n = phi.shape[0]
    dphi = np.zeros_like(phi) if dphi is None else np.atleast_2d(np.asarray(dphi, float))
    ddphi = np.zeros_like(phi) if ddphi is None else np.atleast_2d(np.asarray(ddphi, float))
    out = {k: np.zeros((n, 3)) for k in ("denominator", "b", "l", "theta", "b_dot", "l_dot", "theta_dot",
                                         "b_ddot", "l_ddot", "theta_ddot")}
    out["e"] = np.zeros((n, 3, 3))
    out["tip"] = np.zeros((n, 3, 3))
    out["degenerate"] = np.zeros((n, 3), bool)
    R, w, dw = _rotations(phi, dphi, ddphi)
    hvec = np.array([0.0, 0.0, geometry.h])
    k = np.array([0.0, 0.0, 1.0])
    dot = lambda x, y: np.einsum("ni,ni->n", x, y)  # noqa: E731
    for i in range(3):
        u = np.array([np.cos(geometry.lam[i]), np.sin(geometry.lam[i]), 0.0])
        v = R @ np.array([np.cos(geometry.alpha[i]), np.sin(geometry.alpha[i]), 0.0])
        dv = np.cross(w, v)
        ddv = np.cross(dw, v) + np.cross(w, dv)
        den, dden, ddden = v @ u, dv @ u, ddv @ u
        out["denominator"][:, i] = den
        a = geometry.a[i]
        ok = np.abs(den) >= tolerance
        sd = np.where(ok, den, 1.0)
        b = a / sd                                                         # eq 8
        db = -a * dden / sd ** 2
        ddb = -a * ddden / sd ** 2 + 2.0 * a * dden ** 2 / sd ** 3
        r = hvec + b[:, None] * v - a * u                                  # l_i e_i (eq 2)
        dr = db[:, None] * v + b[:, None] * dv
        ddr = ddb[:, None] * v + 2.0 * db[:, None] * dv + b[:, None] * ddv
        l = np.linalg.norm(r, axis=1)                                      # eq 9
        ok &= l >= tolerance
        sl = np.where(ok, l, 1.0)
        e = r / sl[:, None]                                                # eq 10
        dl = dot(e, dr)
        ddl = dot(e, ddr) + (dot(dr, dr) - dl ** 2) / sl
        t_dir = np.cross(u, k)                                             # e = cos th k + sin th (u x k), eq 12
        y, x = r @ t_dir, r @ k
        dy, dx = dr @ t_dir, dr @ k
        ddy, ddx = ddr @ t_dir, ddr @ k
        D = np.where(ok, x * x + y * y, 1.0)
        N = x * dy - y * dx
        dN = x * ddy - y * ddx
        dD = 2.0 * (x * dx + y * dy)
        z = lambda q: np.where(ok, q, 0.0)  # noqa: E731
        out["b"][:, i], out["b_dot"][:, i], out["b_ddot"][:, i] = z(b), z(db), z(ddb)
        out["l"][:, i], out["l_dot"][:, i], out["l_ddot"][:, i] = z(l), z(dl), z(ddl)
        out["theta"][:, i] = z(np.arctan2(y, x))                           # eq 13
        out["theta_dot"][:, i] = z(N / D)
        out["theta_ddot"][:, i] = z((dN * D - N * dD) / D ** 2)
        out["e"][:, i] = np.where(ok[:, None], e, 0.0)
        out["tip"][:, i] = np.where(ok[:, None], hvec + b[:, None] * v, 0.0)
        out["degenerate"][:, i] = ~ok
    return out


def _rotations(phi, dphi, ddphi):
    """Batch of `platform_rotation`: R (N, 3, 3), w and w' (N, 3)."""
    R, w, dw = zip(*(platform_rotation(p, d, dd) for p, d, dd in zip(phi, dphi, ddphi)))
    return np.array(R), np.array(w), np.array(dw)


def counterweights_eqs_29_31(m_E, m_Q, m_H, m_K, r_H, r_K, r_P, r_N, r_Q, r_F):
    """The counterweights per leg as the paper prints eqs 29-31:
    m_F = -(m_Q r_Q + m_E) / r_F, m_N = -(m_K r_K + m_Q) / r_N,
    m_P = (m_K r_K + (1 - r_N) m_Q) / (r_P r_N) - (m_H r_H + m_K) / r_P."""
    m_F = -(m_Q * r_Q + m_E) / r_F
    m_N = -(m_K * r_K + m_Q) / r_N
    m_P = (m_K * r_K + (1.0 - r_N) * m_Q) / (r_P * r_N) - (m_H * r_H + m_K) / r_P
    return {"m_P": m_P, "m_N": m_N, "m_F": m_F}


def balance_coefficients(m_P, m_N, m_F, m_E, m_Q, m_H, m_K, r_H, r_K, r_P, r_N, r_Q, r_F):
    """The three scalar coefficients of eq 28 (of d_D, d_C/D and d_E): the leg's mass-weighted
    position sum m x = (...) A_i + c_D (D - A) + c_CD (C - D) + c_E (E - A) is constant for every
    motion iff all three vanish (first principles, from H = A + r_H (D - A), P = A + r_P (D - A),
    K = D + r_K (C - D), N = D + r_N (C - D), Q = C + r_Q (E - A), F = A + r_F (E - A))."""
    c_D = m_H * r_H + m_P * r_P + m_K + m_N + m_Q
    c_CD = m_K * r_K + m_N * r_N + m_Q
    c_E = m_Q * r_Q + m_E + m_F * r_F
    return c_D, c_CD, c_E


def table_consistency(tables=PAPER_TABLES, tolerance_pct=0.005):
    """For every printed row: the reduction 100 (1 - |after| / |before|) recomputed from the
    printed forces, against the printed percentage; rows off by more than ``tolerance_pct``
    percentage points are flagged. Also the mean of the printed and of the recomputed column."""
    out = {}
    for axis, rows in tables.items():
        checked = []
        for t, before, after, printed in rows:
            recomputed = 100.0 * (1.0 - abs(after) / abs(before))
            checked.append({"t": t, "before": before, "after": after, "printed_pct": printed,
                            "recomputed_pct": recomputed,
                            "consistent": bool(abs(recomputed - printed) <= tolerance_pct)})
        out[axis] = {"rows": checked,
                     "mean_printed_pct": float(np.mean([r["printed_pct"] for r in checked])),
                     "mean_recomputed_pct": float(np.mean([r["recomputed_pct"] for r in checked]))}
    return out

# importing the schema registers this paper's case kind (mechbal.registry imports this package)
from mechbal.papers.rpsp import schema as _schema  # noqa: E402,F401
