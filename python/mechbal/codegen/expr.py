"""A small expression graph for code generation: scalars that fold constants as they are built.

Every value is either a Python ``float`` (a constant known at generation time) or a `Sym`, a node
of one `Graph`. Building ``a * b`` with ``a == 0.0`` gives ``0.0``, with ``a == 1.0`` gives ``b``;
two constants give their product. Nodes are hash-consed: the same operation on the same operands
is one node, so common subexpressions are shared as they are built (no separate CSE pass). The
graph is written out as straight-line C++ by `mechbal.codegen.emit`.

This is how structural zeros are pruned: a link whose joint axis is z has a rotation whose third
row and column are the constants (0, 0, 1), and every product with those zeros vanishes before it
is written.
"""
from __future__ import annotations

import math
from typing import Union

Value = Union[float, "Sym"]

#: operations and their arity
_UNARY = {"neg", "sin", "cos", "sqrt"}
_BINARY = {"add", "sub", "mul", "div"}


class Sym:
    """A node of a `Graph` (an input or an operation); supports + - * / and unary -."""

    __slots__ = ("graph", "id")

    def __init__(self, graph: "Graph", index: int):
        self.graph = graph
        self.id = index

    def __add__(self, other: Value) -> Value:
        return self.graph.add(self, other)

    def __radd__(self, other: Value) -> Value:
        return self.graph.add(other, self)

    def __sub__(self, other: Value) -> Value:
        return self.graph.sub(self, other)

    def __rsub__(self, other: Value) -> Value:
        return self.graph.sub(other, self)

    def __mul__(self, other: Value) -> Value:
        return self.graph.mul(self, other)

    def __rmul__(self, other: Value) -> Value:
        return self.graph.mul(other, self)

    def __truediv__(self, other: Value) -> Value:
        return self.graph.div(self, other)

    def __neg__(self) -> Value:
        return self.graph.neg(self)

    def __repr__(self) -> str:
        return f"Sym({self.id}: {self.graph.nodes[self.id]})"


def _key(x: Value):
    if isinstance(x, Sym):
        return x.id
    return ("c", float(x) + 0.0)  # -0.0 and 0.0 are one constant


def is_const(x: Value) -> bool:
    return not isinstance(x, Sym)


class Graph:
    """Nodes in creation order (an operation's operands are always older than it)."""

    def __init__(self) -> None:
        self.nodes: list[tuple] = []  # ("in", name) or (op, operand, ...)
        self._index: dict[tuple, Sym] = {}

    # ---- construction ------------------------------------------------------------------------
    def input(self, name: str) -> Sym:
        return self._node(("in", name))

    def _node(self, key: tuple) -> Sym:
        hashed = key if key[0] == "in" else tuple(_key(k) if i else k for i, k in enumerate(key))
        found = self._index.get(hashed)
        if found is not None:
            return found
        node = Sym(self, len(self.nodes))
        self.nodes.append(key)
        self._index[hashed] = node
        return node

    def neg(self, a: Value) -> Value:
        if is_const(a):
            return -float(a) + 0.0
        node = self.nodes[a.id]
        if node[0] == "neg":
            return node[1]
        return self._node(("neg", a))

    def add(self, a: Value, b: Value) -> Value:
        if is_const(a) and is_const(b):
            return float(a) + float(b)
        if is_const(a) and a == 0.0:
            return b
        if is_const(b) and b == 0.0:
            return a
        # x + (-y) -> x - y ; (-x) + y -> y - x
        if isinstance(b, Sym) and self.nodes[b.id][0] == "neg":
            return self.sub(a, self.nodes[b.id][1])
        if isinstance(a, Sym) and self.nodes[a.id][0] == "neg":
            return self.sub(b, self.nodes[a.id][1])
        if _order(a) > _order(b):
            a, b = b, a
        return self._node(("add", a, b))

    def sub(self, a: Value, b: Value) -> Value:
        if is_const(a) and is_const(b):
            return float(a) - float(b)
        if is_const(b) and b == 0.0:
            return a
        if is_const(a) and a == 0.0:
            return self.neg(b)
        if isinstance(a, Sym) and isinstance(b, Sym) and a.id == b.id:
            return 0.0
        if isinstance(b, Sym) and self.nodes[b.id][0] == "neg":
            return self.add(a, self.nodes[b.id][1])
        return self._node(("sub", a, b))

    def mul(self, a: Value, b: Value) -> Value:
        if is_const(a) and is_const(b):
            return float(a) * float(b)
        if is_const(b):
            a, b = b, a
        if is_const(a):
            if a == 0.0:
                return 0.0
            if a == 1.0:
                return b
            if a == -1.0:
                return self.neg(b)
            node = self.nodes[b.id]
            if node[0] == "neg":  # c * (-x) -> (-c) * x
                return self.mul(-float(a), node[1])
            if node[0] == "mul" and is_const(node[1]):  # c * (d * x) -> (c d) * x
                return self.mul(float(a) * float(node[1]), node[2])
            return self._node(("mul", float(a), b))
        # (-x) * y -> -(x y)
        na, nb = self.nodes[a.id], self.nodes[b.id]
        if na[0] == "neg":
            return self.neg(self.mul(na[1], b))
        if nb[0] == "neg":
            return self.neg(self.mul(a, nb[1]))
        if _order(a) > _order(b):
            a, b = b, a
        return self._node(("mul", a, b))

    def div(self, a: Value, b: Value) -> Value:
        if is_const(b):
            return self.mul(1.0 / float(b), a)
        if is_const(a) and a == 0.0:
            return 0.0
        return self._node(("div", a, b))

    def sin(self, a: Value) -> Value:
        return math.sin(a) if is_const(a) else self._node(("sin", a))

    def cos(self, a: Value) -> Value:
        return math.cos(a) if is_const(a) else self._node(("cos", a))

    def sqrt(self, a: Value) -> Value:
        return math.sqrt(a) if is_const(a) else self._node(("sqrt", a))

    # ---- evaluation (for tests of the generator itself) ----------------------------------------
    def evaluate(self, outputs, inputs: dict[str, float]):
        """Evaluate `outputs` (a nested list of values) with the inputs given by name."""
        values: list[float] = []
        for node in self.nodes:
            op = node[0]
            if op == "in":
                values.append(float(inputs[node[1]]))
                continue
            args = [values[x.id] if isinstance(x, Sym) else float(x) for x in node[1:]]
            values.append(_APPLY[op](*args))

        def walk(x):
            if isinstance(x, (list, tuple)):
                return [walk(y) for y in x]
            return values[x.id] if isinstance(x, Sym) else float(x)
        return walk(outputs)


