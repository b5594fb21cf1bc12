"""PAMINSA (Briot & Arakelian 2009, "Complete shaking force and shaking moment balancing of the
position-orientation decoupled PAMINSA manipulator", AIM 2009, Section II) on the general
mechanism model: three pantograph legs, their guides and columns, the platform, the
counterweights, the vertical counter-mass and the z-x-z wrist, as one tree closed by nine loops.

The geometry is the closed form's (``mechbal.PaminsaModel``, cpp/include/mechbal/papers/paminsa/paminsa.hpp and
the assumptions A1-A11 of python/mechbal/papers/paminsa/cases/paminsa.toml): the same layout (A8), the same
38 bodies with the same names, masses, centres of mass and principal inertias. What the general
model adds is the joints the closed form only implies.

Leg i (i = 1, 2, 3), joints named ``leg<i>_...`` (angles in rad, lengths in m):

* ``slider`` (prismatic along z on the fixed vertical line through B_h,i; q = z_B, the height of
  B_i): link 7, the slider at B_i (A4). The three sliders are driven by the one linear actuator
  M_v: ``leg2_slider`` and ``leg3_slider`` are gear couplings of ``leg1_slider`` (ratio 1).
* ``column`` (revolute about the vertical through B_i; q = beta_i, the azimuth of the leg plane):
  link 6, the vertical column B-G (A3). Its frame is (e_z, n, -u), u the leg plane's outward
  horizontal direction and n = e_z x u its normal: the closed form's body axes.
* ``link2`` (revolute about n at B_i on the column; q = elevation of D->F in the leg plane): link 2
  (D-F, which carries B at (k-1)/k of D->F), with link 8 and the counterweight CP2 at F (A5).
* ``link1`` (revolute about n at D on link 2; q relative): link 1 (E-C).
* ``link3`` (revolute about n at E on link 1; q relative): link 3 (A-E) with CP1 at A.
* ``link4`` (revolute about n at F on link 2; q relative): link 4 (A-F), which closes the
  parallelogram A-E-D-F: loop ``leg<i>_parallelogram`` (``planar_point`` at A, 2 equations in
  the leg plane).
* ``guide`` (revolute about the vertical through M_i; q = alpha_i): link 5, the rotating guide,
  with CP3 at L_i (M_iL_i = r M_iS_5i). M_1 and M_3 are the revolute actuators, M_2 is passive.
* ``stroke`` (prismatic along the guide; q = |M_iA_i|): the massless carriage of A_i in the guide.
  Loop ``leg<i>_guide`` (``point``): A of link 3 is the carriage's point.
* loop ``leg<i>_platform`` (``point``): C of link 1 is the platform's joint point C_i = P + (J_i
  - P) - l_CJ e_z.

Each link frame of the pantograph is the closed form's body frame (x along the link, y = n), each
joint angle about -n is the link's elevation, so every body's inertia is its principal diagonal.

Platform and wrist: the platform only translates (its yaw is locked by the parallel legs 1 and 2,
its tilt by the pantographs: the closed form's assumption, whose joint-level reason the paper's
lost figures held). It is modelled on three massless prismatic joints ``platform_x``,
``platform_y``, ``platform_z`` (q = P), passive, fixed by the three ``leg<i>_platform`` closures
(the vertical rows of legs 2 and 3 are redundant with leg 1's through the common z_B: 24 closure
equations for 22 passive coordinates, consistent; the loop solve's least-squares inverse is exact
there). The wrist: ``wrist_phi`` (about z), ``wrist_theta`` (x), ``wrist_psi`` (z) on the
platform, bodies ``wrist1..3`` with their centres of mass at P and no mass (the platform mass
includes the wrist, as in the paper).

Vertical counter-mass (the "supplementary system", A9): ``vertical_counter_mass``, prismatic along
z at its (x, y), a gear coupling of the vertical actuator: z = z0 - (z_P - z_P0) with
z_P = z_A + k (z_B - z_A) + l_CJ, i.e. ratio -k.

Actuated: ``leg1_guide``, ``leg3_guide``, ``leg1_slider`` (the paper's M_1, M_3, M_v) and the
three wrist joints. Every other coordinate is passive. The closed forms (``PaminsaModel``,
``paminsa_kinematics``, ``paminsa_mechanism_wrench``) stay the 1 kHz fast path; they equal this
model to 1e-10 along the paper's cycle (tests/python/test_papers_loops.py).

Layer: papers (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from mechbal import _core
from mechbal.mechanism import Mechanism
from mechbal.schema import validate_case

# the closed forms of the C++ core (cpp/src/papers/paminsa/): fast paths of the general model
PaminsaParameters = _core.PaminsaParameters
PaminsaCounterweights = _core.PaminsaCounterweights
PaminsaModel = _core.PaminsaModel
paminsa_kinematics = _core.paminsa_kinematics
paminsa_reactionless_run = _core.paminsa_reactionless_run
wrist_momentum_matrix = _core.wrist_momentum_matrix
wrist_momentum_bias = _core.wrist_momentum_bias

from mechbal.papers.paminsa.controller import (  # noqa: E402 (the closed-form controllers)
    PaminsaController, PaminsaRun, ReactionlessWrist, ReactionlessWristConfig, WristCommand, WristIntegrator,
    WristRun)

__all__ = ["PaminsaParameters", "parameters_from_config", "PaminsaCounterweights", "PaminsaModel", "paminsa_kinematics", "paminsa_reactionless_run", "wrist_momentum_matrix", "wrist_momentum_bias",
           "paminsa_mechanism", "paminsa_layout", "paminsa_initial_guess", "paminsa_actuated_motion",
           "paminsa_case_toml", "ACTUATED", "body_names", "CounterweightSet", "closed_form_counterweights",
           "printed_counterweights", "reported_counterweights", "counterweights_from_design",
           "REPORTED_COUNTERWEIGHTS_KG", "copy_parameters", "ReactionlessWrist", "ReactionlessWristConfig",
           "WristIntegrator", "WristCommand", "WristRun", "PaminsaController", "PaminsaRun"]

#: the paper's actuators: M_1, M_3 (revolute, in-plane), M_v (linear, vertical), then the wrist
ACTUATED = ("leg1_guide", "leg3_guide", "leg1_slider", "wrist_phi", "wrist_theta", "wrist_psi")
_LINK_NAMES = ("link1_EC", "link2_DF", "link3_AE", "link4_AF", "link5_guide", "link6_BG",
               "link7_slider", "link8_atF")
#: link frame of the column at beta = 0: columns (e_z, e_y, -e_x)
_COLUMN = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
#: link frame of a pantograph link in the column frame at elevation 0: columns (u, n, e_z)
_PANTOGRAPH = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
#: a frame on a pantograph link whose z axis is the leg plane's normal n (the link's y)
_IN_PLANE = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
_EX, _EY, _EZ = np.eye(3)
_MINUS_N = np.array([0.0, -1.0, 0.0])


def body_names() -> list[str]:
    """The 38 bodies, in the closed form's order (``PaminsaModel.body_names``)."""
    names = ["platform"]
    for i in (1, 2, 3):
        names += [f"leg{i}.{n}" for n in _LINK_NAMES]
        names += [f"leg{i}.CP1_atA", f"leg{i}.CP2_atF", f"leg{i}.CP3_atL"]
    return names + ["vertical_counter_mass", "wrist1", "wrist2", "wrist3"]


