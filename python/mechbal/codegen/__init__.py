"""Code generation for one mechanism: a self-contained C++17 header specialised to one model.

`generate(mechanism)` walks the model with its constants known (placements, axes, masses,
inertias, gear ratios, springs) and writes straight-line code for that mechanism only: constants
folded, structural zeros pruned, sines and cosines shared, common subexpressions shared as the
expressions are built (`mechbal.codegen.expr`). The header needs nothing but ``<cmath>`` (the
Eigen overloads need ``<Eigen/Core>`` and can be left out with ``MECHBAL_GENERATED_NO_EIGEN``):
no heap, no exceptions, no virtual calls. It provides, for the model's tree (revolute, prismatic
and fixed joints, gear couplings, springs):

* ``inverse_dynamics(q, v, a, tau)``: tau = M a + C v + G + K (springs included, as the library);
* ``gravity_torque(q, tau)``, ``mass_matrix(q, M)``, ``center_of_mass(q, c)``;
* ``shaking_wrench(q, v, a, F, M)``: the momentum rates about O; ``base_reaction(...)``;
* ``momentum_matrix(q, A)``: [P; H_O] = A v (6 x dof, column-major);
* ``frame_placements(q, R, p)``: every named frame in O (R column-major, 9 per frame).

With loop closures it adds the loop solve and the closed mechanism's tick: ``loop_residual``,
``newton_step``, ``closed_projection`` (v = C v#, a = C a# + c), ``closed_evaluate`` and
``closed_evaluate_forces`` (the closure, the projection and the shaking wrench or the actuated
forces tau# = C^T tau in one pass), ``closed_motion``, ``closed_shaking_wrench`` and
``closed_inverse_dynamics`` (bounded Newton from a warm start, with a status), and the ticks
``closed_tick`` and ``closed_inverse_dynamics_tick`` (warm start moved from the last tick). `build`
compiles the header into a small shared library with the installed C++ compiler (cached by the
hash of the generated code) and returns a `GeneratedModule` whose methods mirror `Mechanism`'s,
for a Python harness that wants the fast path.

Regenerating the same model gives byte-identical output; the header names the model, the
generator's version and a hash of the input.
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .emit import function_body
from .expr import Graph
from . import tree as _tree

#: bumped when the generated code changes for the same input
GENERATOR_VERSION = 1
#: the largest tree generated unrolled (the code grows with the square of the depth)
MAX_JOINTS = 64


class CodegenError(ValueError):
    """A mechanism that cannot be generated, or a build that failed; the message says why."""


@dataclass(frozen=True)
class GeneratedCode:
    """A generated header and what it provides."""

    name: str                 # the C++ namespace: mechbal_generated::<name>
    header: str               # the whole header text
    dof: int
    coordinate_names: list[str]
    frame_names: list[str]
    input_hash: str           # sha256 of the model's constants as the generator read them
    operations: dict[str, int] = field(default_factory=dict)  # arithmetic operations per function
    actuated: list[int] = field(default_factory=list)  # closed mechanisms: indices of q# in q
    passive: list[int] = field(default_factory=list)   # and of the passive coordinates

    @property
    def closed(self) -> bool:
        return bool(self.passive)

    def write(self, directory: str | Path) -> Path:
        """Write ``<name>.hpp`` into `directory` (created if missing); returns its path."""
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        path = out / f"{self.name}.hpp"
        path.write_text(self.header)
        return path


def _identifier(name: str) -> str:
    ident = re.sub(r"[^A-Za-z0-9_]", "_", name)
    if not ident or ident[0].isdigit():
        ident = "m_" + ident
    return ident


def _input_text(tc: _tree.TreeConstants) -> str:
    """A canonical text of every constant the generator reads (the input hash is over it)."""
    def arr(x) -> str:
        return ",".join(repr(float(v)) for v in np.asarray(x, dtype=float).ravel())
    lines = [f"dof {tc.dof}", "coordinates " + ",".join(tc.coordinate_names), "gravity " + arr(tc.gravity)]
    for link in tc.links:
        lines.append(f"link {link.name} {link.parent} {link.kind} {arr(link.R0)} {arr(link.p0)} "
                     f"{arr(link.axis)} {link.coordinate} {link.ratio!r} {link.offset!r} {link.mass!r} "
                     f"{arr(link.first_moment)} {arr(link.inertia_origin)} {link.moves}")
    for name, (link, P) in tc.frames.items():
        lines.append(f"frame {name} {link} {arr(P)}")
    for la, aa, lb, ab, k, t0 in tc.springs:
        lines.append(f"spring {la} {arr(aa)} {lb} {arr(ab)} {k!r} {t0!r}")
    return "\n".join(lines) + "\n"


def generate(mechanism, *, name: str | None = None, frames: list[str] | None = None,
             max_joints: int = MAX_JOINTS) -> GeneratedCode:
    """Generate the C++ header of `mechanism` (a `mechbal.Mechanism`).

    `frames`: the named frames whose placements ``frame_placements`` computes (default: every
    frame of the model). Raises `CodegenError` for a model with more than `max_joints` joints
    (the unrolled code would be too large)."""
    model = mechanism.model
    links = model.num_links - 1
    if links > max_joints:
        raise CodegenError(f"mechanism {mechanism.name!r} has {links} joints, more than the "
                           f"generation limit max_joints = {max_joints}")
    tc = _tree.tree_constants(mechanism)
    frame_names = list(tc.frames) if frames is None else list(frames)
    for f in frame_names:
        if f not in tc.frames:
            raise CodegenError(f"frames: {f!r} is not a frame of {mechanism.name!r} "
                               f"(frames: {', '.join(tc.frames)})")
    ident = _identifier(name or mechanism.name)
    input_text = _input_text(tc) + "frames " + ",".join(frame_names) + "\n"
    digest = hashlib.sha256(input_text.encode()).hexdigest()
    n = tc.dof

    bodies: list[str] = []
    operations: dict[str, int] = {}

    def function(signature: str, doc: str, build, inputs=("q",), sizes=None) -> None:
        g = Graph()
        sizes = sizes or {}
        syms = {k: [g.input(f"{k}{i}") for i in range(sizes.get(k, n))] for k in inputs}
        outputs = build(g, syms)
        names = {f"{k}{i}": f"{k}[{i}]" for k in inputs for i in range(sizes.get(k, n))}
        lines, ops = function_body(g, outputs, names)
        params = [x.strip().split()[-1].lstrip("*") for x in signature.split("(", 1)[1].rstrip(")").split(",")]
        unused = [x for x in params if not any(f"{x}[" in line for line in lines)]
        lines = [f"  static_cast<void>({x});" for x in unused] + lines
        fname = signature.split("(")[0].split()[-1]
        operations[fname] = ops
        bodies.append(f"/// {doc}\ninline {signature} noexcept {{\n" + "\n".join(lines) + "\n}\n")

    def id_outputs(g, s):
        tau, _ = _tree.newton_euler(g, tc, s["q"], s["v"], s["a"], gravity=True, springs=True)
        return [(f"tau[{i}]", tau[i]) for i in range(n)]

    def gravity_outputs(g, s):
        zero = [0.0] * n
        tau, _ = _tree.newton_euler(g, tc, s["q"], zero, zero, gravity=True, springs=False)
        return [(f"tau[{i}]", tau[i]) for i in range(n)]

    def mass_outputs(g, s):
        M = _tree.mass_matrix(g, tc, s["q"])
        return [(f"M[{c * n + r}]", M[r][c]) for c in range(n) for r in range(n)]

    def wrench_outputs(g, s):
        F, M = _tree.shaking_wrench(g, tc, s["q"], s["v"], s["a"])
        return [(f"force[{i}]", F[i]) for i in range(3)] + [(f"moment[{i}]", M[i]) for i in range(3)]

    def reaction_outputs(g, s):
        F, M = _tree.base_reaction(g, tc, s["q"], s["v"], s["a"])
        return [(f"force[{i}]", F[i]) for i in range(3)] + [(f"moment[{i}]", M[i]) for i in range(3)]

    def com_outputs(g, s):
        c = _tree.center_of_mass(g, tc, s["q"])
        return [(f"com[{i}]", c[i]) for i in range(3)]

    def momentum_outputs(g, s):
        A = _tree.momentum_matrix(g, tc, s["q"])
        return [(f"A[{c * 6 + r}]", A[r][c]) for c in range(n) for r in range(6)]

    def frame_outputs(g, s):
        out = []
        for k, f in enumerate(frame_names):
            R, p = _tree.frame_placement(g, tc, s["q"], f)
            out += [(f"R[{9 * k + 3 * c + r}]", R[r][c]) for c in range(3) for r in range(3)]
            out += [(f"p[{3 * k + i}]", p[i]) for i in range(3)]
        return out

    qva = ("q", "v", "a")
    function("void inverse_dynamics(const double* q, const double* v, const double* a, double* tau)",
             "tau = M(q) a + C(q, v) v + G(q) + K(q) [N m or N], gear couplings projected.",
             id_outputs, qva)
    function("void gravity_torque(const double* q, double* tau)", "G(q) [N m or N], gravity alone.",
             gravity_outputs)
    function("void mass_matrix(const double* q, double* M)", "M(q), dof x dof, column-major.",
             mass_outputs)
    function("void shaking_wrench(const double* q, const double* v, const double* a, double* force, "
             "double* moment)", "Shaking force dP/dt [N] and moment dH_O/dt [N m] about O.",
             wrench_outputs, qva)
    function("void base_reaction(const double* q, const double* v, const double* a, double* force, "
             "double* moment)", "Wrench the base exerts on the moving links, gravity included (about O).",
             reaction_outputs, qva)
    function("void center_of_mass(const double* q, double* com)", "Centre of mass of all bodies in O [m].",
             com_outputs)
    function("void momentum_matrix(const double* q, double* A)",
             "A(q), 6 x dof column-major, linear rows first: [P; H_O] = A v.", momentum_outputs)
    function("void frame_placements(const double* q, double* R, double* p)",
             "Placements in O of the frames listed above: R column-major (9 per frame), p (3 per frame).",
             frame_outputs)

    closed = bool(tc.loops)
    if closed:
        na, npas = len(tc.actuated), len(tc.passive)

        def residual_outputs(g, s):
            phi = _tree.loop_residual(g, tc, s["q"])
            return [(f"phi[{i}]", x) for i, x in enumerate(phi)]

        def newton_outputs(g, s):
            new, phi = _tree.newton_step(g, tc, s["q"])
            return [(f"q_next[{k}]", x) for k, x in zip(tc.passive, new)] + \
                [(f"phi[{i}]", x) for i, x in enumerate(phi)]

        def projection_outputs(g, s):
            v, a = _tree.closed_projection(g, tc, s["q"], s["v_actuated"], s["a_actuated"])
            return [(f"v[{k}]", v[k]) for k in range(n)] + [(f"a[{k}]", a[k]) for k in range(n)]

        def evaluation_outputs(g, s):
            phi = _tree.loop_residual(g, tc, s["q"])
            v, a = _tree.closed_projection(g, tc, s["q"], s["v_actuated"], s["a_actuated"])
            F, M = _tree.shaking_wrench(g, tc, s["q"], v, a)
            return ([(f"phi[{i}]", x) for i, x in enumerate(phi)] + [(f"v[{k}]", v[k]) for k in range(n)]
                    + [(f"a[{k}]", a[k]) for k in range(n)] + [(f"force[{i}]", F[i]) for i in range(3)]
                    + [(f"moment[{i}]", M[i]) for i in range(3)])

        def forces_outputs(g, s):
            phi = _tree.loop_residual(g, tc, s["q"])
            v, a = _tree.closed_projection(g, tc, s["q"], s["v_actuated"], s["a_actuated"])
            tau = _tree.closed_actuated_forces(g, tc, s["q"], v, a)
            return ([(f"phi[{i}]", x) for i, x in enumerate(phi)] + [(f"v[{k}]", v[k]) for k in range(n)]
                    + [(f"a[{k}]", a[k]) for k in range(n)] + [(f"tau[{i}]", x) for i, x in enumerate(tau)])

        actuated_sizes = {"v_actuated": na, "a_actuated": na}
        function("void loop_residual(const double* q, double* phi)",
                 "Phi(q): the loop-closure equations (num_equations values).", residual_outputs)
        function("void newton_step(const double* q, double* q_next, double* phi)",
                 "One Gauss-Newton step of the passive coordinates on Phi(q) = 0 (writes only the passive "
                 "entries of q_next, which must not be q) and Phi(q), the residual it started from.",
                 newton_outputs)
        function("void closed_projection(const double* q, const double* v_actuated, const double* a_actuated, "
                 "double* v, double* a)",
                 "At a closed q: v = C v#, a = C a# + c over every coordinate (the coupling-matrix method).",
                 projection_outputs, ("q", "v_actuated", "a_actuated"), actuated_sizes)
        function("void closed_evaluate(const double* q, const double* v_actuated, const double* a_actuated, "
                 "double* phi, double* v, double* a, double* force, double* moment)",
                 "At q, in one pass sharing the kinematics: Phi(q), v = C v#, a = C a# + c and the shaking "
                 "wrench of (q, v, a) (meaningful when Phi(q) is within the tolerance).",
                 evaluation_outputs, ("q", "v_actuated", "a_actuated"), actuated_sizes)
        function("void closed_evaluate_forces(const double* q, const double* v_actuated, "
                 "const double* a_actuated, double* phi, double* v, double* a, double* tau)",
                 "At q, in one pass: Phi(q), v = C v#, a = C a# + c and the actuated forces tau# = C^T "
                 "tau(q, v, a) (gravity and springs included) that drive that motion.",
                 forces_outputs, ("q", "v_actuated", "a_actuated"), actuated_sizes)

    from mechbal._core import __version__ as library_version
    coordinate_lines = "\n".join(f"//   q[{i}] = {c}" for i, c in enumerate(tc.coordinate_names))
    frame_lines = "\n".join(f"//   {k}: {f}" for k, f in enumerate(frame_names)) or "//   (none)"
    eigen = _eigen_overloads(n, len(frame_names))
    header = f"""// Generated by mechbal {library_version} (mechbal.codegen, generator {GENERATOR_VERSION}) for the
