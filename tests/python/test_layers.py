"""The layers of the architecture (docs/architecture.md) point one way.

C++: ``cpp/include/mechbal/{model,algorithm,control,io,papers}`` and ``cpp/src`` mirroring it, bottom
up; a file includes only headers of its own layer or below, and no general header or source
includes a paper's. Python: the import-linter contracts of ``pyproject.toml`` (``[tool.importlinter]``)
over the installed package.
"""
from __future__ import annotations

import functools
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
INCLUDE = ROOT / "cpp" / "include" / "mechbal"
SRC = ROOT / "cpp" / "src"

#: bottom up; the top-level headers (status, version) sit with
#: ``model``; ``mechbal.hpp`` includes everything and is checked by the install test instead
LAYERS = ["model", "algorithm", "control", "io", "papers"]
_INCLUDE = re.compile(r'#\s*include\s*[<"]mechbal/([^">]+)[">]')


def _layer_of_header(rel: str) -> int:
    head = rel.split("/", 1)[0] if "/" in rel else ""
    if head in LAYERS:
        return LAYERS.index(head)
    return 0  # status.hpp, version.hpp, detail/


def _files():
    for base in (INCLUDE, SRC):
        for p in sorted(base.rglob("*")):
            if p.suffix in (".hpp", ".cpp") and p.name != "mechbal.hpp":
                yield base, p


def test_cpp_layer_folders_exist():
    for layer in LAYERS[:-1]:  # the papers' folder goes with the last paper
        assert (INCLUDE / layer).is_dir(), layer
        assert (SRC / layer).is_dir(), layer


def test_cpp_includes_point_down_and_never_into_a_paper():
    bad = []
    for base, p in _files():
        rel = p.relative_to(base).as_posix()
        own = _layer_of_header(rel)
        own_paper = rel.split("/")[1] if rel.startswith("papers/") else None
        for m in _INCLUDE.finditer(p.read_text()):
            target = m.group(1)
            layer = _layer_of_header(target)
            if layer > own:
                bad.append(f"{p.relative_to(ROOT)} ({LAYERS[own]}) includes mechbal/{target} ({LAYERS[layer]})")
            elif target.startswith("papers/") and target.split("/")[1] != own_paper:
                bad.append(f"{p.relative_to(ROOT)} includes another paper's header mechbal/{target}")
    assert not bad, "\n".join(bad)


def test_general_bindings_include_no_paper_header():
    # bindings/ mirrors the library: a paper's binding lives in bindings/papers/<paper>/ and
    # includes only its own paper's headers; no general binding includes a paper's
    bindings = ROOT / "bindings"
    bad = []
    for p in sorted(bindings.rglob("*.[ch]pp")):
        rel = p.relative_to(bindings).parts
        own = rel[1] if rel[0] == "papers" else None
        for m in _INCLUDE.finditer(p.read_text()):
            target = m.group(1)
            if target.startswith("papers/") and target.split("/")[1] != own:
                bad.append(f"{p.relative_to(ROOT)}: {target}")
    assert not bad, bad
    assert not list(SRC.rglob("bind_*.cpp")), "bindings live in bindings/, not in the library's sources"


#: the names a paper's binding file gives the module (classes and functions)
_BOUND = re.compile(r'(?:py::(?:class_|enum_)<[^>]*>(?:\s+\w+)?\(\s*m,\s*|m\.def\(\s*|m\.attr\()"(\w+)"')


def _paper_bound_names() -> list[str]:
    return sorted({n for p in (ROOT / "bindings" / "papers").rglob("*.cpp") for n in _BOUND.findall(p.read_text())})


def test_paper_bindings_bind_only_their_own_classes():
    # a paper's binding never reopens or extends a general class (as five_bar once added a
    # constructor to ComputedTorque): no m.attr("...") lookups, and every name it binds is new
    if not (ROOT / "bindings" / "papers").is_dir():
        pytest.skip("no paper is left")
    general = {n for p in (ROOT / "bindings").glob("*.cpp") for n in _BOUND.findall(p.read_text())}
    names = _paper_bound_names()
    assert {"PaminsaModel", "Arm2DofDynamics", "FiveBarDynamics"} <= set(names), names
    assert not set(names) & general, set(names) & general
    reopened = [p.name for p in (ROOT / "bindings" / "papers").rglob("*.cpp")
                if "reinterpret_borrow" in p.read_text() or 'm.attr("' in p.read_text()]
    assert not reopened, reopened


def test_the_layer_check_catches_an_upward_include(tmp_path):
    # the scan above must be able to fail: a model header that includes a controller
    assert _layer_of_header("control/computed_torque.hpp") > _layer_of_header("model/model.hpp")
    assert _layer_of_header("papers/paminsa/paminsa.hpp") == LAYERS.index("papers")


