"""The import graph of a Python package read from its sources (ast), every import counted.

Unlike import-linter's graph (grimp), this one counts what runs, wherever it is written:

* imports at module level, inside functions and under ``if TYPE_CHECKING`` alike;
* ``from pkg import name``: an edge to ``pkg.name`` when that is a module, else to ``pkg``
  (``from mechbal import Mechanism`` goes through the root facade);
* the compiled module ``mechbal._core`` is a node of its own (a leaf): ``from mechbal import
  _core`` and ``import mechbal._core`` both import it, not the root package;
* dynamic imports, ``importlib.import_module(...)`` and ``__import__(...)``: a literal name is an
  edge to that module; an f-string with a literal head (``f"mechbal.papers.{name}"``) is an edge
  to every module under that head (``{__name__}`` is the module's own name); any other argument
  is an edge to every module of the package named by a string literal in the same file (the
  values of a table such as ``{"static": "mechbal.balance.static"}``).

Implicit imports of parent packages (``import a.b.c`` runs ``a/__init__`` and ``a/b/__init__``)
are not edges, as in every import graph tool: otherwise each module would import the root.
"""
from __future__ import annotations

import ast
from pathlib import Path

#: compiled modules of the package (no .py source), leaves of the graph
COMPILED = {"mechbal._core"}


def modules_of(package_dir: Path, package: str = "mechbal") -> dict[str, Path]:
    """{dotted name: source file} of every module of `package` under `package_dir`."""
    root = package_dir / package
    out: dict[str, Path] = {}
    for p in sorted(root.rglob("*.py")):
        rel = p.relative_to(package_dir).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if "__pycache__" in parts:
            continue
        out[".".join(parts)] = p
    return out


def _resolve_relative(module: str, is_package: bool, level: int, name: str | None) -> str:
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    if level > 1:
        base = base[: len(base) - (level - 1)]
    return ".".join(base + ([name] if name else []))


def _nearest(name: str, known: set[str]) -> str | None:
    parts = name.split(".")
    while parts:
        candidate = ".".join(parts)
        if candidate in known:
            return candidate
        parts.pop()
    return None


def _under(head: str, known: set[str]) -> set[str]:
    """Modules whose name starts with `head` (an f-string's literal head, e.g. ``mechbal.papers.``)."""
    return {m for m in known if m.startswith(head) or m == head.rstrip(".")}


def _dynamic_targets(node: ast.Call, module: str, strings: set[str], known: set[str]) -> set[str]:
    arg = node.args[0] if node.args else None
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        hit = _nearest(arg.value, known)
        return {hit} if hit else set()
    if isinstance(arg, ast.JoinedStr):
        head = ""
        for part in arg.values:
            if isinstance(part, ast.Constant) and isinstance(part.value, str):
                head += part.value
            elif (isinstance(part, ast.FormattedValue) and isinstance(part.value, ast.Name)
                  and part.value.id == "__name__" and not head):
                head = module
            else:
                break
        return _under(head, known) if head else set()
    # a computed name: whichever module of the package the file names in a string literal
    return {s for s in strings if s in known}


def _is_dynamic_import(node: ast.Call) -> bool:
    f = node.func
    return ((isinstance(f, ast.Attribute) and f.attr == "import_module")
            or (isinstance(f, ast.Name) and f.id in ("import_module", "__import__")))


def import_graph(package_dir: Path, package: str = "mechbal") -> dict[str, set[str]]:
    """{module: modules it imports} for every module of `package` under `package_dir`."""
    files = modules_of(package_dir, package)
    known = set(files) | COMPILED
    graph: dict[str, set[str]] = {m: set() for m in known}
    for module, path in files.items():
        is_package = path.name == "__init__.py"
        tree = ast.parse(path.read_text(), filename=str(path))
        strings = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
        edges = graph[module]
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    hit = _nearest(alias.name, known)
                    if hit:
                        edges.add(hit)
            elif isinstance(node, ast.ImportFrom):
                base = (_resolve_relative(module, is_package, node.level, node.module) if node.level
                        else node.module or "")
                for alias in node.names:
                    sub = f"{base}.{alias.name}"
                    hit = sub if sub in known else _nearest(base, known)
                    if hit:
                        edges.add(hit)
            elif isinstance(node, ast.Call) and _is_dynamic_import(node):
                edges |= _dynamic_targets(node, module, strings, known)
        edges.discard(module)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    out: list[list[str]] = []
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            v, children = work[-1]
            advanced = False
            for w in children:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                    advanced = True
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return sorted(out)


def reachable(graph: dict[str, set[str]], start: str) -> set[str]:
    """Every module `start` imports, directly or through others."""
    seen: set[str] = set()
    todo = list(graph.get(start, ()))
    while todo:
        m = todo.pop()
        if m not in seen:
            seen.add(m)
            todo.extend(graph.get(m, ()))
    return seen