// mechanism {_comment(mechanism.name)}; do not edit, regenerate: `mechbal codegen`.
// Input hash (sha256 of the constants the generator read): {digest}
// Coordinates:
{coordinate_lines}
// Frames of frame_placements:
{frame_lines}
// Everything is noexcept, allocation-free and branch-free; arrays are the caller's.
#pragma once
#include <cmath>
#ifndef MECHBAL_GENERATED_NO_EIGEN
#include <Eigen/Core>
#endif

namespace mechbal_generated {{
namespace {ident} {{

constexpr int dof = {n};
constexpr int num_frames = {len(frame_names)};

{chr(10).join(bodies)}
{_closed_driver(tc) if closed else _computed_torque()}{eigen}
}}  // namespace {ident}
}}  // namespace mechbal_generated
"""
    return GeneratedCode(ident, header, n, list(tc.coordinate_names), frame_names, digest, operations,
                         list(tc.actuated) if closed else [], list(tc.passive) if closed else [])


def _computed_torque() -> str:
    """The computed-torque controller of an open tree over the generated inverse dynamics, with
    the library's semantics (control/computed_torque.hpp): the same checks in the same order, the
    same status bits, the held command on bad input."""
    return """/// Status bits of a controller tick, as the library's mechbal::Status.
enum ControlStatus : unsigned {{
  control_ok = 0u,
  non_finite_input = 1u << 0,  ///< an input was NaN or infinite: the held command is returned
  saturated = 1u << 2,         ///< the command was clipped to torque_limit
  out_of_range = 1u << 5,      ///< an input beyond the input range, or a command that overflowed
}};