@dataclass(frozen=True)
class PaminsaLayout:
    """The layout of Section II.A as reconstructed (A8), the same as ``PaminsaModel``'s:
    ``platform_joint_offset`` C_i - P (3, 3), ``slider_line`` B_h,i (3, 2), ``guide_pivot`` M_i
    (3, 2), ``vertical_mass_xy`` (2,)."""
    platform_joint_offset: np.ndarray
    slider_line: np.ndarray
    guide_pivot: np.ndarray
    vertical_mass_xy: np.ndarray


def paminsa_layout(params) -> PaminsaLayout:
    """J_1 = P + (-a, -b), J_2 = P + (-a, b), J_3 = P + (d, 0); C_i = J_i - l_CJ e_z; at the nominal
    pose, B_h,i = C_h,i + (k-1) rho u0_i, A_h,i = B_h,i + rho u0_i, M_i = A_h,i - c/2 g0_i with the
    legs pointing along u0 = (-1, 0), (-1, 0), (1, 0) and the guides along g0 = (0, 1), (0, 1),
    (1, 0) (A8); the vertical counter-mass on the vertical through the B_i's centroid (A9)."""
    p = params
    j_off = np.array([[-p.a, -p.b, 0.0], [-p.a, p.b, 0.0], [p.d, 0.0, 0.0]])
    u0 = np.array([[-1.0, 0.0], [-1.0, 0.0], [1.0, 0.0]])
    g0 = np.array([[0.0, 1.0], [0.0, 1.0], [1.0, 0.0]])
    c_off = j_off - p.length_CJ * _EZ
    C0 = np.asarray(p.nominal_platform, float)[:2] + c_off[:, :2]
    B = C0 + (p.k - 1.0) * p.nominal_rho * u0
    M = B + p.nominal_rho * u0 - 0.5 * p.c * g0
    v = B.mean(axis=0) if p.vertical_mass_at_centroid else np.asarray(p.vertical_mass_xy, float)
    return PaminsaLayout(c_off, B, M, np.array(v, float))


