"""PAMINSA counterweights for complete shaking-force balancing (Briot & Arakelian 2009, eqs 6-16).

Two independent answers, both reported by the ``paminsa`` case:

1. :func:`closed_form` -- the paper's closed forms, re-derived for the reconstructed leg. Writing
   every leg point as an affine combination of A, C and E (D = E + (C-E)/k, F = A + (C-E)/k,
   B = ((k-1)A + C)/k) and using G_A = G_C,h/(1-k), G_B = G_C,z/k, the momentum of leg i is
   m_C1 v_C,h + m_C2 v_C,z e_z + m_E v_E + (m5 v_S5 + m_CP3 v_L). Force balance needs
   m_E = 0 (eq 12 -> eq 15), m_C1 = 0 (eq 10 -> eq 14), m5 + r m_CP3 = 0 (eq 13 -> eq 16), and a
   vertical counter-mass sum_i m_C2,i moving as -z_P (eq 11).

   Corrections to the printed equations (each checked by :func:`least_squares` and by the
   simulated shaking force):

   * eq 6 / eq 11 (m_C2): must contain + 2 m8 / (2k) -- link 8 sits at F, which moves vertically,
     and eqs 7, 8, 12 already place it there. Printed eq 11 gives 3 x 3.1033 = 9.310 kg of vertical
     counter-mass; the correct value is 9.615 kg.
   * eq 7: (m1 + m2)/(2k) must be (m1 + m2/k)/2, as eq 10 has it.
   * eq 13: "OL_i = OO_i + r OS_5i" must read M_iL_i = r M_iS_5i (the pivot of link 5 is M_i).
   * k is D_iF_i / B_iF_i (the paper prints B_iF_i / D_iF_i, which would make BF = 1.26 m).
   * eqs 14-16 as printed are algebraically right: 2.7915 / 1.3865 / 0.436 kg.
   * the paper *reports* 4.49 / 1.69 / 0.436 kg. 1.69 is eq 15 with its -2 m8 term dropped
     (1.6915); 4.49 is not reproduced by eq 14 under any misprint we tried. The reported masses
     leave ~17 N of shaking force (63 % of the unbalanced peak) -- see the case summary.

2. :func:`least_squares` -- a general solver: choose the counterweight masses so that the total
   linear momentum sum m v_G vanishes (the total centre of mass is stationary) at samples of any
   set of trajectories, by linear least squares over the unknowns [CP1 (shared: all A_i have the
   same velocity, only the sum is identifiable), CP2_1..3, CP3_1..3, vertical counter-mass]. The
   velocities of the candidate locations come from the C++ kinematics (no closed form used).
   The paper's cycle alone leaves 3 of the 8 unknowns unidentified (no x motion; legs 1 and 2
   move identically); trajectories exciting x, y and z leave only the leg 1 / leg 2 symmetry, and
   the minimum-norm solution is the symmetric one.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: the values the paper reports (Sec. III) [kg]; the vertical counter-mass is not given
PAPER_REPORTED = {"cp1": 4.49, "cp2": 1.69, "cp3": 0.436}


@dataclass
class CounterweightSet:
    cp1: list[float]          # at A_i, per leg
    cp2: list[float]          # at F_i, per leg
    cp3: list[float]          # at L_i, per leg
    vertical: float           # vertical counter-mass
    source: str
    notes: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {"cp1": list(self.cp1), "cp2": list(self.cp2), "cp3": list(self.cp3),
                "vertical": float(self.vertical), "source": self.source, **self.notes}

    def apply(self, params):
        """A copy of ``params`` (mechbal.PaminsaParameters) carrying these counterweights."""
        from mechbal._core import PaminsaCounterweights

        cw = PaminsaCounterweights()
        cw.at_A, cw.at_F, cw.at_L = list(self.cp1), list(self.cp2), list(self.cp3)
        cw.vertical = float(self.vertical)
        out = copy_parameters(params)
        out.counterweights = cw
        return out


PARAMETER_FIELDS = ("k", "a", "b", "c", "d", "e", "f", "length_BG", "length_AE", "length_DF",
                    "length_CE", "length_AF", "length_CJ", "length_MS5", "length_MO",
                    "platform_mass", "link_mass", "link_inertia", "wrist_inertia",
                    "nominal_platform", "nominal_rho", "z_A", "elbow", "vertical_mass_at_centroid",
                    "vertical_mass_xy", "vertical_mass_z0", "cp3_ratio", "counterweights")


def copy_parameters(params):
    """A field-by-field copy of a mechbal.PaminsaParameters."""
    from mechbal._core import PaminsaParameters

    out = PaminsaParameters()
    for name in PARAMETER_FIELDS:
        setattr(out, name, getattr(params, name))
    return out


def _m(params):
    return [float(x) for x in params.link_mass]


def closed_form(params) -> CounterweightSet:
    """Corrected eqs 14, 15, 16 and eq 11 (with the m8 term) for leg masses m1..m8, platform mass
    m_pl, magnification k and CP3 ratio r:

    m_CP2 = k (m1+m3)/2 + (k-2) m2/2 - m4/2 - m8                            (eq 15)
    m_CP1 = (k-1)(m_pl/3 + m1/2 + m2/(2k)) - (m3+m4)/2 - (m2+m4+2 m8+2 m_CP2)/(2k)   (eq 14)
    m_CP3 = -m5 / r                                                         (eq 16)
    m_vert = 3 [m_pl/3 + m1/2 + (2 m2 + m4 + 2 m6 + 2 m7 + 2 m8 + 2 m_CP2)/(2k)]     (eq 11 + m8)
    """
    k, r, mpl = params.k, params.cp3_ratio, params.platform_mass
    m1, m2, m3, m4, m5, m6, m7, m8 = _m(params)
    cp2 = k * (m1 + m3) / 2 + (k - 2) * m2 / 2 - m4 / 2 - m8
    cp1 = (k - 1) * (mpl / 3 + m1 / 2 + m2 / (2 * k)) - (m3 + m4) / 2 - (m2 + m4 + 2 * m8 + 2 * cp2) / (2 * k)
    cp3 = -m5 / r
    mc2 = mpl / 3 + m1 / 2 + (2 * m2 + m4 + 2 * m6 + 2 * m7 + 2 * m8 + 2 * cp2) / (2 * k)
    return CounterweightSet([cp1] * 3, [cp2] * 3, [cp3] * 3, 3 * mc2, "closed_form (eqs 11, 14-16 corrected)")


def paper_printed(params) -> CounterweightSet:
    """Eqs 14, 15, 16 evaluated literally as printed, and eq 11 (without m8) summed over the legs."""
    k, r, mpl = params.k, params.cp3_ratio, params.platform_mass
    m1, m2, m3, m4, m5, m6, m7, m8 = _m(params)
    cp2 = k * ((m1 + m3) / 2 + (k - 1) * m2 / (2 * k) - (m2 + m4 + 2 * m8) / (2 * k))            # (15)
    cp1 = ((k - 1) * ((m3 + m4) / (2 * (1 - k)) + (m1 + m2 / k) / 2 + mpl / 3)
           - (m4 + m2 + 2 * m8 + 2 * cp2) / (2 * k))                                            # (14)
    cp3 = -m5 / r                                                                               # (16)
    mc2 = (2 * m2 + m4 + 2 * m6 + 2 * m7 + 2 * cp2) / (2 * k) + mpl / 3 + m1 / 2                 # (11)
    return CounterweightSet([cp1] * 3, [cp2] * 3, [cp3] * 3, 3 * mc2, "paper eqs 11, 14-16 as printed",
                            {"cp2_without_m8_term": cp2 + 2 * m8 * k / (2 * k)})


def paper_reported(params, vertical: float) -> CounterweightSet:
    """The masses the paper reports, with the given vertical counter-mass (the paper gives none)."""
    p = PAPER_REPORTED
    return CounterweightSet([p["cp1"]] * 3, [p["cp2"]] * 3, [p["cp3"]] * 3, vertical, "paper reported")


def _platform_samples(trajectories, samples):
    Ps, Pds, Pdds = [], [], []
    for traj in trajectories:
        t = np.linspace(0.0, traj.duration, samples)[1:-1]
        P, Pd, Pdd = traj.evaluate_batch(t)
        Ps.append(P)
        Pds.append(Pd)
        Pdds.append(Pdd)
    return np.vstack(Ps), np.vstack(Pds), np.vstack(Pdds)


def least_squares(params, trajectories, samples: int = 40) -> tuple[CounterweightSet, np.ndarray]:
    """Counterweights that make the total linear momentum zero along ``trajectories`` (each a
    mechbal.RestToRestTrajectory of the platform point P), by linear least squares (minimum-norm
    solution). Returns the set and the singular values of the stacked regressor (zeros = directions
    the trajectories cannot identify)."""
    from mechbal._core import PaminsaCounterweights, PaminsaModel, paminsa_kinematics

    bare = copy_parameters(params)
    bare.counterweights = PaminsaCounterweights()
    model = PaminsaModel(bare)
    P, Pd, Pdd = _platform_samples(trajectories, samples)
    z = np.zeros_like(P)
    k = paminsa_kinematics(model, P, Pd, Pdd, z, z, z)
    v = k["com_velocity"]                                   # (N, 38, 3)
    p0 = np.einsum("b,nbi->ni", np.asarray(model.masses), v)  # momentum without counterweights
    names = model.body_names
    idx = {n: i for i, n in enumerate(names)}
    cols = [sum(v[:, idx[f"leg{i}.CP1_atA"]] for i in (1, 2, 3))]
    cols += [v[:, idx[f"leg{i}.CP2_atF"]] for i in (1, 2, 3)]
    cols += [v[:, idx[f"leg{i}.CP3_atL"]] for i in (1, 2, 3)]
    cols += [v[:, idx["vertical_counter_mass"]]]
    V = np.stack([c.reshape(-1) for c in cols], axis=1)
    y = -p0.reshape(-1)
    sol, *_ = np.linalg.lstsq(V, y, rcond=None)
    sv = np.linalg.svd(V, compute_uv=False)
    residual = float(np.linalg.norm(V @ sol - y) / max(np.linalg.norm(y), 1e-300))
    cw = CounterweightSet([sol[0]] * 3, list(sol[1:4]), list(sol[4:7]), float(sol[7]),
                          "least_squares (total COM stationary)",
                          {"relative_residual": residual,
                           "unidentified_directions": int(np.sum(sv < 1e-9 * sv[0]))})
    return cw, sv