/// Computed-torque control (tau = M(q) (a_des + kp (q_des - q) + kd (v_des - v)) + C v + G + K)
/// over the generated inverse dynamics: the library's ComputedTorque for this mechanism. Set kp,
/// kd (> 0) and, where wanted, torque_limit (+infinity: none) and the input range (+infinity:
/// none) before the first tick; step() is noexcept, allocation-free and bounded.
struct ComputedTorque {{
  double kp[dof];
  double kd[dof];
  double torque_limit[dof];
  double max_position = HUGE_VAL;
  double max_speed = HUGE_VAL;
  double max_acceleration = HUGE_VAL;
  double last_command[dof] = {{}};            ///< held on bad input (zero before the first good tick)
  double commanded_acceleration[dof] = {{}};  ///< the outer loop's acceleration of the last good tick

  ComputedTorque() noexcept {{
    for (int i = 0; i < dof; ++i) {{
      kp[i] = kd[i] = 0.0;
      torque_limit[i] = HUGE_VAL;
    }}
  }}

  unsigned step(const double* q, const double* v, const double* q_des, const double* v_des, const double* a_des,
                double* tau) noexcept {{
    bool finite = true;
    for (int i = 0; i < dof; ++i)
      finite = finite && std::isfinite(q[i]) && std::isfinite(v[i]) && std::isfinite(q_des[i]) &&
               std::isfinite(v_des[i]) && std::isfinite(a_des[i]);
    if (!finite) return hold(tau, non_finite_input);
    for (int i = 0; i < dof; ++i) {{
      if (!(std::fabs(q[i]) <= max_position && std::fabs(q_des[i]) <= max_position &&
            std::fabs(v[i]) <= max_speed && std::fabs(v_des[i]) <= max_speed &&
            std::fabs(a_des[i]) <= max_acceleration))
        return hold(tau, out_of_range);
    }}
    double a[dof], raw[dof];
    for (int i = 0; i < dof; ++i) {{
      a[i] = a_des[i] + kp[i] * (q_des[i] - q[i]) + kd[i] * (v_des[i] - v[i]);
      if (!std::isfinite(a[i])) return hold(tau, out_of_range);
    }}
    for (int i = 0; i < dof; ++i) commanded_acceleration[i] = a[i];
    inverse_dynamics(q, v, a, raw);
    for (int i = 0; i < dof; ++i) {{
      if (!std::isfinite(raw[i])) return hold(tau, out_of_range);
    }}
    unsigned status = control_ok;
    for (int i = 0; i < dof; ++i) {{
      if (raw[i] > torque_limit[i]) {{
        raw[i] = torque_limit[i];
        status = saturated;
      }} else if (raw[i] < -torque_limit[i]) {{
        raw[i] = -torque_limit[i];
        status = saturated;
      }}
      last_command[i] = tau[i] = raw[i];
    }}
    return status;
  }}