def _T(xyz=(0.0, 0.0, 0.0), R=None) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = xyz
    if R is not None:
        T[:3, :3] = R
    return T


# ---- counterweights ------------------------------------------------------------------------------
# Counterweights for complete shaking-force balancing (Briot & Arakelian 2009, eqs 6-16): the
# paper's fast path and the regression test of the general method.
#
# 1. `closed_form_counterweights` -- the paper's closed forms, re-derived for the
#    reconstructed leg. Writing every leg point as an affine combination of A, C and E
#    (D = E + (C-E)/k, F = A + (C-E)/k, B = ((k-1)A + C)/k) and using G_A = G_C,h/(1-k),
#    G_B = G_C,z/k, the momentum of leg i is
#    m_C1 v_C,h + m_C2 v_C,z e_z + m_E v_E + (m5 v_S5 + m_CP3 v_L). Force balance needs
#    m_E = 0 (eq 12 -> eq 15), m_C1 = 0 (eq 10 -> eq 14), m5 + r m_CP3 = 0 (eq 13 -> eq 16), and a
#    vertical counter-mass sum_i m_C2,i moving as -z_P (eq 11).
#
#    Corrections to the printed equations (each checked by the general method, 2., and by the
#    simulated shaking force):
#
#    * eq 6 / eq 11 (m_C2): must contain + 2 m8 / (2k) -- link 8 sits at F, which moves vertically,
#      and eqs 7, 8, 12 already place it there. Printed eq 11 gives 3 x 3.1033 = 9.310 kg of vertical
#      counter-mass; the correct value is 9.615 kg.
#    * eq 7: (m1 + m2)/(2k) must be (m1 + m2/k)/2, as eq 10 has it.
#    * eq 13: "OL_i = OO_i + r OS_5i" must read M_iL_i = r M_iS_5i (the pivot of link 5 is M_i).
#    * k is D_iF_i / B_iF_i (the paper prints B_iF_i / D_iF_i, which would make BF = 1.26 m).
#    * eqs 14-16 as printed are algebraically right: 2.7915 / 1.3865 / 0.436 kg.
#    * the paper *reports* 4.49 / 1.69 / 0.436 kg. 1.69 is eq 15 with its -2 m8 term dropped
#      (1.6915); 4.49 is not reproduced by eq 14 under any misprint we tried. The reported masses
#      leave ~17 N of shaking force (63 % of the unbalanced peak) -- see the case summary.
#
# 2. The general method, `mechbal.balance.force` (least squares of the linear momentum of
#    the general model over sampled closed motions), with the slots of ``cases/paminsa.toml``'s
#    ``[balance]`` table: the ``paminsa`` runner sizes with it and reports the closed form beside it
#    (`counterweights_from_design` reads its design back into a `CounterweightSet`).
#    With the legs tied (identical legs) every mass is determined; untied, legs 1 and 2 (one
#    actuator) leave combinations of their masses undetermined, as the paper's cycle alone does
#    (no x motion).