# ---- Python --------------------------------------------------------------------------------------

def test_import_linter_contracts_hold():
    # lint-imports analyses the installed package (the same sources as python/mechbal)
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or shutil.which("lint-imports")
    if exe is None:
        pytest.skip("import-linter is a test dependency: make test installs it")
    r = subprocess.run([exe, "--no-cache", str(ROOT / "pyproject.toml")], capture_output=True, text=True, cwd=ROOT,
                       timeout=300)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
    assert "0 broken" in r.stdout


@functools.lru_cache(maxsize=None)
def _graph(package_dir: Path) -> dict[str, set[str]]:
    from import_graph import import_graph

    return import_graph(package_dir)


def test_no_import_cycles_anywhere_in_the_package():
    # every import counted (function-level, TYPE_CHECKING, dynamic: tests/python/import_graph.py),
    # the root package included: it is a lazy facade that nothing inside the package imports, so
    # its edges to every public module close no circle; a paper's __init__ importing its own runner
    # (which imports the paper back) would be a cycle too
    from import_graph import cycles

    graph = _graph(ROOT / "python")
    assert "mechbal.trajectory" in graph and graph["mechbal"], "the graph was not read"
    assert cycles(graph) == [], "import cycles"


def test_no_module_imports_the_root_facade():
    graph = _graph(ROOT / "python")
    assert sorted(m for m, targets in graph.items() if "mechbal" in targets) == []


#: general modules: everything but the root facade, the command line, the papers and the cases
def _general(graph: dict[str, set[str]]) -> list[str]:
    top = {"mechbal", "mechbal.cli", "mechbal.__main__"}
    return sorted(m for m in graph if m not in top and not m.startswith(("mechbal.papers", "mechbal.cases")))


def _reaching(graph: dict[str, set[str]], prefix: str) -> dict[str, list[str]]:
    from import_graph import reachable

    out = {}
    for m in _general(graph):
        hit = sorted(x for x in reachable(graph, m) if x == prefix or x.startswith(prefix + "."))
        if hit:
            out[m] = hit
    return out


def test_no_general_module_imports_a_paper():
    # directly, through another module, dynamically or through the facade (which no module imports)
    assert _reaching(_graph(ROOT / "python"), "mechbal.papers") == {}


def test_no_general_module_imports_the_cases():
    # what verify, sweep and balance share with the runners (the motion, the control plan, the
    # bodies files, the URDF's default case) lives in the case layer, mechbal.case
    assert _reaching(_graph(ROOT / "python"), "mechbal.cases") == {}


