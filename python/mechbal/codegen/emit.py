"""Write expression graphs (`expr.Graph`) as straight-line C++: one local per shared node, in
the order the nodes were built, constants written so that they read back to the same double."""
from __future__ import annotations

from .expr import Graph, Sym, Value


def literal(x: float) -> str:
    """A C++ double literal that reads back to exactly `x` (repr is the shortest such string)."""
    text = repr(float(x))
    if text in ("inf", "-inf", "nan"):
        raise ValueError(f"a generated constant is not finite ({text})")
    if "e" not in text and "." not in text:
        text += ".0"
    return text


def _flatten(values) -> list:
    out = []
    for x in values:
        if isinstance(x, (list, tuple)):
            out.extend(_flatten(x))
        else:
            out.append(x)
    return out


def function_body(g: Graph, outputs: list[tuple[str, Value]], inputs: dict[str, str],
                  indent: str = "  ") -> tuple[list[str], int]:
    """The statements computing each output `target = value;` (targets are C++ lvalues), and the
    number of arithmetic operations written. `inputs` maps an input node's name to its C++ text."""
    needed: set[int] = set()
    stack = [x.id for _, x in outputs if isinstance(x, Sym)]
    while stack:
        k = stack.pop()
        if k in needed:
            continue
        needed.add(k)
        for arg in g.nodes[k][1:]:
            if isinstance(arg, Sym) and g.nodes[arg.id][0] != "in":
                stack.append(arg.id)
            elif isinstance(arg, Sym):
                needed.add(arg.id)
    names: dict[int, str] = {}
    lines: list[str] = []
    count = 0
    operations = 0

    def text(x: Value) -> str:
        return names[x.id] if isinstance(x, Sym) else literal(float(x))

    for k in sorted(needed):
        node = g.nodes[k]
        op = node[0]
        if op == "in":
            names[k] = inputs[node[1]]
            continue
        args = [text(x) for x in node[1:]]
        if op == "add":
            expr = f"{args[0]} + {args[1]}"
        elif op == "sub":
            expr = f"{args[0]} - {args[1]}"
        elif op == "mul":
            expr = f"{args[0]} * {args[1]}"
        elif op == "div":
            expr = f"{args[0]} / {args[1]}"
        elif op == "neg":
            expr = f"-{args[0]}"
        else:  # sin, cos, sqrt
            expr = f"std::{op}({args[0]})"
        operations += 1
        name = f"t{count}"
        count += 1
        names[k] = name
        lines.append(f"{indent}const double {name} = {expr};")
    for target, value in outputs:
        lines.append(f"{indent}{target} = {text(value)};")
    return lines, operations