def _order(x: Value):
    return (1, x.id) if isinstance(x, Sym) else (0, float(x))


_APPLY = {
    "neg": lambda a: -a, "sin": math.sin, "cos": math.cos, "sqrt": math.sqrt,
    "add": lambda a, b: a + b, "sub": lambda a, b: a - b, "mul": lambda a, b: a * b,
    "div": lambda a, b: a / b,
}


# ---- 3-vectors and 3x3 matrices of values (lists), the algorithms' algebra ----------------------
def vadd(g: Graph, a, b):
    return [g.add(x, y) for x, y in zip(a, b)]


def vsub(g: Graph, a, b):
    return [g.sub(x, y) for x, y in zip(a, b)]


def vscale(g: Graph, s: Value, a):
    return [g.mul(s, x) for x in a]


def dot(g: Graph, a, b) -> Value:
    out: Value = 0.0
    for x, y in zip(a, b):
        out = g.add(out, g.mul(x, y))
    return out


def cross(g: Graph, a, b):
    return [g.sub(g.mul(a[1], b[2]), g.mul(a[2], b[1])),
            g.sub(g.mul(a[2], b[0]), g.mul(a[0], b[2])),
            g.sub(g.mul(a[0], b[1]), g.mul(a[1], b[0]))]


def matvec(g: Graph, m, x):
    return [dot(g, row, x) for row in m]


def mattvec(g: Graph, m, x):
    """m^T x."""
    return [dot(g, [m[0][j], m[1][j], m[2][j]], x) for j in range(3)]


def matmul(g: Graph, a, b):
    return [[dot(g, a[i], [b[0][j], b[1][j], b[2][j]]) for j in range(3)] for i in range(3)]


def transpose(m):
    return [[m[j][i] for j in range(3)] for i in range(3)]


def directional_derivative(g: Graph, values: list, seeds: dict[int, Value]) -> list:
    """Forward-mode derivative of `values` along the input directions `seeds` (input node id ->
    the derivative of that input, a graph value): d/ds of each value, as graph values. One pass
    over the nodes the values depend on; derivatives that vanish structurally fold to 0.0."""
    top = 1 + max((x.id for x in values if isinstance(x, Sym)), default=-1)
    d: dict[int, Value] = {}
    for k in range(top):
        node = g.nodes[k]
        op = node[0]
        if op == "in":
            d[k] = seeds.get(k, 0.0)
            continue
        args = node[1:]
        da = [d[x.id] if isinstance(x, Sym) else 0.0 for x in args]
        if all(is_const(z) and z == 0.0 for z in da):
            d[k] = 0.0
            continue
        me = Sym(g, k)
        if op == "add":
            d[k] = g.add(da[0], da[1])
        elif op == "sub":
            d[k] = g.sub(da[0], da[1])
        elif op == "mul":
            d[k] = g.add(g.mul(args[0], da[1]), g.mul(args[1], da[0]))
        elif op == "div":
            d[k] = g.div(g.sub(da[0], g.mul(me, da[1])), args[1])
        elif op == "neg":
            d[k] = g.neg(da[0])
        elif op == "sin":
            d[k] = g.mul(g.cos(args[0]), da[0])
        elif op == "cos":
            d[k] = g.neg(g.mul(g.sin(args[0]), da[0]))
        elif op == "sqrt":
            d[k] = g.div(g.mul(0.5, da[0]), me)
        else:  # pragma: no cover - every operation is listed above
            raise ValueError(f"no derivative for {op}")
    return [d[x.id] if isinstance(x, Sym) else 0.0 for x in values]