#: the values the paper reports (Sec. III) [kg]; the vertical counter-mass is not given
REPORTED_COUNTERWEIGHTS_KG = {"cp1": 4.49, "cp2": 1.69, "cp3": 0.436}


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


def closed_form_counterweights(params) -> CounterweightSet:
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


def printed_counterweights(params) -> CounterweightSet:
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


def reported_counterweights(params, vertical: float) -> CounterweightSet:
    """The masses the paper reports, with the given vertical counter-mass (the paper gives none)."""
    p = REPORTED_COUNTERWEIGHTS_KG
    return CounterweightSet([p["cp1"]] * 3, [p["cp2"]] * 3, [p["cp3"]] * 3, vertical, "paper reported")


def counterweights_from_design(design: dict, source: str) -> CounterweightSet:
    """A `CounterweightSet` from the design of a balancing method (``BalanceResult.design``)
    whose slots carry the paper's names (``leg<i>.CP1_atA``, ``leg<i>.CP2_atF``,
    ``leg<i>.CP3_atL``, ``vertical_counter_mass``: ``cases/paminsa.toml``'s ``[balance]``).
    KeyError naming the missing slot otherwise."""
    def mass(name):
        if name not in design:
            raise KeyError(f"the design has no slot '{name}' (the paper's counterweights are "
                           "leg<i>.CP1_atA, leg<i>.CP2_atF, leg<i>.CP3_atL and vertical_counter_mass)")
        return float(design[name].mass)

    return CounterweightSet([mass(f"leg{i}.CP1_atA") for i in (1, 2, 3)],
                            [mass(f"leg{i}.CP2_atF") for i in (1, 2, 3)],
                            [mass(f"leg{i}.CP3_atL") for i in (1, 2, 3)],
                            mass("vertical_counter_mass"), source)


def _balanced(params):
    return closed_form_counterweights(params).apply(params)