 private:
  unsigned hold(double* tau, unsigned status) const noexcept {{
    for (int i = 0; i < dof; ++i) tau[i] = last_command[i];
    return status;
  }}
}};

""".format()


def _closed_driver(tc) -> str:
    """The loop solve and the closed mechanism's tick, over the generated functions."""
    na, npas = len(tc.actuated), len(tc.passive)
    g = Graph()
    m = len(_tree.loop_residual(g, tc, [g.input(f"q{i}") for i in range(tc.dof)]))
    act = ", ".join(str(k) for k in tc.actuated)
    pas = ", ".join(str(k) for k in tc.passive)
    return f"""constexpr int num_actuated = {na};
constexpr int num_passive = {npas};
constexpr int num_equations = {m};
constexpr int actuated_index[num_actuated] = {{{act}}};
constexpr int passive_index[num_passive] = {{{pas}}};

/// Status of closed_motion: ok; loops_not_closed (no solution within max_iterations Newton steps
/// from the warm start: q, v, a are left unchanged); non_finite (a non-finite input or result).
enum ClosedStatus : int {{ ok = 0, loops_not_closed = 1, non_finite = 2 }};

namespace detail {{
inline bool closed(const double* phi, double tolerance, bool& finite) noexcept {{
  double largest = 0.0;
  finite = true;
  for (int i = 0; i < num_equations; ++i) {{
    finite = finite && std::isfinite(phi[i]);
    largest = std::fabs(phi[i]) > largest ? std::fabs(phi[i]) : largest;
  }}
  return finite && largest <= tolerance;
}}

/// The shaking wrench or the actuated forces, evaluated with the closure (closed_evaluate*).
struct Wrench {{
  double force[3], moment[3];
  void evaluate(const double* q, const double* va, const double* aa, double* phi, double* v, double* a) noexcept {{
    closed_evaluate(q, va, aa, phi, v, a, force, moment);
  }}
  bool finite() const noexcept {{
    bool out = true;
    for (int i = 0; i < 3; ++i) out = out && std::isfinite(force[i]) && std::isfinite(moment[i]);
    return out;
  }}
}};
struct Forces {{
  double tau[num_actuated];
  void evaluate(const double* q, const double* va, const double* aa, double* phi, double* v, double* a) noexcept {{
    closed_evaluate_forces(q, va, aa, phi, v, a, tau);
  }}
  bool finite() const noexcept {{
    bool out = true;
    for (int i = 0; i < num_actuated; ++i) out = out && std::isfinite(tau[i]);
    return out;
  }}
}};

/// The loop solve from q (actuated entries set) and the evaluation at its solution: at most
/// max_iterations Gauss-Newton steps, each followed by one fused evaluation, which also checks
/// the closure; q, v, a and `out` hold the result only when ok is returned.
template <class Output>
inline int solve(double* q, const double* v_actuated, const double* a_actuated, double* v, double* a,
                 Output& out, int max_iterations, double tolerance) noexcept {{
  double work[dof], next[dof], phi[num_equations], v_out[dof], a_out[dof];
  for (int i = 0; i < dof; ++i) work[i] = next[i] = q[i];
  bool finite = true;
  newton_step(work, next, phi);
  bool step = !closed(phi, tolerance, finite);
  if (!finite) return non_finite;
  for (int steps = 0;;) {{
    if (step) {{
      if (steps == max_iterations) return loops_not_closed;
      for (int i = 0; i < num_passive; ++i) work[passive_index[i]] = next[passive_index[i]];
      ++steps;
    }}
    out.evaluate(work, v_actuated, a_actuated, phi, v_out, a_out);
    if (closed(phi, tolerance, finite)) break;
    if (!finite) return loops_not_closed;
    newton_step(work, next, phi);
    step = true;
  }}
  for (int i = 0; i < dof; ++i) {{
    if (!std::isfinite(v_out[i]) || !std::isfinite(a_out[i])) return non_finite;
  }}
  if (!out.finite()) return non_finite;
  for (int i = 0; i < dof; ++i) {{
    q[i] = work[i];
    v[i] = v_out[i];
    a[i] = a_out[i];
  }}
  return ok;
}}

/// solve from q with the actuated entries replaced by q_actuated; q is written only on success.
template <class Output>
inline int closed(const double* q_actuated, const double* v_actuated, const double* a_actuated, double* q,
                  double* v, double* a, Output& out, int max_iterations, double tolerance) noexcept {{
  double work[dof];
  for (int i = 0; i < dof; ++i) work[i] = q[i];
  for (int i = 0; i < num_actuated; ++i) work[actuated_index[i]] = q_actuated[i];
  const int status = solve(work, v_actuated, a_actuated, v, a, out, max_iterations, tolerance);
  if (status == ok) {{
    for (int i = 0; i < dof; ++i) q[i] = work[i];
  }}
  return status;
}}
}}  // namespace detail

/// The closed mechanism's motion from its actuated coordinates: q (in: warm start of the passive
/// coordinates; out: the solution, actuated entries replaced) closes the loops to `tolerance`
/// (max |Phi|) by at most `max_iterations` Gauss-Newton steps, then v = C v#, a = C a# + c.
/// On failure q, v, a are left unchanged.
inline int closed_motion(const double* q_actuated, const double* v_actuated, const double* a_actuated,
                         double* q, double* v, double* a, int max_iterations = 20,
                         double tolerance = 1e-13) noexcept {{
  detail::Wrench out;
  return detail::closed(q_actuated, v_actuated, a_actuated, q, v, a, out, max_iterations, tolerance);
}}

/// closed_motion, then the shaking wrench of that motion (force dP/dt, moment dH_O/dt about O).
inline int closed_shaking_wrench(const double* q_actuated, const double* v_actuated, const double* a_actuated,
                                 double* q, double* force, double* moment, int max_iterations = 20,
                                 double tolerance = 1e-13) noexcept {{
  double v[dof], a[dof];
  detail::Wrench out;
  const int status = detail::closed(q_actuated, v_actuated, a_actuated, q, v, a, out, max_iterations, tolerance);
  if (status == ok) {{
    for (int i = 0; i < 3; ++i) {{
      force[i] = out.force[i];
      moment[i] = out.moment[i];
    }}
  }}
  return status;
}}

/// closed_motion, then the actuated forces tau# = C^T tau that drive it (gravity, springs).
inline int closed_inverse_dynamics(const double* q_actuated, const double* v_actuated, const double* a_actuated,
                                   double* q, double* tau_actuated, int max_iterations = 20,
                                   double tolerance = 1e-13) noexcept {{
  double v[dof], a[dof];
  detail::Forces out;
  const int status = detail::closed(q_actuated, v_actuated, a_actuated, q, v, a, out, max_iterations, tolerance);
  if (status == ok) {{
    for (int i = 0; i < num_actuated; ++i) tau_actuated[i] = out.tau[i];
  }}
  return status;
}}

/// What a tick keeps of the last one, for the warm start: the solved q, v, a and the actuated
/// coordinates and rates they were solved for. `valid` is false before the first good tick.
struct ClosedState {{
  double q[dof] = {{}};
  double v[dof] = {{}};
  double a[dof] = {{}};
  double q_actuated[num_actuated] = {{}};
  double v_actuated[num_actuated] = {{}};
  bool valid = false;
}};

namespace detail {{
/// One tick from `state`: the passive coordinates predicted from the last solution (see
/// closed_tick), then solve; `state` is updated on success.
template <class Output>
inline int tick(ClosedState& state, const double* q_actuated, const double* v_actuated, const double* a_actuated,
                Output& out, int max_iterations, double tolerance) noexcept {{
  double q[dof], v[dof], a[dof];
  for (int i = 0; i < dof; ++i) q[i] = state.q[i];
  if (state.valid) {{
    double num = 0.0, den = 0.0;
    for (int i = 0; i < num_actuated; ++i) {{
      const double rate = 0.5 * (v_actuated[i] + state.v_actuated[i]);
      num += (q_actuated[i] - state.q_actuated[i]) * rate;
      den += rate * rate;
    }}
    const double s = den > 0.0 ? num / den : 0.0;
    if (std::isfinite(s)) {{
      for (int i = 0; i < num_passive; ++i) {{
        const int k = passive_index[i];
        q[k] = state.q[k] + s * (state.v[k] + 0.5 * s * state.a[k]);
      }}
    }}
  }}
  for (int i = 0; i < num_actuated; ++i) q[actuated_index[i]] = q_actuated[i];
  const int status = solve(q, v_actuated, a_actuated, v, a, out, max_iterations, tolerance);
  if (status != ok) return status;
  for (int i = 0; i < dof; ++i) {{
    state.q[i] = q[i];
    state.v[i] = v[i];
    state.a[i] = a[i];
  }}
  for (int i = 0; i < num_actuated; ++i) {{
    state.q_actuated[i] = q_actuated[i];
    state.v_actuated[i] = v_actuated[i];
  }}
  state.valid = true;
  return ok;
}}
}}  // namespace detail

/// A tick along a motion: the loops are closed from the last tick's solution moved to the new
/// actuated coordinates to second order (q + v s + a s^2 / 2, with s the time step that the
/// actuated displacement and rates imply, so that a motion run backwards or at another rate
/// predicts as well), then as closed_shaking_wrench; `state` is updated on success. Before the
/// first good tick, `state.q` is the warm start (set it, with state.valid = false).
inline int closed_tick(ClosedState& state, const double* q_actuated, const double* v_actuated,
                       const double* a_actuated, double* force, double* moment, int max_iterations = 20,
                       double tolerance = 1e-13) noexcept {{
  detail::Wrench out;
  const int status = detail::tick(state, q_actuated, v_actuated, a_actuated, out, max_iterations, tolerance);
  if (status == ok) {{
    for (int i = 0; i < 3; ++i) {{
      force[i] = out.force[i];
      moment[i] = out.moment[i];
    }}
  }}
  return status;
}}

/// closed_tick's warm start, then the actuated forces as closed_inverse_dynamics.
inline int closed_inverse_dynamics_tick(ClosedState& state, const double* q_actuated, const double* v_actuated,
                                        const double* a_actuated, double* tau_actuated, int max_iterations = 20,
                                        double tolerance = 1e-13) noexcept {{
  detail::Forces out;
  const int status = detail::tick(state, q_actuated, v_actuated, a_actuated, out, max_iterations, tolerance);
  if (status == ok) {{
    for (int i = 0; i < num_actuated; ++i) tau_actuated[i] = out.tau[i];
  }}
  return status;
}}

"""


