"""Where the papers register what the general code finds by name (core layer).

The general layers (configuration, ``mechbal.cases``, ``mechbal.balance``, ``mechbal.sweep``, the
command line) never import a paper. Each paper is one package ``mechbal/papers/<paper>/``; this
module finds those packages by looking in the ``mechbal/papers`` folder (deleting a paper's folder
removes it, nothing else to edit) and imports each once, on first use. A paper package may hold:

* ``cases/*.toml``: its built-in case files (found by name like those of ``mechbal/cases/``);
* ``sweeps/*.toml``: its built-in sweep files;
* ``__init__.py``: its mechanism builders and closed forms; importing it registers the schema of
  its case kinds (`mechbal.schema.register_case_model`);
* ``runner.py``: the runner of its case kinds (`mechbal.cases.register`), imported when a
  case is run;
* ``balance.py``: its ``mechbal balance`` adapters (`mechbal.balance.run.register_case`),
  imported when a case is balanced.

Layer: Python core (docs/architecture.md).
"""
from __future__ import annotations

import importlib
import importlib.util
from pathlib import Path
from types import ModuleType

__all__ = ["PAPERS_DIR", "GENERAL_CASES_DIR", "GENERAL_SWEEPS_DIR", "papers", "case_dirs", "sweep_dirs",
           "paper_modules"]

_PACKAGE = Path(__file__).resolve().parent
#: the folder of the paper packages
PAPERS_DIR = _PACKAGE / "papers"
#: the general built-in cases (no paper behind them) and their sweeps
GENERAL_CASES_DIR = _PACKAGE / "cases"
GENERAL_SWEEPS_DIR = GENERAL_CASES_DIR / "sweeps"

_papers: dict[str, ModuleType] | None = None


def _paper_names() -> list[str]:
    if not PAPERS_DIR.is_dir():
        return []
    return sorted(p.name for p in PAPERS_DIR.iterdir()
                  if p.is_dir() and not p.name.startswith(("_", ".")) and (p / "__init__.py").is_file())


def papers() -> dict[str, ModuleType]:
    """Every paper package, imported (and so registered) once: ``{name: module}``."""
    global _papers
    if _papers is None:
        _papers = {}  # set first: a paper that asks for the registry while loading sees it
        for name in _paper_names():
            _papers[name] = importlib.import_module(f"mechbal.papers.{name}")
    return _papers


def paper_modules(submodule: str) -> list[ModuleType]:
    """The module ``submodule`` (``runner``, ``balance``) of every paper that has one, imported."""
    out = []
    for name in papers():
        full = f"mechbal.papers.{name}.{submodule}"
        if importlib.util.find_spec(full) is not None:
            out.append(importlib.import_module(full))
    return out


def _dirs(general: Path, sub: str) -> list[Path]:
    return [general] + [d for d in (PAPERS_DIR / n / sub for n in _paper_names()) if d.is_dir()]


def case_dirs() -> list[Path]:
    """The folders of the built-in case files: the general ones first, then each paper's."""
    return _dirs(GENERAL_CASES_DIR, "cases")


def sweep_dirs() -> list[Path]:
    """The folders of the built-in sweep files: the general ones first, then each paper's."""
    return _dirs(GENERAL_SWEEPS_DIR, "sweeps")
