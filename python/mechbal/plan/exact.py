"""Exact partial derivatives of the shaking wrench and the actuator torques with respect to the
actuated positions, rates and accelerations, by forward-mode differentiation of the model's
expression graph (`mechbal.codegen`: the same Newton-Euler recursion and loop projection that
the generated C++ runs, here evaluated by numpy over a batch of instants).

For a closed mechanism the full coordinates ``q`` come from the library's loop solver; on the
closure manifold ``dq/dq# = C`` (the coupling matrix), so the derivative with respect to an
actuated position ``j`` is the graph's directional derivative along ``C e_j`` (itself a graph
value: the rates of the projection with ``v# = e_j``). Rates and accelerations are inputs of
the graph: their derivatives are forward-mode too. Nothing is differenced.

The graph is built once per mechanism and moment point (a few hundred milliseconds for a
six-joint arm or a four-bar) and compiled into one straight-line function: C++ by the installed
compiler (cached beside `mechbal.codegen.build`'s libraries; then an evaluation costs what the
central differences cost), else numpy (about three times that). Mechanisms the generator does
not take (too many joints, more than `MAX_PASSIVE` passive coordinates, a graph above
`MAX_NODES`) have no exact partials (`exact_partials` returns None) and `mechbal.plan.model`
falls back on central differences.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

import weakref
from typing import Any, Callable

import numpy as np

#: largest graph compiled (nodes the outputs need); beyond it compiling costs minutes and the
#: central differences are as good
MAX_NODES = 20_000
#: most passive coordinates of a closed mechanism whose loop projection is unrolled (PAMINSA's
#: legs, with dozens, stay on differences: their graph alone takes a minute to build)
MAX_PASSIVE = 12

_CACHE: "weakref.WeakKeyDictionary[Any, dict]" = weakref.WeakKeyDictionary()


class ExactPartials:
    """``__call__(q, va, aa)`` with ``q`` the full coordinates (N, dof) of a motion (closed: on the
    loops) and ``va, aa`` the actuated rates and accelerations (N, na): a dict of ``wrench``
    (N, 6) [F; M_p], ``torque`` (N, na), and their partials ``dq`` (N, 6, na) and ``torque_dq``
    (N, na, na); ``with_rates``: also ``dv, da, torque_dv, torque_da``."""

    def __init__(self, function: Callable, na: int, nodes: int, with_rates: bool, torque: bool):
        self._f = function
        self.na = na
        self.nodes = nodes
        self.with_rates = with_rates
        self.torque = torque

    def __call__(self, q: np.ndarray, va: np.ndarray, aa: np.ndarray) -> dict[str, np.ndarray]:
        N = q.shape[0]
        with np.errstate(all="ignore"):
            out = self._f(*(list(np.ascontiguousarray(np.asarray(x, float).T)) for x in (q, va, aa)), np.zeros(N))
        na = self.na
        if isinstance(out, np.ndarray):
            vals = out
        else:
            vals = np.empty((len(out), N))
            for k, x in enumerate(out):
                vals[k] = x
        # layout: [W (6), tau (na)] then the same per derivative direction: dq_j, dv_j, da_j
        k = 6 + (na if self.torque else 0)
        base = vals[:k].T
        kinds = ("q", "v", "a") if self.with_rates else ("q",)
        der = vals[k:].reshape(len(kinds), na, k, N)            # (kind, j, output, N)
        res = {"wrench": base[:, :6]}
        if self.torque:
            res["torque"] = base[:, 6:]
        for kind, name in enumerate(kinds):
            d = np.transpose(der[kind], (2, 1, 0))      # (N, output, j)
            res[f"d{name}"] = d[:, :6]
            if self.torque:
                res[f"torque_d{name}"] = d[:, 6:]
        return res


def exact_partials(mech, moment_point, with_rates: bool = False, torque: bool = True) -> ExactPartials | None:
    """The compiled exact partials of ``mech`` (a `mechbal.Mechanism`) with the moment about
    ``moment_point``, or None where the generator does not take the mechanism (see the module
    docstring). ``with_rates``: the partials in the rates and accelerations too (else only in
    the positions: `mechbal.plan.model` has the others exactly from the library). Cached per
    mechanism, moment point, ``with_rates`` and ``torque`` (the actuated torques and their partials
    too)."""
    key = (*(float(x) for x in np.asarray(moment_point, float).reshape(3)), bool(with_rates), bool(torque))
    try:
        per = _CACHE.setdefault(mech, {})
    except TypeError:
        per = {}
    if key not in per:
        try:
            per[key] = _build(mech, np.array(key[:3]), bool(with_rates), bool(torque))
        except Exception:   # the generator's refusal (CodegenError, an unsupported joint): differences
            per[key] = None
    return per[key]


def _build(mech, p: np.ndarray, with_rates: bool = False, torque: bool = True) -> ExactPartials | None:
    from mechbal.codegen import MAX_JOINTS
    from mechbal.codegen import tree as T
    from mechbal.codegen.expr import Graph, cross, directional_derivative, vsub

    if mech.model.num_links - 1 > MAX_JOINTS:
        return None
    if mech.is_closed and len(mech.model.passive_coordinates) > MAX_PASSIVE:
        return None
    tc = T.tree_constants(mech)
    g = Graph()
    n = tc.dof
    q = [g.input(f"q{i}") for i in range(n)]
    closed = bool(tc.loops)
    act = list(tc.actuated) if closed else list(range(n))
    na = len(act)
    va = [g.input(f"va{j}") for j in range(na)]
    aa = [g.input(f"aa{j}") for j in range(na)]
    if closed:
        spare = [g.input(f"w{i}") for i in range(n)]
        v, a = T.closed_projection(g, tc, q, va, aa, spare)
        # C e_j: v is linear in v#
        C = [directional_derivative(g, v, {va[j].id: 1.0}) for j in range(na)]
    else:
        v, a = list(va), list(aa)
        C = [[1.0 if k == j else 0.0 for k in range(n)] for j in range(na)]
    F, M = T.shaking_wrench(g, tc, q, v, a)
    Mp = vsub(g, M, cross(g, [float(x) for x in p], F))
    tau_a: list = []
    if torque:
        tau, _ = T.newton_euler(g, tc, q, v, a, gravity=True, springs=True)
        if closed:
            from mechbal.codegen.expr import dot

            tau_a = [dot(g, C[j], tau) for j in range(na)]
        else:
            tau_a = list(tau)
    outputs = list(F) + list(Mp) + tau_a
    derivs = []
    for j in range(na):
        derivs += directional_derivative(g, outputs, {q[k].id: C[j][k] for k in range(n)})
    if with_rates:
        for j in range(na):
            derivs += directional_derivative(g, outputs, {va[j].id: 1.0})
        for j in range(na):
            derivs += directional_derivative(g, outputs, {aa[j].id: 1.0})
    allout = outputs + derivs
    if int(np.count_nonzero(_needed(g, allout))) > MAX_NODES:
        return None
    function = _compile_c(g, allout, n, na) or _compile(g, allout, n, na, closed)
    return ExactPartials(function, na, len(g.nodes), with_rates, torque)


def _compile(g, outputs: list, n: int, na: int, closed: bool) -> Callable:
    """One straight-line numpy function ``f(q, va, aa, zero)`` (lists of (N,) arrays) returning
    the outputs, over the nodes they need."""
    from mechbal.codegen.expr import Sym

    need = np.zeros(len(g.nodes), bool)
    stack = [x.id for x in outputs if isinstance(x, Sym)]
    while stack:
        k = stack.pop()
        if need[k]:
            continue
        need[k] = True
        stack.extend(x.id for x in g.nodes[k][1:] if isinstance(x, Sym))
    ops = {"add": "{0} + {1}", "sub": "{0} - {1}", "mul": "{0} * {1}", "div": "{0} / {1}", "neg": "-{0}",
           "sin": "_sin({0})", "cos": "_cos({0})", "sqrt": "_sqrt({0})"}
    lines = ["def f(q, va, aa, zero):"]

    def arg(x) -> str:
        return f"x{x.id}" if isinstance(x, Sym) else repr(float(x))

    for k in np.flatnonzero(need):
        node = g.nodes[k]
        if node[0] == "in":
            name = node[1]
            if name.startswith("va"):
                src = f"va[{int(name[2:])}]"
            elif name.startswith("aa"):
                src = f"aa[{int(name[2:])}]"
            elif name.startswith("q"):
                src = f"q[{int(name[1:])}]"
            else:   # the spare inputs of the loop projection are substituted away
                src = "zero"
            lines.append(f"    x{k} = {src}")
        else:
            lines.append(f"    x{k} = " + ops[node[0]].format(*(arg(x) for x in node[1:])))
    lines.append("    return [" + ", ".join(arg(x) if isinstance(x, Sym) else f"zero + {float(x)!r}"
                                          for x in outputs) + "]")
    scope: dict[str, Any] = {"_sin": np.sin, "_cos": np.cos, "_sqrt": np.sqrt}
    exec(compile("\n".join(lines), "<mechbal.plan.exact>", "exec"), scope)  # noqa: S102 - generated here
    return scope["f"]


def _needed(g, outputs: list) -> np.ndarray:
    from mechbal.codegen.expr import Sym

    need = np.zeros(len(g.nodes), bool)
    stack = [x.id for x in outputs if isinstance(x, Sym)]
    while stack:
        k = stack.pop()
        if need[k]:
            continue
        need[k] = True
        stack.extend(x.id for x in g.nodes[k][1:] if isinstance(x, Sym))
    return need


def _compile_c(g, outputs: list, n: int, na: int) -> Callable | None:
    """The same straight-line function in C, compiled by the installed C++ compiler
    (`mechbal.codegen.compiler`) into the code generator's cache and loaded with ctypes: one loop
    over the instants, no interpreter per operation. None without a compiler or where the compile
    fails (the numpy function then)."""
    import ctypes
    import hashlib
    import os
    import subprocess
    import tempfile
    from pathlib import Path

    from mechbal.codegen import _cache_dir, compiler
    from mechbal.codegen.expr import Sym

    if os.environ.get("MECHBAL_PLAN_NO_COMPILE"):
        return None
    cxx = compiler()
    if cxx is None:
        return None
    need = _needed(g, outputs)
    ops = {"add": "{0} + {1}", "sub": "{0} - {1}", "mul": "{0} * {1}", "div": "{0} / {1}", "neg": "-{0}",
           "sin": "std::sin({0})", "cos": "std::cos({0})", "sqrt": "std::sqrt({0})"}

    def arg(x) -> str:
        return f"x{x.id}" if isinstance(x, Sym) else repr(float(x))

    m = len(outputs)
    body = []
    for k in np.flatnonzero(need):
        node = g.nodes[k]
        if node[0] == "in":
            name = node[1]
            if name.startswith("va"):
                src = f"V[{int(name[2:])}]"
            elif name.startswith("aa"):
                src = f"A[{int(name[2:])}]"
            elif name.startswith("q"):
                src = f"Q[{int(name[1:])}]"
            else:
                src = "0.0"
        else:
            src = ops[node[0]].format(*(arg(x) for x in node[1:]))
        body.append(f"    const double x{k} = {src};")
    body += [f"    out[{i} * N + r] = {arg(x)};" for i, x in enumerate(outputs)]
    source = ("#include <cmath>\nextern \"C\" void f(int N, const double* q, const double* va, const double* aa, "
              "double* out) {\n  for (int r = 0; r < N; ++r) {\n"
              f"    const double* Q = q + r * {n}; const double* V = va + r * {na}; const double* A = aa + r * {na};\n"
              + "\n".join(body) + "\n  }\n}\n")
    flags = ["-O1", "-fPIC", "-shared", "-fno-math-errno"]
    key = hashlib.sha256((source + " ".join(flags)).encode()).hexdigest()[:24]
    directory = _cache_dir()
    library = directory / f"plan-partials-{key}.so"
    try:
        if not library.exists():
            directory.mkdir(parents=True, exist_ok=True)
            with tempfile.TemporaryDirectory(dir=directory) as tmp:
                src = Path(tmp) / "partials.cpp"
                src.write_text(source)
                out = Path(tmp) / library.name
                r = subprocess.run([cxx, *flags, str(src), "-o", str(out)], capture_output=True, text=True)
                if r.returncode != 0:
                    return None
                os.replace(out, library)
        lib = ctypes.CDLL(str(library))
    except OSError:
        return None
    fn = lib.f
    ptr = ctypes.POINTER(ctypes.c_double)
    fn.argtypes = [ctypes.c_int, ptr, ptr, ptr, ptr]
    fn.restype = None

    def call(q_cols, va_cols, aa_cols, zero):
        N = zero.shape[0]
        q = np.ascontiguousarray(np.column_stack(q_cols) if q_cols else np.zeros((N, 0)))
        v = np.ascontiguousarray(np.column_stack(va_cols))
        a = np.ascontiguousarray(np.column_stack(aa_cols))
        out = np.empty((m, N))
        fn(N, q.ctypes.data_as(ptr), v.ctypes.data_as(ptr), a.ctypes.data_as(ptr), out.ctypes.data_as(ptr))
        return out

    call.library = library  # type: ignore[attr-defined]
    return call