def _comment(text: str) -> str:
    """A name made safe for a one-line C++ comment (printable ASCII, quoted)."""
    return '"' + "".join(c if 32 <= ord(c) < 127 and c != "\\" else "?" for c in text) + '"'


def _eigen_overloads(n: int, frames: int) -> str:
    return f"""#ifndef MECHBAL_GENERATED_NO_EIGEN
using Vector = Eigen::Matrix<double, dof, 1>;
using Matrix = Eigen::Matrix<double, dof, dof>;
using Vector3 = Eigen::Matrix<double, 3, 1>;
inline Vector inverse_dynamics(const Vector& q, const Vector& v, const Vector& a) noexcept {{
  Vector tau;
  inverse_dynamics(q.data(), v.data(), a.data(), tau.data());
  return tau;
}}
inline Vector gravity_torque(const Vector& q) noexcept {{
  Vector tau;
  gravity_torque(q.data(), tau.data());
  return tau;
}}
inline Matrix mass_matrix(const Vector& q) noexcept {{
  Matrix M;
  mass_matrix(q.data(), M.data());
  return M;
}}
inline Eigen::Matrix<double, 6, dof> momentum_matrix(const Vector& q) noexcept {{
  Eigen::Matrix<double, 6, dof> A;
  momentum_matrix(q.data(), A.data());
  return A;
}}
inline Vector3 center_of_mass(const Vector& q) noexcept {{
  Vector3 c;
  center_of_mass(q.data(), c.data());
  return c;
}}
#endif  // MECHBAL_GENERATED_NO_EIGEN
"""