def test_the_graph_sees_function_level_dynamic_and_facade_imports(tmp_path):
    # the checks above can fail: plant each kind of import in a copy of the package
    from import_graph import cycles

    if not (ROOT / "python" / "mechbal" / "papers" / "paminsa").is_dir():
        pytest.skip("the planted imports go into PAMINSA's package")
    shutil.copytree(ROOT / "python" / "mechbal", tmp_path / "mechbal",
                    ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    with (tmp_path / "mechbal" / "papers" / "paminsa" / "__init__.py").open("a") as f:
        f.write("\n\ndef _planted():\n    from mechbal.papers.paminsa.runner import run  # noqa\n")
    with (tmp_path / "mechbal" / "trajectory.py").open("a") as f:
        f.write("\n\ndef _planted(name):\n    import importlib\n"
                "    return importlib.import_module(f\"mechbal.papers.{name}\")\n")
    with (tmp_path / "mechbal" / "progress.py").open("a") as f:
        f.write("\n\ndef _planted():\n    from mechbal import Mechanism  # noqa\n")
    graph = _graph(tmp_path)
    found = cycles(graph)
    assert any({"mechbal.papers.paminsa", "mechbal.papers.paminsa.runner"} <= set(c) for c in found), found
    assert any({"mechbal", "mechbal.progress"} <= set(c) for c in found), found
    assert "mechbal.papers.paminsa" in _reaching(graph, "mechbal.papers")["mechbal.trajectory"]


def test_the_contracts_catch_an_upward_import(tmp_path):
    # the same contracts on a copy of the package in which one core module imports a paper:
    # import-linter must report the layer broken (the check above can fail)
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or shutil.which("lint-imports")
    if exe is None:
        pytest.skip("import-linter is a test dependency: make test installs it")
    import mechbal

    if not (Path(mechbal.__file__).parent / "papers" / "paminsa").is_dir():
        pytest.skip("the planted import names PAMINSA's package")
    pkg = tmp_path / "mechbal"
    shutil.copytree(Path(mechbal.__file__).parent, pkg, ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    with (pkg / "trajectory.py").open("a") as f:
        f.write("\nfrom mechbal.papers.paminsa import paminsa_mechanism  # noqa\n")
    r = subprocess.run([exe, "--no-cache", str(ROOT / "pyproject.toml")], capture_output=True, text=True, cwd=tmp_path,
                       env={**__import__("os").environ, "PYTHONPATH": str(tmp_path)}, timeout=300)
    assert r.returncode != 0
    assert "mechbal.trajectory is not allowed to import mechbal.papers" in r.stdout


def test_the_contracts_catch_a_paper_importing_another(tmp_path):
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or shutil.which("lint-imports")
    if exe is None:
        pytest.skip("import-linter is a test dependency: make test installs it")
    if not (ROOT / "python" / "mechbal" / "papers" / "rpsp").is_dir():
        pytest.skip("the planted import goes into the RPSP paper")
    shutil.copytree(ROOT / "python" / "mechbal", tmp_path / "mechbal", ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    with (tmp_path / "mechbal" / "papers" / "rpsp" / "runner.py").open("a") as f:
        f.write("\n\ndef _planted():\n    from mechbal.papers.discs import coupling  # noqa\n")
    r = subprocess.run([exe, "--no-cache", str(ROOT / "pyproject.toml")], capture_output=True, text=True, cwd=tmp_path,
                       env={**__import__("os").environ, "PYTHONPATH": str(tmp_path)}, timeout=300)
    assert r.returncode != 0
    assert "mechbal.papers.rpsp is not allowed to import mechbal.papers.discs" in r.stdout, r.stdout[-3000:]


_WITHOUT_PAPERS = r"""
import json, sys, tempfile
from pathlib import Path
import numpy as np
import mechbal
from mechbal import registry
from mechbal.cases import available, run_case
from mechbal.balance.run import run_balance
assert registry.papers() == {}, registry.papers()
names = [n for n, _, _ in available()]
assert names and not {"paminsa", "discs-3r", "rpsp", "orthoglide", "arm2dof"} & set(names), names
out = Path(tempfile.mkdtemp())
summary = run_case("four-bar", out / "run")
assert (out / "run" / "summary.json").is_file()
summary = run_balance("arm2link", "static", out / "balance")
assert (out / "balance" / "balanced.toml").is_file()
from mechbal.cli import main
assert main(["cases"]) == 0
from mechbal.cases import default_case
assert default_case() == "four-bar"
print("general ok", len(names))
"""


#: run first by every Python process of the test below (a sitecustomize.py on its path): the
#: compiled module loses the names the papers' bindings give it, as in a build without them
_HIDE_PAPER_BINDINGS = """
import mechbal._core as _core
for _name in {names!r}:
    delattr(_core, _name)
"""


def test_general_code_runs_with_every_paper_deleted(tmp_path):
    """Deleting a paper deletes its folders and nothing else: the package without any paper still
    lists its general cases, runs and balances them, and the general test files pass. Here the
    Python papers are deleted and the names the papers' bindings give the compiled module are
    removed from it; `make test-without-papers` deletes the C++ and binding folders too and
    builds."""
    import os

    import mechbal

    pkg = tmp_path / "mechbal"
    shutil.copytree(Path(mechbal.__file__).parent, pkg, ignore=shutil.ignore_patterns("__pycache__"))
    for paper in (pkg / "papers").iterdir():
        if paper.is_dir() and not paper.name.startswith("_"):
            shutil.rmtree(paper)
    names = _paper_bound_names()
    (tmp_path / "sitecustomize.py").write_text(_HIDE_PAPER_BINDINGS.format(names=names))
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "MPLBACKEND": "Agg"}
    check = "import mechbal._core as c; print(sorted(n for n in %r if hasattr(c, n)))" % (names,)
    assert subprocess.run([sys.executable, "-c", check], capture_output=True, text=True, env=env,
                          timeout=120).stdout.strip() == "[]", "the paper bindings were not hidden"
    r = subprocess.run([sys.executable, "-c", _WITHOUT_PAPERS], capture_output=True, text=True, env=env,
                       timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "general ok" in r.stdout
    general = ["test_mechanism.py", "test_spec.py", "test_config.py"]
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                        *[str(Path(__file__).parent / f) for f in general]],
                       capture_output=True, text=True, env=env, cwd=tmp_path, timeout=900)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert str(tmp_path) in subprocess.run(
        [sys.executable, "-c", "import mechbal; print(mechbal.__file__)"], capture_output=True, text=True,
        env=env).stdout