def _zero(x: Value) -> bool:
    return is_const(x) and x == 0.0


def ldlt_factor(g: Graph, N: list[list[Value]], order: list[int] | None = None):
    """Unrolled LDL^T of symmetric positive definite N (n x n graph values) in the elimination
    `order` (default: a minimum-degree order of N's structural nonzeros): (L, 1/D, order). Products
    with structural zeros fold away, so only the fill the order creates is computed."""
    n = len(N)
    if order is None:
        order = minimum_degree_order(N)
    P = [[N[order[i]][order[j]] for j in range(n)] for i in range(n)]
    L: list[list[Value]] = [[0.0] * n for _ in range(n)]
    D: list[Value] = [0.0] * n
    inv: list[Value] = [0.0] * n
    for j in range(n):
        s = P[j][j]
        for k in range(j):
            if not _zero(L[j][k]):
                s = g.sub(s, g.mul(g.mul(L[j][k], L[j][k]), D[k]))
        D[j] = s
        inv[j] = g.div(1.0, s)
        for i in range(j + 1, n):
            t = P[i][j]
            for k in range(j):
                if not _zero(L[i][k]) and not _zero(L[j][k]):
                    t = g.sub(t, g.mul(g.mul(L[i][k], L[j][k]), D[k]))
            L[i][j] = g.mul(t, inv[j])
    return L, inv, order


def ldlt_apply(g: Graph, factor, b: list[Value]) -> list[Value]:
    """x with N x = b, from `ldlt_factor`'s result."""
    L, inv, order = factor
    n = len(order)
    y = [b[order[i]] for i in range(n)]
    for i in range(n):
        for k in range(i):
            if not _zero(L[i][k]):
                y[i] = g.sub(y[i], g.mul(L[i][k], y[k]))
    y = [g.mul(y[i], inv[i]) for i in range(n)]
    for i in range(n - 1, -1, -1):
        for k in range(i + 1, n):
            if not _zero(L[k][i]):
                y[i] = g.sub(y[i], g.mul(L[k][i], y[k]))
    x: list[Value] = [0.0] * n
    for i in range(n):
        x[order[i]] = y[i]
    return x


def substitute(g: Graph, values: list, mapping: dict[int, Value]) -> list:
    """`values` with the input nodes of `mapping` (node id -> value) replaced, rebuilt through the
    graph (nodes that do not depend on them stay the same nodes)."""
    top = 1 + max((x.id for x in values if isinstance(x, Sym)), default=-1)
    new: dict[int, Value] = {}
    for k in range(top):
        node = g.nodes[k]
        op = node[0]
        if op == "in":
            new[k] = mapping.get(k, Sym(g, k))
            continue
        args = [new[x.id] if isinstance(x, Sym) else x for x in node[1:]]
        if all(isinstance(a, Sym) and isinstance(o, Sym) and a.id == o.id or (not isinstance(a, Sym) and not isinstance(o, Sym))
               for a, o in zip(args, node[1:])):
            new[k] = Sym(g, k)
            continue
        new[k] = getattr(g, op)(*args)
    return [new[x.id] if isinstance(x, Sym) else x for x in values]


def minimum_degree_order(N: list[list[Value]]) -> list[int]:
    """A greedy minimum-degree elimination order of the structural nonzeros of symmetric N."""
    n = len(N)
    adj = {i: {j for j in range(n) if j != i and not (is_const(N[i][j]) and N[i][j] == 0.0)} for i in range(n)}
    order: list[int] = []
    remaining = set(range(n))
    while remaining:
        i = min(remaining, key=lambda k: (len(adj[k]), k))
        order.append(i)
        nbrs = adj[i]
        for a in nbrs:
            adj[a] |= nbrs - {a}
            adj[a].discard(i)
        remaining.discard(i)
        del adj[i]
    return order