# ---- building and loading -----------------------------------------------------------------------
def _cache_dir() -> Path:
    base = os.environ.get("MECHBAL_CACHE") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "mechbal")
    return Path(base) / "codegen"


_SHIM = """#define MECHBAL_GENERATED_NO_EIGEN
#include <new>
#include "{header}"
namespace g = mechbal_generated::{ident};
extern "C" {{
int mb_dof() {{ return g::dof; }}
int mb_num_frames() {{ return g::num_frames; }}
void mb_inverse_dynamics(const double* q, const double* v, const double* a, double* tau) {{ g::inverse_dynamics(q, v, a, tau); }}
void mb_gravity_torque(const double* q, double* tau) {{ g::gravity_torque(q, tau); }}
void mb_mass_matrix(const double* q, double* M) {{ g::mass_matrix(q, M); }}
void mb_shaking_wrench(const double* q, const double* v, const double* a, double* f, double* m) {{ g::shaking_wrench(q, v, a, f, m); }}
void mb_base_reaction(const double* q, const double* v, const double* a, double* f, double* m) {{ g::base_reaction(q, v, a, f, m); }}
void mb_center_of_mass(const double* q, double* c) {{ g::center_of_mass(q, c); }}
void mb_momentum_matrix(const double* q, double* A) {{ g::momentum_matrix(q, A); }}
void mb_frame_placements(const double* q, double* R, double* p) {{ g::frame_placements(q, R, p); }}
{closed}}}
"""

_SHIM_OPEN = """int mb_ct_size() {{ return static_cast<int>(sizeof(g::ComputedTorque)); }}
void mb_ct_init(void* c, const double* kp, const double* kd, const double* limit, const double* range) {{
  auto* ct = new (c) g::ComputedTorque();
  for (int i = 0; i < g::dof; ++i) {{ ct->kp[i] = kp[i]; ct->kd[i] = kd[i]; ct->torque_limit[i] = limit[i]; }}
  ct->max_position = range[0]; ct->max_speed = range[1]; ct->max_acceleration = range[2];
}}
unsigned mb_ct_step(void* c, const double* q, const double* v, const double* qd, const double* vd, const double* ad, double* tau) {{
  return static_cast<g::ComputedTorque*>(c)->step(q, v, qd, vd, ad, tau);
}}
"""

_SHIM_CLOSED = """int mb_closed_motion(const double* qa, const double* va, const double* aa, double* q, double* v, double* a, int it, double tol) {{ return g::closed_motion(qa, va, aa, q, v, a, it, tol); }}
int mb_closed_shaking_wrench(const double* qa, const double* va, const double* aa, double* q, double* f, double* m, int it, double tol) {{ return g::closed_shaking_wrench(qa, va, aa, q, f, m, it, tol); }}
int mb_closed_inverse_dynamics(const double* qa, const double* va, const double* aa, double* q, double* tau, int it, double tol) {{ return g::closed_inverse_dynamics(qa, va, aa, q, tau, it, tol); }}
int mb_closed_state_size() {{ return static_cast<int>(sizeof(g::ClosedState)); }}
void mb_closed_state_init(void* state, const double* q) {{ auto* s = new (state) g::ClosedState(); for (int i = 0; i < g::dof; ++i) s->q[i] = q[i]; }}
int mb_closed_tick(void* state, const double* qa, const double* va, const double* aa, double* f, double* m, double* q_out) {{
  auto* s = static_cast<g::ClosedState*>(state);
  const int status = g::closed_tick(*s, qa, va, aa, f, m);
  for (int i = 0; i < g::dof; ++i) q_out[i] = s->q[i];
  return status;
}}
"""

#: flags of `build` (part of the cache key)
BUILD_FLAGS = ("-std=c++17", "-O2", "-fPIC", "-shared", "-fno-exceptions", "-fno-rtti")


def compiler() -> str | None:
    """The C++ compiler `build` uses: $CXX, else c++ or g++ on PATH (None when there is none)."""
    cxx = os.environ.get("CXX")
    if cxx:
        return shutil.which(cxx) or (cxx if os.path.isfile(cxx) else None)
    return shutil.which("c++") or shutil.which("g++") or shutil.which("clang++")