def paminsa_mechanism(params, balanced: bool = True, *, name: str | None = None) -> Mechanism:
    """PAMINSA as a closed `mechbal.Mechanism` (module docstring) from
    ``mechbal.PaminsaParameters`` (`parameters_from_config`).
    ``balanced=True``: the closed-form counterweights (eqs 11, 14-16 corrected:
    `closed_form_counterweights`) replace the parameters' own;
    ``balanced=False``: the parameters' counterweights as given (none in the case file)."""
    p = _balanced(params) if balanced else params
    lay = paminsa_layout(p)
    k = p.k
    cw = p.counterweights
    R, P, F = _core.JointType.revolute, _core.JointType.prismatic, _core.JointType.fixed  # noqa: F841
    link_mass = list(p.link_mass)
    J = [np.diag(np.asarray(v, float)) for v in p.link_inertia]
    Jw = [np.diag(np.asarray(v, float)) for v in p.wrist_inertia]
    zero3 = np.zeros((3, 3))
    lAE, lDF, lCE, lAF = p.length_AE, p.length_DF, p.length_CE, p.length_AF
    x_D, x_F = -(k - 1.0) / k * lDF, lDF / k          # on link 2, from B
    x_E, x_C = -lCE / k, lCE * (k - 1.0) / k           # on link 1, from D

    joints = [_core.Joint("platform_x", P, "base", _T(), _EX),
              _core.Joint("platform_y", P, "platform_x", _T(), _EY),
              _core.Joint("platform_z", P, "platform_y", _T(), _EZ),
              _core.Joint("wrist_phi", R, "platform_z", _T(), _EZ),
              _core.Joint("wrist_theta", R, "wrist_phi", _T(), _EX),
              _core.Joint("wrist_psi", R, "wrist_theta", _T(), _EZ)]
    bodies = {"platform": _core.Body("platform", "platform_z", float(p.platform_mass), np.zeros(3), zero3,
                                     "payload")}
    for w in range(3):
        n = f"wrist{w + 1}"
        bodies[n] = _core.Body(n, ("wrist_phi", "wrist_theta", "wrist_psi")[w], 0.0, np.zeros(3), Jw[w], "link")
    frames, loops = [], []
    for i in range(3):
        L = f"leg{i + 1}"
        Bh, Mh = lay.slider_line[i], lay.guide_pivot[i]
        mimic = {} if i == 0 else dict(mimic_joint="leg1_slider", mimic_ratio=1.0, mimic_offset=0.0)
        joints += [
            _core.Joint(f"{L}_slider", P, "base", _T((Bh[0], Bh[1], 0.0)), _EZ, **mimic),
            _core.Joint(f"{L}_column", R, f"{L}_slider", _T(R=_COLUMN), _EX),
            _core.Joint(f"{L}_link2", R, f"{L}_column", _T(R=_PANTOGRAPH), _MINUS_N),
            _core.Joint(f"{L}_link1", R, f"{L}_link2", _T((x_D, 0.0, 0.0)), _MINUS_N),
            _core.Joint(f"{L}_link3", R, f"{L}_link1", _T((x_E, 0.0, 0.0)), _MINUS_N),
            _core.Joint(f"{L}_link4", R, f"{L}_link2", _T((x_F, 0.0, 0.0)), _MINUS_N),
            _core.Joint(f"{L}_guide", R, "base", _T((Mh[0], Mh[1], p.z_A)), _EZ),
            _core.Joint(f"{L}_stroke", P, f"{L}_guide", _T(), _EX)]
        # (body, link, com along the link's x, inertia): the closed form's body frames
        for j, link, x in ((0, "link1", 0.5 * (x_E + x_C)), (1, "link2", 0.5 * (x_D + x_F)),
                           (2, "link3", -0.5 * lAE), (3, "link4", -0.5 * lAF),
                           (4, "guide", p.length_MS5), (5, "column", 0.5 * p.length_BG),
                           (6, "slider", 0.0), (7, "link2", x_F)):
            n = f"{L}.{_LINK_NAMES[j]}"
            bodies[n] = _core.Body(n, f"{L}_{link}", float(link_mass[j]), np.array([x, 0.0, 0.0]), J[j], "link")
        for n, link, x, m in ((f"{L}.CP1_atA", "link3", -lAE, cw.at_A[i]),
                              (f"{L}.CP2_atF", "link2", x_F, cw.at_F[i]),
                              (f"{L}.CP3_atL", "guide", p.cp3_ratio * p.length_MS5, cw.at_L[i])):
            bodies[n] = _core.Body(n, f"{L}_{link}", float(m), np.array([x, 0.0, 0.0]), zero3, "counterweight")
        frames += [_core.Frame(f"{L}_A_link3", f"{L}_link3", _T((-lAE, 0.0, 0.0), _IN_PLANE)),
                   _core.Frame(f"{L}_A_link4", f"{L}_link4", _T((-lAF, 0.0, 0.0))),
                   _core.Frame(f"{L}_A_guide", f"{L}_stroke", _T()),
                   _core.Frame(f"{L}_C_link1", f"{L}_link1", _T((x_C, 0.0, 0.0))),
                   _core.Frame(f"{L}_C_platform", "platform_z", _T(lay.platform_joint_offset[i]))]
        loops += [_core.LoopConstraint(f"{L}_parallelogram", _core.LoopType.planar_point,
                                       f"{L}_A_link3", f"{L}_A_link4"),
                  _core.LoopConstraint(f"{L}_guide", _core.LoopType.point, f"{L}_A_link3", f"{L}_A_guide"),
                  _core.LoopConstraint(f"{L}_platform", _core.LoopType.point, f"{L}_C_link1",
                                       f"{L}_C_platform")]
    v = lay.vertical_mass_xy
    P0z = float(np.asarray(p.nominal_platform, float)[2])
    offset = p.vertical_mass_z0 + P0z + (k - 1.0) * p.z_A - p.length_CJ
    joints.append(_core.Joint("vertical_counter_mass", P, "base", _T((v[0], v[1], 0.0)), _EZ,
                              mimic_joint="leg1_slider", mimic_ratio=-k, mimic_offset=float(offset)))
    bodies["vertical_counter_mass"] = _core.Body("vertical_counter_mass", "vertical_counter_mass",
                                                 float(cw.vertical), np.zeros(3), zero3, "counterweight")
    variant = "balanced" if balanced else "unbalanced"
    return Mechanism.from_description(joints, [bodies[n] for n in body_names()], frames, (0.0, 0.0, -9.81),
                                      name=name or f"paminsa ({variant})", loops=loops, actuated=list(ACTUATED))


