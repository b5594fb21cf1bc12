"""The layers of the architecture (docs/architecture.md) point one way.

C++: ``cpp/include/mechbal/{model,algorithm,control,io,papers}`` and ``cpp/src`` mirroring it, bottom
up; a file includes only headers of its own layer or below, and no general header or source
includes a paper's. Python: the import-linter contracts of ``pyproject.toml`` (``[tool.importlinter]``)
over the installed package.
"""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
INCLUDE = ROOT / "cpp" / "include" / "mechbal"
SRC = ROOT / "cpp" / "src"

#: bottom up; the top-level headers (status, version, the pre-model ones being removed) sit with
#: ``model``; ``mechbal.hpp`` includes everything and is checked by the install test instead
LAYERS = ["model", "algorithm", "control", "io", "papers"]
_INCLUDE = re.compile(r'#\s*include\s*[<"]mechbal/([^">]+)[">]')


def _layer_of_header(rel: str) -> int:
    head = rel.split("/", 1)[0] if "/" in rel else ""
    if head in LAYERS:
        return LAYERS.index(head)
    return 0  # status.hpp, version.hpp, detail/, the top-level pre-model headers


def _files():
    for base in (INCLUDE, SRC):
        for p in sorted(base.rglob("*")):
            if p.suffix in (".hpp", ".cpp") and p.name != "mechbal.hpp":
                yield base, p


def test_cpp_layer_folders_exist():
    for layer in LAYERS:
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
    # a paper's binding lives in its own folder (cpp/src/papers/<paper>/bind_<paper>.cpp)
    bad = [f"{p.name}: {m.group(1)}" for p in sorted((ROOT / "bindings").glob("*.[ch]pp"))
           for m in _INCLUDE.finditer(p.read_text()) if m.group(1).startswith("papers/")]
    assert not bad, bad


def test_the_layer_check_catches_an_upward_include(tmp_path):
    # the scan above must be able to fail: a model header that includes a controller
    assert _layer_of_header("control/computed_torque.hpp") > _layer_of_header("model/model.hpp")
    assert _layer_of_header("papers/paminsa/paminsa.hpp") == LAYERS.index("papers")