class GeneratedModule:
    """The generated functions of one mechanism, compiled and loaded (ctypes). Single samples:
    1-D arrays in, arrays out, as `mechbal.Mechanism`'s methods."""

    def __init__(self, code: GeneratedCode, library: Path):
        self.code = code
        self.path = library
        self._lib = ctypes.CDLL(str(library))
        self.dof = int(self._lib.mb_dof())
        self.frame_names = list(code.frame_names)
        d = ctypes.POINTER(ctypes.c_double)
        for fname, nargs in (("inverse_dynamics", 4), ("gravity_torque", 2), ("mass_matrix", 2),
                             ("shaking_wrench", 5), ("base_reaction", 5), ("center_of_mass", 2),
                             ("momentum_matrix", 2), ("frame_placements", 3)):
            f = getattr(self._lib, f"mb_{fname}")
            f.argtypes = [d] * nargs
            f.restype = None
        if code.closed:
            for fname in ("closed_motion", "closed_shaking_wrench"):
                f = getattr(self._lib, f"mb_{fname}")
                f.argtypes = [d] * 6 + [ctypes.c_int, ctypes.c_double]
                f.restype = ctypes.c_int
            f = self._lib.mb_closed_inverse_dynamics
            f.argtypes = [d] * 5 + [ctypes.c_int, ctypes.c_double]
            f.restype = ctypes.c_int
            self._lib.mb_closed_state_size.restype = ctypes.c_int
            self._lib.mb_closed_state_init.argtypes = [ctypes.c_void_p, d]
            self._lib.mb_closed_tick.argtypes = [ctypes.c_void_p] + [d] * 6
            self._lib.mb_closed_tick.restype = ctypes.c_int
        else:
            self._lib.mb_ct_size.restype = ctypes.c_int
            self._lib.mb_ct_init.argtypes = [ctypes.c_void_p] + [d] * 4
            self._lib.mb_ct_step.argtypes = [ctypes.c_void_p] + [d] * 6
            self._lib.mb_ct_step.restype = ctypes.c_uint

    def _vec(self, x, name: str) -> np.ndarray:
        arr = np.ascontiguousarray(x, dtype=float)
        if arr.shape != (self.dof,):
            raise ValueError(f"{name} must have shape ({self.dof},), got {arr.shape}")
        return arr

    @staticmethod
    def _ptr(a: np.ndarray):
        return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))

    def inverse_dynamics(self, q, v, a) -> np.ndarray:
        q, v, a = self._vec(q, "q"), self._vec(v, "v"), self._vec(a, "a")
        tau = np.empty(self.dof)
        self._lib.mb_inverse_dynamics(self._ptr(q), self._ptr(v), self._ptr(a), self._ptr(tau))
        return tau

    def gravity_torque(self, q) -> np.ndarray:
        q = self._vec(q, "q")
        tau = np.empty(self.dof)
        self._lib.mb_gravity_torque(self._ptr(q), self._ptr(tau))
        return tau

    def mass_matrix(self, q) -> np.ndarray:
        q = self._vec(q, "q")
        M = np.empty((self.dof, self.dof), order="F")
        self._lib.mb_mass_matrix(self._ptr(q), self._ptr(M))
        return np.ascontiguousarray(M)

    def shaking_wrench(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        q, v, a = self._vec(q, "q"), self._vec(v, "v"), self._vec(a, "a")
        f, m = np.empty(3), np.empty(3)
        self._lib.mb_shaking_wrench(self._ptr(q), self._ptr(v), self._ptr(a), self._ptr(f), self._ptr(m))
        return f, m

    def base_reaction(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        q, v, a = self._vec(q, "q"), self._vec(v, "v"), self._vec(a, "a")
        f, m = np.empty(3), np.empty(3)
        self._lib.mb_base_reaction(self._ptr(q), self._ptr(v), self._ptr(a), self._ptr(f), self._ptr(m))
        return f, m

    def center_of_mass(self, q) -> np.ndarray:
        q = self._vec(q, "q")
        c = np.empty(3)
        self._lib.mb_center_of_mass(self._ptr(q), self._ptr(c))
        return c

    def momentum_matrix(self, q) -> np.ndarray:
        q = self._vec(q, "q")
        A = np.empty((6, self.dof), order="F")
        self._lib.mb_momentum_matrix(self._ptr(q), self._ptr(A))
        return np.ascontiguousarray(A)

    def _actuated(self, x, name: str) -> np.ndarray:
        arr = np.ascontiguousarray(x, dtype=float)
        if arr.shape != (len(self.code.actuated),):
            raise ValueError(f"{name} must have shape ({len(self.code.actuated)},), got {arr.shape}")
        return arr

    def closed_motion(self, q_actuated, v_actuated, a_actuated, q_guess, *, max_iterations: int = 20,
                      tolerance: float = 1e-13) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        """(q, v, a, status) of a closed mechanism from its actuated coordinates, the loops closed
        from the warm start `q_guess` (status 0 ok, 1 the loops did not close, 2 non-finite)."""
        if not self.code.closed:
            raise ValueError(f"{self.code.name!r} has no loop closures: closed_motion does not apply")
        qa, va, aa = (self._actuated(x, n) for x, n in ((q_actuated, "q_actuated"), (v_actuated, "v_actuated"),
                                                          (a_actuated, "a_actuated")))
        q = np.array(self._vec(q_guess, "q_guess"))
        v, a = np.zeros(self.dof), np.zeros(self.dof)
        status = self._lib.mb_closed_motion(self._ptr(qa), self._ptr(va), self._ptr(aa), self._ptr(q),
                                            self._ptr(v), self._ptr(a), int(max_iterations), float(tolerance))
        return q, v, a, int(status)

    def closed_shaking_wrench(self, q_actuated, v_actuated, a_actuated, q_guess, *, max_iterations: int = 20,
                              tolerance: float = 1e-13) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        """(force, moment, q, status): the shaking wrench of the closed mechanism's motion."""
        if not self.code.closed:
            raise ValueError(f"{self.code.name!r} has no loop closures: closed_shaking_wrench does not apply")
        qa, va, aa = (self._actuated(x, n) for x, n in ((q_actuated, "q_actuated"), (v_actuated, "v_actuated"),
                                                          (a_actuated, "a_actuated")))
        q = np.array(self._vec(q_guess, "q_guess"))
        f, m = np.zeros(3), np.zeros(3)
        status = self._lib.mb_closed_shaking_wrench(self._ptr(qa), self._ptr(va), self._ptr(aa), self._ptr(q),
                                                    self._ptr(f), self._ptr(m), int(max_iterations), float(tolerance))
        return f, m, q, int(status)

    def closed_inverse_dynamics(self, q_actuated, v_actuated, a_actuated, q_guess, *, max_iterations: int = 20,
                                tolerance: float = 1e-13) -> tuple[np.ndarray, np.ndarray, int]:
        """(tau_actuated, q, status): the actuated forces that drive the closed mechanism's motion
        (tau# = C^T tau, gravity and springs included), the loops closed from `q_guess`."""
        if not self.code.closed:
            raise ValueError(f"{self.code.name!r} has no loop closures: closed_inverse_dynamics does not apply")
        qa, va, aa = (self._actuated(x, n) for x, n in ((q_actuated, "q_actuated"), (v_actuated, "v_actuated"),
                                                          (a_actuated, "a_actuated")))
        q = np.array(self._vec(q_guess, "q_guess"))
        tau = np.zeros(len(self.code.actuated))
        status = self._lib.mb_closed_inverse_dynamics(self._ptr(qa), self._ptr(va), self._ptr(aa), self._ptr(q),
                                                      self._ptr(tau), int(max_iterations), float(tolerance))
        return tau, q, int(status)

    def closed_ticks(self, q_actuated, v_actuated, a_actuated, q_guess):
        """Run `closed_tick` along a motion ((N, na) arrays, in the order given), its state kept
        from tick to tick: (force (N, 3), moment (N, 3), q (N, dof), status (N,))."""
        if not self.code.closed:
            raise ValueError(f"{self.code.name!r} has no loop closures: closed_ticks does not apply")
        Qa, Va, Aa = (np.ascontiguousarray(x, dtype=float) for x in (q_actuated, v_actuated, a_actuated))
        state = ctypes.create_string_buffer(int(self._lib.mb_closed_state_size()) + 64)
        address = (ctypes.addressof(state) + 63) // 64 * 64
        guess = np.array(self._vec(q_guess, "q_guess"))
        self._lib.mb_closed_state_init(ctypes.c_void_p(address), self._ptr(guess))
        n = len(Qa)
        F, M, Q, status = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, self.dof)), np.zeros(n, dtype=int)
        f, m, q = np.zeros(3), np.zeros(3), np.zeros(self.dof)
        for k in range(n):
            qa, va, aa = (self._actuated(x[k], name) for x, name in ((Qa, "q_actuated"), (Va, "v_actuated"),
                                                                     (Aa, "a_actuated")))
            status[k] = self._lib.mb_closed_tick(ctypes.c_void_p(address), self._ptr(qa), self._ptr(va),
                                                 self._ptr(aa), self._ptr(f), self._ptr(m), self._ptr(q))
            F[k], M[k], Q[k] = f, m, q
        return F, M, Q, status

    def computed_torque_run(self, q, v, q_des, v_des, a_des, *, kp, kd, torque_limit=None,
                            max_position: float = np.inf, max_speed: float = np.inf,
                            max_acceleration: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
        """N ticks ((N, dof) arrays) of one generated `ComputedTorque` (open trees): (tau (N, dof),
        status (N,), the bits of mechbal.Status), its held command carried from tick to tick."""
        if self.code.closed:
            raise ValueError(f"{self.code.name!r} has loop closures: the generated computed torque is "
                             "for open trees")
        rows = [np.ascontiguousarray(np.atleast_2d(x), dtype=float) for x in (q, v, q_des, v_des, a_des)]
        for name, x in zip(("q", "v", "q_des", "v_des", "a_des"), rows):
            if x.ndim != 2 or x.shape[1] != self.dof or len(x) != len(rows[0]):
                raise ValueError(f"{name} must have shape (N, {self.dof}) with one N, got {x.shape}")
        gains = [self._vec(np.broadcast_to(np.asarray(x, float), (self.dof,)), name)
                 for x, name in ((kp, "kp"), (kd, "kd"))]
        limit = self._vec(np.full(self.dof, np.inf) if torque_limit is None else
                          np.broadcast_to(np.asarray(torque_limit, float), (self.dof,)), "torque_limit")
        bounds = np.array([max_position, max_speed, max_acceleration], dtype=float)
        state = ctypes.create_string_buffer(int(self._lib.mb_ct_size()) + 64)
        address = ctypes.c_void_p((ctypes.addressof(state) + 63) // 64 * 64)
        self._lib.mb_ct_init(address, self._ptr(gains[0]), self._ptr(gains[1]), self._ptr(limit), self._ptr(bounds))
        n = len(rows[0])
        tau, status = np.zeros((n, self.dof)), np.zeros(n, dtype=np.int64)
        out = np.zeros(self.dof)
        for k in range(n):
            status[k] = self._lib.mb_ct_step(address, *(self._ptr(np.ascontiguousarray(x[k])) for x in rows),
                                             self._ptr(out))
            tau[k] = out
        return tau, status

    def frame_placement(self, q, frame: str) -> np.ndarray:
        """4x4 placement of a generated frame in O."""
        if frame not in self.frame_names:
            raise ValueError(f"frame {frame!r} was not generated (frames: {', '.join(self.frame_names)})")
        q = self._vec(q, "q")
        k = len(self.frame_names)
        R, p = np.empty(9 * max(k, 1)), np.empty(3 * max(k, 1))
        self._lib.mb_frame_placements(self._ptr(q), self._ptr(R), self._ptr(p))
        i = self.frame_names.index(frame)
        T = np.eye(4)
        T[:3, :3] = R[9 * i:9 * i + 9].reshape(3, 3, order="F")
        T[:3, 3] = p[3 * i:3 * i + 3]
        return T


def build(mechanism_or_code, *, cache_dir: str | Path | None = None, **generate_options) -> GeneratedModule:
    """Generate (unless given a `GeneratedCode`), compile with the installed C++ compiler and load.

    The library is cached under `cache_dir` (default ``$MECHBAL_CACHE/codegen`` or
    ``~/.cache/mechbal/codegen``) by the hash of the generated code and the compiler flags, so a
    second call with the same model loads it without compiling. Raises `CodegenError` when no
    compiler is installed or the compile fails (its diagnostics in the message)."""
    code = mechanism_or_code if isinstance(mechanism_or_code, GeneratedCode) else \
        generate(mechanism_or_code, **generate_options)
    cxx = compiler()
    if cxx is None:
        raise CodegenError("mechbal.codegen.build needs a C++17 compiler: none found (set CXX, or "
                           "install g++: apt-get install g++); generate() and the header need none")
    key = hashlib.sha256((code.header + "\0" + " ".join(BUILD_FLAGS)).encode()).hexdigest()[:24]
    directory = Path(cache_dir) if cache_dir is not None else _cache_dir()
    library = directory / f"{code.name}-{key}.so"
    if not library.exists():
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=directory) as tmp:
            header = Path(tmp) / f"{code.name}.hpp"
            header.write_text(code.header)
            shim = Path(tmp) / "shim.cpp"
            shim.write_text(_SHIM.format(header=header.name, ident=code.name,
                                         closed=_SHIM_CLOSED if code.closed else _SHIM_OPEN.format()))
            out = Path(tmp) / library.name
            result = subprocess.run([cxx, *BUILD_FLAGS, str(shim), "-o", str(out)],
                                    capture_output=True, text=True)
            if result.returncode != 0:
                raise CodegenError(f"compiling the generated code of {code.name!r} failed "
                                   f"({cxx}):\n{result.stderr.strip()[-4000:]}")
            os.replace(out, library)  # atomic: a concurrent build finds a whole file or none
    return GeneratedModule(code, library)


__all__ = ["BUILD_FLAGS", "CodegenError", "GENERATOR_VERSION", "GeneratedCode", "GeneratedModule",
           "MAX_JOINTS", "build", "compiler", "generate"]