def _elevation(d: np.ndarray, u: np.ndarray) -> float:
    """Elevation in the leg plane of a base-frame vector d (u: the plane's horizontal direction)."""
    return float(np.arctan2(d[2], d[:2] @ u[:2]))


def paminsa_initial_guess(mech: Mechanism, params, P, wrist_angles=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Every coordinate of `paminsa_mechanism` at platform position P, from the closed form's
    leg points (``PaminsaModel.leg_points``: the assembly of A6, elbow outward and up)."""
    model = _core.PaminsaModel(params)
    pts, status = model.leg_points(np.asarray(P, float))
    if status != _core.Status.ok:
        raise ValueError(f"P = {list(P)}: the pantographs cannot reach it ({status})")
    lay = paminsa_layout(params)
    values = {"platform_x": P[0], "platform_y": P[1], "platform_z": P[2], "wrist_phi": wrist_angles[0],
              "wrist_theta": wrist_angles[1], "wrist_psi": wrist_angles[2]}
    for i in range(3):
        A, B, C, D, E, F = pts[i]
        L = f"leg{i + 1}"
        w = A[:2] - B[:2]
        u = np.append(w / np.linalg.norm(w), 0.0)
        g_df, g_ec, g_ae = _elevation(F - D, u), _elevation(C - E, u), _elevation(E - A, u)
        g = A[:2] - lay.guide_pivot[i]
        values.update({f"{L}_slider": B[2], f"{L}_column": np.arctan2(u[1], u[0]), f"{L}_link2": g_df,
                       f"{L}_link1": g_ec - g_df, f"{L}_link3": g_ae - g_ec, f"{L}_link4": g_ec - g_df,
                       f"{L}_guide": np.arctan2(g[1], g[0]), f"{L}_stroke": np.linalg.norm(g)})
    return np.array([values[n] for n in mech.joint_names], float)


def paminsa_actuated_motion(mech: Mechanism, params, P, Pd, Pdd, wrist=None, wrist_rates=None,
                            wrist_accelerations=None):
    """(q#, v#, a#) (N, 6) of the actuated joints of `paminsa_mechanism` for a platform
    motion P, Pd, Pdd (N, 3) and a wrist motion (N, 3; default still at zero): the closed-form
    inverse kinematics (``PaminsaModel.inverse_kinematics``) and its derivatives. alpha_i is the
    angle of A_h,i - M_i with A_h,i = (k B_h,i - C_h,i)/(k - 1); z_B = z_A + (z_P - l_CJ - z_A)/k."""
    P, Pd, Pdd = (np.atleast_2d(np.asarray(x, float)) for x in (P, Pd, Pdd))
    N = len(P)
    zeros = np.zeros((N, 3))
    wq = zeros if wrist is None else np.atleast_2d(np.asarray(wrist, float))
    wv = zeros if wrist_rates is None else np.atleast_2d(np.asarray(wrist_rates, float))
    wa = zeros if wrist_accelerations is None else np.atleast_2d(np.asarray(wrist_accelerations, float))
    lay = paminsa_layout(params)
    k = params.k
    values = {}
    for i in (0, 2):
        Ah = (k * lay.slider_line[i] - (P[:, :2] + lay.platform_joint_offset[i, :2])) / (k - 1.0)
        g, gd, gdd = Ah - lay.guide_pivot[i], -Pd[:, :2] / (k - 1.0), -Pdd[:, :2] / (k - 1.0)
        r2 = np.sum(g * g, axis=1)
        cross = lambda a, b: a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]  # noqa: E731
        ad = cross(g, gd) / r2
        add = (cross(g, gdd) - 2.0 * ad * np.sum(g * gd, axis=1)) / r2
        values[f"leg{i + 1}_guide"] = (np.arctan2(g[:, 1], g[:, 0]), ad, add)
    values["leg1_slider"] = (params.z_A + (P[:, 2] - params.length_CJ - params.z_A) / k, Pd[:, 2] / k,
                             Pdd[:, 2] / k)
    for w, n in enumerate(("wrist_phi", "wrist_theta", "wrist_psi")):
        values[n] = (wq[:, w], wv[:, w], wa[:, w])
    names = mech.actuated_names
    return tuple(np.stack([values[n][j] for n in names], axis=1) for j in range(3))


def paminsa_case_toml(config="paminsa", balanced: bool = True, samples: int = 501, *,
                      reactionless: bool = False) -> str:
    """The ``kind = "mechanism"`` case file of a ``paminsa`` case's mechanism (balanced: the
    closed-form counterweights): what ``python/mechbal/papers/paminsa/cases/paminsa-linkage.toml`` holds for the
    shipped case. Its trajectory is rest-to-rest in the actuated joints between the actuator
    positions of the case's start and end platform positions (the case itself moves P on a straight
    line: the same end points, not the same path), wrist still at the case's initial angles.

    ``reactionless=True``: ``paminsa-reactionless.toml``, the same mechanism and trajectory with a
    ``[control]`` table (kind reactionless, the three wrist joints balancing the moment, the
    case's ``[wrist]`` integrator, rate, damping and rate limit): PAMINSA's reactionless wrist
    through the general controller (``mechbal run paminsa-reactionless``)."""
    from mechbal.config import read_case
    from mechbal.papers._toml import case_toml

    cfg = read_case(config) if isinstance(config, str) else config
    params = parameters_from_config(cfg)
    mech = paminsa_mechanism(params, balanced)
    tr, wrist = cfg["trajectory"], np.asarray(cfg["wrist"]["initial_angles"], float)
    ends = np.array([tr["start"], tr["end"]], float)
    still = np.tile(wrist, (2, 1))
    qa, _, _ = paminsa_actuated_motion(mech, params, ends, np.zeros((2, 3)), np.zeros((2, 3)), still)
    pb = _balanced(params) if balanced else params
    traj = {"law": tr.get("law", "quintic"), "start": qa[0], "end": qa[1], "duration": tr["duration"],
            # a guess the loop solve refines: rounded to 1e-12, so that the last bits of the trigonometry
            # (which vary with the platform's libm and memory alignment) leave the written file the same
            "samples": samples, "initial_guess": np.round(paminsa_initial_guess(mech, pb, ends[0], wrist), 12)}
    variant = "balanced: closed-form counterweights and vertical counter-mass" if balanced else "unbalanced"
    name = "paminsa-reactionless" if reactionless else "paminsa-linkage"
    generator = (f'mechbal.papers.paminsa.paminsa_case_toml("{cfg["case"]["name"]}"'
                 + (", reactionless=True)" if reactionless else ")"))
    header = f"""\
PAMINSA (Briot & Arakelian 2009, AIM, Section II; {variant}) as data on the general model:
three pantograph legs (sliders, columns, pantograph links 1-4, rotating guides with carriages),
the translating platform, counterweights CP1-CP3, the vertical counter-mass (a gear coupling of
the vertical actuator) and the z-x-z wrist: 38 bodies, 9 loop closures, actuated M_1, M_3, M_v
and the wrist. The reconstructed geometry (A1-A11) is that of paminsa.toml; joints, frames and
loops are explained in mechbal.papers.paminsa. Generated by
{generator}; the closed form PaminsaModel
equals it to 1e-10 (tests/python/test_papers_loops.py). Do not edit by hand: regenerate.
The trajectory is rest-to-rest in the actuated joints between the actuator positions of the
paper's start and end platform positions (the paminsa case moves P on a straight line)."""
    if reactionless:
        header += """
Reactionless control through the general controller (mechbal.control.ReactionlessController):
the three wrist joints are the balancing joints and cancel the shaking moment (Briot & Arakelian
2009, eqs 23-26: the reactionless wrist is the special case). `mechbal run paminsa-reactionless`
compares the wrist held at its start (uncontrolled) with the controlled wrist; the wrist angles
and rates equal the closed-form ReactionlessWrist's to 1e-9 (tests/python/test_reactionless_cases.py)."""
    comments = {"platform_x": "passive: the platform translates only (module docstring)",
                "leg1_slider": "actuated: M_v, the common height z_B of the B_i",
                "leg2_slider": "geared to M_v", "leg3_slider": "geared to M_v",
                "leg1_guide": "actuated: M_1", "leg2_guide": "passive: M_2", "leg3_guide": "actuated: M_3",
                "vertical_counter_mass": "moves as -z_P: geared to M_v with ratio -k"}
    comments["trajectory.start"] = "actuated joints in the model's order: " + ", ".join(mech.actuated_names)
    title = (f"PAMINSA ({variant}) on the general model" if not reactionless else
             "PAMINSA: the reactionless wrist through the general controller")
    text = case_toml(mech, name=name, title=title, header=header, trajectory=traj, comments=comments)
    if reactionless:
        w = cfg["wrist"]
        text += ("\n[control]\n"
                 'kind = "reactionless"\n'
                 'balancing_joints = ["wrist_phi", "wrist_theta", "wrist_psi"]   # the z-x-z wrist\n'
                 'cancel = ["moment"]\n'
                 f'integrator = "{w.get("integrator", "rk4")}"   # the [wrist] table of {cfg["case"]["name"]}.toml\n'
                 f'rate_hz = {float(w.get("rate_hz", 1000.0))!r}\n'
                 f'damping = {float(w.get("damping", 1e-2))!r}\n'
                 f'max_rate = {float(w.get("max_rate", 100.0))!r}\n')
    return text

# ---- a case's parameters (the runner, the balance adapter and the case-file generator) ----
_GEOMETRY_SCALARS = ("k", "a", "b", "c", "d", "e", "f", "length_BG", "length_AE", "length_DF",
                     "length_CE", "length_AF", "length_CJ", "length_MS5", "length_MO", "nominal_rho",
                     "z_A", "elbow", "vertical_mass_z0", "cp3_ratio")


def parameters_from_config(config):
    """mechbal.PaminsaParameters (without counterweights) from the [geometry], [masses],
    [inertias] tables of a case (validated, or a dict validated here); ConfigError names the
    field. The C++ model validates the rest (ValueError naming the field)."""
    case = validate_case(config, warn=False)
    p = PaminsaParameters()
    g = case.geometry
    for key in _GEOMETRY_SCALARS:
        setattr(p, key, getattr(g, key))
    p.nominal_platform = np.array(g.nominal_platform, float)
    if isinstance(g.vertical_mass_xy, str):  # "centroid"
        p.vertical_mass_at_centroid = True
    else:
        p.vertical_mass_at_centroid = False
        p.vertical_mass_xy = np.array(g.vertical_mass_xy, float)
    p.platform_mass = case.masses.platform
    p.link_mass = [float(x) for x in case.masses.links]
    p.link_inertia = [np.array(v, float) for v in case.inertias.links]
    p.wrist_inertia = [np.array(v, float) for v in case.inertias.wrist]
    return p


# importing the schema registers this paper's case kind (mechbal.registry imports this package)
from mechbal.papers.paminsa import schema as _schema  # noqa: E402,F401
